r"""thomas2019 — FE² model of a tricuspid anterior-leaflet sample (Thomas, Lai & Amini, Acta Biomater 2019).

Modules, one direction only (each imports only those above it):

* :mod:`.data` — the numbers the paper gives (§2.2–2.6, §3, Table 1), with their place.
* :mod:`.models` — the matrix (Eq. 10) and fiber (Eq. 9) laws with the fitted parameters, the FE² material.
* :mod:`.sample` — the §2.5 sample: hex mesh, α/μ map, library networks per element.
* :mod:`.protocols` — the five biaxial protocols: edge displacements found to reach the edge tensions.
* :mod:`.figures` — Figs. 5–7 from the macro deformation.
* :mod:`.reproduce` — ``skvalve reproduce thomas2019``.
"""
