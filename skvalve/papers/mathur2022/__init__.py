"""mathur2022 — Texas TriValve 1.0, an open model of the human tricuspid valve (Mathur et al., Eng Comput 2022).

* :mod:`.data` — the paper's numbers (Tables 2, 3, Sect. 2–3) and the TriValve material parameters read from
  the model's Abaqus input (CC BY-NC-SA 4.0, never copied into skvalve).
* :mod:`.models` — those parameters as skvalve laws (kPa).
* :mod:`.figures` — the closed valve seen from the atrium, the coaptation map and the orifice outline.
* :mod:`.columns` — which paper column of Tables 2–3 each Texas TriValve input (1.0 and 1.1) answers, and its rows.
* :mod:`.reproduce` — ``skvalve reproduce mathur2022``: Table 2 geometry of the open valve by default; ``--state``
  measures a kept state of :func:`skvalve.valve.run.close_valve`; ``--full`` closes every input present with it
  and prints each one's Table 2–3 rows at end-systole.
"""
