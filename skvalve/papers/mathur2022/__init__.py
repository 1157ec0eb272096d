"""mathur2022 — Texas TriValve 1.0, an open model of the human tricuspid valve (Mathur et al., Eng Comput 2022).

* :mod:`.data` — the paper's numbers (Tables 2, 3, Sect. 2–3) and the TriValve material parameters read from
  the model's Abaqus input (CC BY-NC-SA 4.0, never copied into skvalve).
* :mod:`.models` — those parameters as skvalve laws (kPa).

``skvalve reproduce mathur2022`` is not available yet (see :mod:`skvalve.papers.registry`): it needs the
whole-valve model (shells of hexes, trusses, contact) of the valve issues.
"""
