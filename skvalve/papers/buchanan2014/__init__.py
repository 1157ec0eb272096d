r"""buchanan2014 — layered aortic-valve leaflet in flexure (Buchanan & Sacks, BMMB 13:813, 2014).

Modules, one direction only (each imports only those above it):

* :mod:`.data` — every number the paper gives (Tables 1–3, Fig. 8, Sect. 2.2–3.4), with its place.
* :mod:`.models` — the layered strips (tri-layer Eq. 3, bimodular bilayer Eq. 4) and their exact
  pure-bending response (:mod:`skvalve.analytic.rivlin`).
* :mod:`.fe` — plane-strain and 3D FE strips bent by rotating the end face (Figs. 7, 11).
* :mod:`.sliding` — the pin-ended end loading of Figs. 4/9 and the interlayer-sliding measure.
* :mod:`.rows` — each result beside the paper's value (or an exact one) as a table row.
* :mod:`.figures` — Figs. 3, 4/9, 7, 8, 11.
* :mod:`.reproduce` — ``skvalve reproduce buchanan2014``.

What is reproduced and how:

* **Fig. 3** — normalised M–Δκ of the one-term Ogden model (Eq. 1) from Rivlin's solution for several
  α. The experimental curve (Merryman et al. 2006) is not published as numbers, so only the model family
  is shown.
* **Fig. 8 / Table 2** — neutral axis of the bimodular bilayer (Eq. 4, Table 3 moduli, fibrosa 60 % /
  ventricularis 40 %) in WC and AC bending at Δκ = 0.1, 0.2, 0.3 mm⁻¹, from Rivlin's exact pure-bending
  solution, beside the paper's 0.35 / 0.79 and Table 2.
* **Sect. 3.3** — extreme transmural stretches Λ1 in AC bending against the measured ones.
* **Figs. 4 / 9 (bounds)** — Λ1 through the thickness for μS from 1 Pa to 45 kPa in pure bending
  (bonded: Rivlin, layered) and the fully unbonded limit (each layer bent alone). In *pure* bending the
  bonded block is exactly Rivlin's for any μS > 0 (no shear).
* **Figs. 4 / 9 (end loading)** — the paper's pin-ended loading (M = P·y) in plane-strain FE, Λ1 at the
  centre per μS and Δκ, and the μS threshold of measurable sliding.
* **FE (skvalve.fem, mixed Q2/Q1)** — plane-strain strip bent by rotating its end face, checked against
  Rivlin at the FE's own mid-length curvature; 3D quarter strip for the edge-versus-centre warping of
  Fig. 7 (and Fig. 11 with ``full``).
* **Tables 1, 3** — the averages, SEMs, relative moduli and ratios recomputed from the printed values.

Not reproducible without the authors' raw data: the experimental M–Δκ curves (Figs. 3, 5), the measured
transmural profiles (Figs. 6, 10), the silicone validation itself (Table 1) and the fit of μ = 45 kPa
(Sect. 3.1). Conventions: lengths in mm, moduli in kPa, moments per unit width in kPa·mm²; normalised
thickness 0 = ventricularis face, 1 = fibrosa face; AC bending stretches the fibrosa face (``a > 0`` in
:func:`skvalve.analytic.rivlin.bend`), WC the ventricularis face (``a < 0``).
"""
