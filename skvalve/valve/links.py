r"""Abaqus ``*MPC`` ``LINK`` constraints (pinned rigid links) as stiff penalty bars.

A ``LINK`` MPC keeps the distance between two nodes :math:`p, a` at its reference value :math:`L`
(Abaqus Analysis User's Guide, "General multi-point constraints"). The Texas TriValve 1.0 annuloplasty
input chains six of them along the septal annulus (node labels 54-50-46-42-38-34-30, node 30 moved by
the annular amplitude) to model the ring's inextensibility, while the other annular nodes follow
prescribed displacements.

Choice: a penalty, not an exact constraint
------------------------------------------
The constraint :math:`|x_a - x_p| = L` is nonlinear, so it cannot be eliminated like a prescribed
displacement, and the Newton solver (:mod:`skvalve.fem.solvers.newton`) has no Lagrange multipliers. Each link
is therefore a :class:`~skvalve.fem.elements.truss.Truss` bar with the linear law
:class:`~skvalve.materials.uniaxial.LinearUniaxial`, energy

.. math::

    W = \frac{EA}{2L}\,(l - L)^2, \qquad N = EA\,\Big(\frac{l}{L} - 1\Big),

with its exact tangent (material plus geometric stiffness), so it needs nothing from the solver. Its
axial rigidity is a stated multiple of the stiffest chord's,

.. math::

    EA = f \max_c E_c A_c, \qquad E_c = 3\sum_i\mu_i \ (\text{small-strain modulus of the Ogden law}),

(:data:`LINK_FACTOR` :math:`f = 10^3`; about :math:`5\times 10^4` N for the 1.0 chordae). **Tolerance**:
a link carrying the axial force :math:`N` changes its length by exactly

.. math::

    \frac{|l - L|}{L} = \frac{|N|}{EA} = \frac{|N|}{f \max_c E_c A_c},

e.g. :math:`10^{-5}` for a link carrying the force that strains the stiffest chord by 1 %. A larger
:math:`f` tightens it at the price of the condition number of the tangent (the leaflets' stiffness per
unit length is :math:`10^{-3}` to :math:`1` N/mm; a 3 mm link of :math:`f = 10^3` has :math:`EA/L
\approx 2\times 10^4` N/mm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fem.elements.truss import Truss
from ..fem.space import Space
from ..io.abaqus import AbaqusModel, Location
from ..materials.uniaxial import LinearUniaxial

__all__ = ["LINK_FACTOR", "LINK_TERM", "Links", "link_nodes", "link_constraints"]

#: Axial rigidity of a LINK bar over that of the stiffest chord (module docstring: tolerance).
LINK_FACTOR = 1.0e3
#: The name of the links' :class:`~skvalve.fem.elements.truss.Truss` term
LINK_TERM = "links"


@dataclass
class Links:
    """LINK MPCs between mesh vertices: ends, reference lengths, the common axial rigidity :math:`EA` (N) and the
    input line of each link."""

    ends: np.ndarray
    length: np.ndarray
    rigidity: float
    locations: list[Location]

    @property
    def size(self) -> int:
        return int(self.ends.shape[0])

    def relative_change(self, X: np.ndarray, u: np.ndarray) -> np.ndarray:
        """:math:`(l - L)/L` of every link at displacement ``u`` (mesh coordinates ``X`` of shape (n, 3))."""
        x = X + np.asarray(u, dtype=float)[: X.size].reshape(-1, 3)
        return np.linalg.norm(x[self.ends[:, 1]] - x[self.ends[:, 0]], axis=1) / self.length - 1.0

    def term(self, space: Space) -> Truss:
        """The penalty bars as a :class:`~skvalve.fem.elements.truss.Truss` term (unit area, modulus :math:`EA`)."""
        return Truss(space, self.ends, 1.0, LinearUniaxial(self.rigidity), rest_length=self.length, name=LINK_TERM)

    def subset(self, new_index: np.ndarray) -> Links:
        """The links whose two ends survive a renumbering ``new_index`` (-1 = dropped vertex)."""
        keep = np.all(new_index[self.ends] >= 0, axis=1)
        return Links(new_index[self.ends[keep]], self.length[keep], self.rigidity,
                     [loc for loc, k in zip(self.locations, keep, strict=True) if k])


def link_nodes(abaqus: AbaqusModel) -> np.ndarray:
    """Global node indices joined by the input's LINK MPCs; raises ``ValueError`` at the line of any other
    ``*MPC`` type (not modelled: it would be lost silently)."""
    for mpc in abaqus.mpcs:
        if mpc.mpc_type != "LINK":
            raise ValueError(f"{mpc.location}: *MPC {mpc.mpc_type} is not modelled (only LINK)")
    pairs = [mpc.pairs() for mpc in abaqus.mpcs]
    return np.unique(np.concatenate(pairs)) if pairs else np.zeros(0, dtype=np.int64)


def link_constraints(abaqus: AbaqusModel, vertex_of: dict[int, int], points: np.ndarray, chord_rigidity: float | None,
                     factor: float = LINK_FACTOR) -> Links:
    """The input's LINK MPCs on mesh vertices (``vertex_of``: global node -> vertex; ``points`` (n, 3)).

    ``chord_rigidity``: :math:`\\max_c E_c A_c` of the chordae (N); None when the model has none, which is an
    error if there are links (no stated reference for the penalty).
    """
    ends, locations = [], []
    for mpc in abaqus.mpcs:
        for p, a in mpc.pairs().tolist():
            missing = [int(abaqus.node_labels[g]) for g in (p, a) if g not in vertex_of]
            if missing:
                raise ValueError(f"{mpc.location}: LINK joins node(s) {missing} (labels), which are not nodes of the "
                                 "leaflets or chordae")
            ends.append((vertex_of[p], vertex_of[a]))
            locations.append(mpc.location)
    ends_arr = np.asarray(ends, dtype=np.int64).reshape(-1, 2)
    length = np.linalg.norm(points[ends_arr[:, 1]] - points[ends_arr[:, 0]], axis=1)
    if np.any(~(length > 0.0)):
        k = int(np.flatnonzero(~(length > 0.0))[0])
        raise ValueError(f"{locations[k]}: LINK between coincident nodes (zero length)")
    if ends_arr.shape[0] and chord_rigidity is None:
        raise ValueError(f"{locations[0]}: LINK MPCs need the chordae's rigidity as the penalty's reference; the model "
                         "has no chordae")
    if not (factor > 0.0):
        raise ValueError(f"link factor must be positive; got {factor!r}")
    rigidity = factor * chord_rigidity if chord_rigidity is not None else 0.0
    return Links(ends_arr, length, float(rigidity), locations)
