r"""How the biaxial rig holds the sample: whole edges, or tines (hooks, sutures) at discrete points.

Thomas et al. (2019) §2.1 mounted the sample "using fish hooks as described by Amini-Khoi et al. [51]"
(Amini Khoiy & Amini's custom planar biaxial device, Fig. 2b): a few hooks pierce each edge and pull
it through pulleys, and the corners between the outermost hooks of two edges are free. The paper does not
say how many hooks per side; rigs of this lineage (trampoline mounting of valve leaflets, Sacks' group
where Amini trained, and the later tricuspid tests of the same group) use **four per side**, evenly
spaced, which is the default here — a parameter, stated as an assumption, not a number from the paper.

Two kinds of attachment are modelled:

* :class:`UniformEdges` — every node of the four edge faces moves along the edge normal by the same
  amount (free tangentially and through the thickness): the idealised biaxial test, a homogeneous
  state for a homogeneous sample.
* :class:`Tines` — ``per_edge`` point-like attachments on each edge, each a column of nodes through the
  thickness at one in-plane point; the edge between them and the corners are free. A tine either
  slides along the edge (``sliding=True``: pulleys or loops of suture let it follow the sample's
  lateral contraction; only the normal component is prescribed) or is pinned to its carriage
  (``sliding=False``: the tangential component stays 0 as well).

Positions. The tines of an edge of length :math:`L` sit at :math:`s_k = L/2 + (k - (n-1)/2)\,a/(n-1)`,
:math:`k = 0..n-1`, where :math:`a` is the span between the outermost tines (``span`` as a fraction of
:math:`L`; default :math:`(n-1)/n`, i.e. even spacing :math:`L/n` with half a spacing to each corner).
On a mesh a tine takes the node column nearest to its position, rounded away from the edge centre so
that the pattern stays symmetric.

Load. The rig measures the force on each axis' load cell; the tension of Fig. 5b is that force per unit
reference edge length, :math:`T_1 = \sum_\text{right tines} R_x / H`, :math:`T_2 = \sum_\text{top tines}
R_y / W` (:meth:`Grips.tensions`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...fem import Solid

__all__ = ["UniformEdges", "Tines", "Attachment", "Grips", "DEFAULT_TINES", "UNIFORM_EDGES", "tine_fractions",
           "grips_of"]

#: edge name, normal axis, sign of the outward normal
EDGES = (("left", 0, -1.0), ("right", 0, 1.0), ("bottom", 1, -1.0), ("top", 1, 1.0))


@dataclass(frozen=True)
class UniformEdges:
    """Every node of the four edge faces moves by the same normal displacement (free tangentially)."""

    @property
    def label(self) -> str:
        return "uniform edges"


@dataclass(frozen=True)
class Tines:
    """``per_edge`` point attachments per edge over ``span`` (fraction of the edge; None: (n−1)/n).

    sliding : True when a tine can move along its edge (pulleys, suture loops), False when pinned.
    """

    per_edge: int = 4
    span: float | None = None
    sliding: bool = True

    def __post_init__(self) -> None:
        if isinstance(self.per_edge, bool) or not isinstance(self.per_edge, int | np.integer) or self.per_edge < 1:
            raise ValueError(f"Tines: per_edge must be a positive integer; got {self.per_edge!r}")
        if self.span is not None:
            if isinstance(self.span, bool) or not isinstance(self.span, int | float) or not 0.0 <= self.span < 1.0:
                raise ValueError(f"Tines: span must be a number in [0, 1) (the corners stay free); got {self.span!r}")
            if self.per_edge == 1 and self.span != 0.0:
                raise ValueError("Tines: a single tine per edge has span 0")
            if self.per_edge > 1 and self.span == 0.0:
                raise ValueError(f"Tines: {self.per_edge} tines cannot share one point (span 0)")
        if not isinstance(self.sliding, bool):
            raise ValueError(f"Tines: sliding must be True or False; got {self.sliding!r}")

    @property
    def label(self) -> str:
        return f"{self.per_edge} {'sliding' if self.sliding else 'pinned'} tines per edge"


Attachment = UniformEdges | Tines

#: whole edge faces moved uniformly (the idealised test)
UNIFORM_EDGES = UniformEdges()
#: four evenly spaced hooks per edge that slide with the sample (see the module docstring for the source)
DEFAULT_TINES = Tines(per_edge=4, span=None, sliding=True)


def tine_fractions(tines: Tines) -> np.ndarray:
    """Tine positions along an edge as fractions of its length (module docstring)."""
    n = tines.per_edge
    span = (n - 1) / n if tines.span is None else tines.span
    if n == 1:
        return np.array([0.5])
    return 0.5 + (np.arange(n) - (n - 1) / 2) * span / (n - 1)


def _snap(fractions: np.ndarray, divisions: int) -> np.ndarray:
    """Node index along an edge of ``divisions`` elements nearest to each fraction, symmetric about the centre."""
    lower = np.floor(fractions * divisions + 0.5).astype(int)
    upper = divisions - np.floor((1.0 - fractions) * divisions + 0.5).astype(int)
    return np.where(fractions <= 0.5, np.minimum(lower, upper), np.maximum(lower, upper))


@dataclass
class Grips:
    """The scalar dofs each edge's attachment holds and the components it prescribes.

    nodes : edge name -> scalar dof indices held (all nodes of the face, or the tines' node columns).
    pinned : True when the tangential component is held at 0 as well (pinned tines).
    positions : edge name -> in-plane positions (m, along the edge) of the tines; empty for uniform edges.
    """

    attachment: Attachment
    nodes: dict[str, np.ndarray]
    pinned: bool
    positions: dict[str, np.ndarray]

    def points(self, width: float, height: float) -> np.ndarray:
        """(2, n) reference in-plane positions (m) of all tines, every edge; (2, 0) for uniform edges."""
        xy = []
        for name, axis, sign in EDGES:
            along = self.positions[name]
            across = np.full(along.size, 0.0 if sign < 0 else (width, height)[axis])
            xy.append(np.stack([across, along]) if axis == 0 else np.stack([along, across]))
        return np.concatenate(xy, axis=1)

    def tensions(self, solid: Solid, residual: np.ndarray, width: float, height: float) -> np.ndarray:
        """(T1, T2) in N/m: summed x reactions of the right grips / H, y reactions of the top grips / W."""
        space = solid.space
        right = residual[space.displacement_dofs(self.nodes["right"], [0])].sum()
        top = residual[space.displacement_dofs(self.nodes["top"], [1])].sum()
        return np.array([right / height, top / width])


def grips_of(solid: Solid, attachment: Attachment, size: tuple[float, float, float]) -> Grips:
    """Select the held nodes of a box mesh ``[0, W] × [0, H] × [0, t]`` for ``attachment``."""
    if not isinstance(attachment, UniformEdges | Tines):
        raise TypeError(f"attachment must be UniformEdges or Tines; got {type(attachment).__name__}")
    space = solid.space
    if isinstance(attachment, UniformEdges):
        nodes = {name: space.scalar_dofs_on(name) for name, _, _ in EDGES}
        return Grips(attachment, nodes, False, {name: np.zeros(0) for name, _, _ in EDGES})
    X = space.dof_coordinates
    lengths = size[:2]
    nodes, positions = {}, {}
    for name, axis, sign in EDGES:
        along = 1 - axis
        on_edge = np.isclose(X[axis], 0.0 if sign < 0 else lengths[axis], atol=1e-9 * lengths[axis])
        columns = np.unique(np.round(X[along, on_edge] / lengths[along], 12))
        divisions = columns.size - 1
        index = _snap(tine_fractions(attachment), divisions)
        if np.unique(index).size < attachment.per_edge or index.min() < 1 or index.max() > divisions - 1:
            raise ValueError(f"Tines: {attachment.per_edge} tines over span {attachment.span} do not fit on "
                             f"distinct interior node columns of the {name} edge ({divisions} elements): refine "
                             f"the mesh or use fewer tines")
        chosen = columns[index] * lengths[along]
        held = on_edge & np.any(np.isclose(X[along][:, None], chosen[None, :], atol=1e-9 * lengths[along]), axis=1)
        nodes[name] = np.flatnonzero(held)
        positions[name] = chosen
    return Grips(attachment, nodes, not attachment.sliding, positions)
