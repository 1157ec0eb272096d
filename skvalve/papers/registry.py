"""The papers ``skvalve reproduce`` knows, and where each one's reproduction lives.

Plugging a paper in
-------------------
A paper is reproduced by a module ``skvalve.papers.<key>.reproduce`` with a function

.. code-block:: python

    def reproduce(out: pathlib.Path | None = None, full: bool = False) -> Iterable[Row | Stage | Written]:
        ...

that returns (a list) or, better, yields (a generator) the items of :mod:`skvalve.papers.table`:

* :class:`~skvalve.papers.table.Row` — one compared quantity, yielded as soon as it is computed (the CLI
  prints it at once); a paper row that cannot agree carries ``expected_difference`` and a note;
* :class:`~skvalve.papers.table.Stage` — optional, a line announcing the next long computation;
* :class:`~skvalve.papers.table.Written` — optional, a figure or file finished in ``out`` (written with
  :func:`skvalve.papers.plotting.save_figure`, atomically). With ``out=None`` write nothing.

``full=True`` means converged meshes and complete sweeps (slow); the default run should take a minute or
two. The module exists or not: until it does, the CLI prints the entry's :attr:`Paper.plan` and exits 2.
Nothing else is needed to plug it in; the entry below stays as it is.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Paper", "PAPERS"]


@dataclass(frozen=True)
class Paper:
    """A reproducible paper: its key, citation, the module with ``reproduce`` and what it computes."""

    key: str
    citation: str
    plan: str

    @property
    def module(self) -> str:
        return f"skvalve.papers.{self.key}.reproduce"


PAPERS = {
    p.key: p
    for p in (
        Paper("buchanan2014", "Buchanan & Sacks, Biomech Model Mechanobiol 13:813 (2014)",
              "neutral axes (Fig. 8, Table 2) and transmural stretches (Sect. 3.3) of the bimodular bilayer from "
              "Rivlin's solution; FE strips against Rivlin; 3D edge-versus-centre warping (Fig. 7); the pin-ended "
              "interlayer-sliding study (Figs. 4/9); Figs. 3, 4/9, 7, 8 (and 11 with --full)"),
        Paper("thomas2019", "Thomas et al., multiscale tricuspid leaflet (2019)",
              "the collagen-network RVE (fibre Eq. 9, matrix Eq. 10) under the paper's stretch protocols: RVE "
              "stresses and fibre orientations against the paper's figures, and the FE² leaflet strip"),
        Paper("mathur2022", "Mathur et al., Texas TriValve 1.0, Eng Comput (2022)",
              "the diseased, annuloplasty and clip-repaired valves of the shared Texas TriValve input at "
              "end-systole: orifice, leaflet and coaptation areas (Table 2) and leaflet-centre maximum "
              "principal stresses (Table 3)"),
    )
}
