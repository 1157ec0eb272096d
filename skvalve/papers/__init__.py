"""The three papers skvalve reproduces, one package each, and what they share.

* :mod:`.buchanan2014`, :mod:`.thomas2019`, :mod:`.mathur2022` — each with ``data`` (every number the paper
  gives, with its table/equation/page), ``models`` (builders), and where available ``figures`` and
  ``reproduce`` (``skvalve reproduce <paper>``).
* :mod:`.registry` — the papers the CLI knows and the ``reproduce`` interface.
* :mod:`.table` — reproduction rows and their status; :mod:`.plotting` — readable, atomically written figures.
* :mod:`.catalogue`, :mod:`.catalogue_figures` — ``skvalve materials``: the library laws with the papers' parameters.
"""
