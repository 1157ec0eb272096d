r"""Two-node truss (cable) elements in 3D on the displacement field of a solid.

A bar joins the scalar dofs (nodes) :math:`a, b` of the solid's displacement space. With reference
positions :math:`X`, current positions :math:`x = X + u`, rest length :math:`L` (by default
:math:`|X_b - X_a|`; a collapsed chordae chain uses its path length), current length
:math:`l = |x_b - x_a|`, unit vector :math:`n = (x_b - x_a)/l` and stretch :math:`\lambda = l/L`,
a uniaxial law (:mod:`skvalve.materials.uniaxial`) gives the axial force
:math:`N = A\,P(\lambda)` with the reference cross-section :math:`A` (Abaqus's convention for
hyperelastic trusses). The bar stores :math:`W = A L \int_1^\lambda P\,d\lambda'`; its internal
forces and tangent are

.. math::

    f_b = -f_a = N\,n, \qquad
    K = \begin{bmatrix} k & -k \\ -k & k \end{bmatrix}, \qquad
    k = \frac{A}{L}\frac{dP}{d\lambda}\,n\otimes n + \frac{N}{l}\,(I - n\otimes n),

the material stiffness along the bar plus the geometric (stress) stiffness across it (a bar under
tension resists transverse motion of its ends by :math:`N/l`). ``K`` is symmetric; a bar with
:math:`N \le 0` has no transverse stiffness, which is why chains of bars are collapsed
(:mod:`skvalve.valve.chordae`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ...materials.uniaxial import TensionOnly, UniaxialLaw
from ..space import Space
from ..terms import Blocks, Contribution, Term

__all__ = ["BarResponse", "bar_response", "BarEnd", "LawAssignment", "Truss"]


@dataclass
class BarEnd:
    r"""One end of every bar as a fixed weighted average of nodes, :math:`x = \sum_j w_j x_{n_j}`
    (a distributing coupling: the end's force goes to the nodes in proportion to :math:`w_j`).

    nodes, weights : (n_bars, k) scalar dof (node) indices and weights, each row summing to 1 (pad a short row
    with any node and weight 0).
    """

    nodes: np.ndarray
    weights: np.ndarray

    @classmethod
    def single(cls, nodes: np.ndarray) -> BarEnd:
        """Each bar end at one node."""
        nodes = np.asarray(nodes, dtype=np.int64).reshape(-1, 1)
        return cls(nodes, np.ones(nodes.shape, dtype=float))


@dataclass
class BarResponse:
    """Per-bar state: stretch, axial force and current length; element forces (n, 6) and tangents (n, 6, 6), and
    the tangents' positive semidefinite projections (:func:`bar_response`)."""

    stretch: np.ndarray
    axial_force: np.ndarray
    length: np.ndarray
    forces: np.ndarray
    matrices: np.ndarray | None
    projected: np.ndarray | None = None


class LawAssignment:
    """One uniaxial law for all bars, or ``laws[index[bar]]``."""

    def __init__(self, laws: UniaxialLaw | Sequence[UniaxialLaw], index: np.ndarray | None, n_bars: int) -> None:
        if isinstance(laws, UniaxialLaw):
            if index is not None:
                raise ValueError("law_index is only used with a sequence of laws")
            self.laws, self.index = [laws], np.zeros(n_bars, dtype=np.int64)
            return
        self.laws = list(laws)
        for k, law in enumerate(self.laws):
            if not isinstance(law, UniaxialLaw):
                raise TypeError(f"laws[{k}] has no nominal_stress(stretch): {type(law).__name__}")
        if index is None:
            raise ValueError("a sequence of laws needs law_index (one law number per bar)")
        self.index = np.asarray(index, dtype=np.int64).ravel()
        if self.index.shape != (n_bars,):
            raise ValueError(f"law_index must have one entry per bar ({n_bars}); got shape {self.index.shape}")
        if n_bars and (self.index.min() < 0 or self.index.max() >= len(self.laws)):
            raise ValueError(f"law_index must lie in 0..{len(self.laws) - 1}")

    def evaluate(self, stretch: np.ndarray, slack_stretch: np.ndarray | None = None, scale: float = 1.0
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Nominal stress and slope of every bar (``slack_stretch`` per bar for tension-only laws); ``scale``
        multiplies each law (for tension-only laws the taut law only, not the slack spring)."""
        P, dP = np.empty_like(stretch), np.empty_like(stretch)
        for k, law in enumerate(self.laws):
            mine = self.index == k
            if not np.any(mine):
                continue
            if isinstance(law, TensionOnly):
                slack = 1.0 if slack_stretch is None else slack_stretch[mine]
                P[mine], dP[mine] = law.nominal_stress(stretch[mine], slack, scale)
            else:
                P_k, dP_k = law.nominal_stress(stretch[mine])
                P[mine], dP[mine] = scale * P_k, scale * dP_k
        return P, dP

    def energy(self, stretch: np.ndarray, slack_stretch: np.ndarray | None = None, scale: float = 1.0
               ) -> np.ndarray | None:
        """Stored energy per reference volume of every bar (the integral of :meth:`evaluate`'s stress), or ``None``
        when a law has no ``energy(stretch)``."""
        W = np.empty_like(stretch)
        for k, law in enumerate(self.laws):
            mine = self.index == k
            if not np.any(mine):
                continue
            if getattr(law, "energy", None) is None:
                return None
            if isinstance(law, TensionOnly):
                if getattr(law.law, "energy", None) is None:
                    return None
                slack = 1.0 if slack_stretch is None else slack_stretch[mine]
                W[mine] = law.energy(stretch[mine], slack, scale)
            else:
                W[mine] = scale * law.energy(stretch[mine])
        return W


def bar_response(x_a: np.ndarray, x_b: np.ndarray, rest_length: np.ndarray, area: np.ndarray,
                 laws: LawAssignment, tangent: bool = True, slack_stretch: np.ndarray | None = None,
                 scale: float = 1.0) -> BarResponse:
    r"""Forces and tangents of bars with current end positions ``x_a, x_b`` of shape (n, 3) (module docstring).

    ``slack_stretch``: per-bar force-free stretch of tension-only laws
    (:class:`~skvalve.materials.uniaxial.TensionOnly`).
    Raises ``ValueError`` naming the bars whose current length is zero or not finite.

    The tangent of a bar is :math:`\begin{bmatrix} k & -k\\ -k & k\end{bmatrix}`, :math:`k = a\,nn^T +
    b\,(I - nn^T)` with the axial stiffness :math:`a = A\,P'(\lambda)/L` and the geometric one :math:`b = N/l`:
    its eigenvalues are :math:`2a` (stretching), :math:`2b` (twice: rotation) and 0 (three translations). Its
    projection onto the positive semidefinite matrices (``projected``, for projected Newton steps) therefore sets
    :math:`a \to \max(a, 0)` and :math:`b \to \max(b, 0)`: a closed form, no eigendecomposition.
    """
    d = x_b - x_a
    length = np.linalg.norm(d, axis=1)
    bad = ~(np.isfinite(length) & (length > 0.0))
    if np.any(bad):
        raise ValueError(f"truss: zero or non-finite current length in bar(s) {np.flatnonzero(bad)[:10].tolist()}")
    n = d / length[:, None]
    stretch = length / rest_length
    P, dP = laws.evaluate(stretch, slack_stretch, scale)
    N = area * P
    f = N[:, None] * n
    forces = np.hstack([-f, f])
    matrices = projected = None
    if tangent:
        nn = n[:, :, None] * n[:, None, :]
        axial, geometric = area * dP / rest_length, N / length
        matrices = _bar_matrices(axial, geometric, nn)
        projected = _bar_matrices(np.maximum(axial, 0.0), np.maximum(geometric, 0.0), nn)
    return BarResponse(stretch, N, length, forces, matrices, projected)


def _bar_matrices(axial: np.ndarray, geometric: np.ndarray, nn: np.ndarray) -> np.ndarray:
    """(n, 6, 6) bar tangents from the axial and geometric stiffnesses and the axis dyads (:func:`bar_response`)."""
    k = axial[:, None, None] * nn + geometric[:, None, None] * (np.eye(3) - nn)
    matrices = np.empty((k.shape[0], 6, 6))
    matrices[:, :3, :3] = k
    matrices[:, 3:, 3:] = k
    matrices[:, :3, 3:] = -k
    matrices[:, 3:, :3] = -k
    return matrices


class Truss(Term):
    """Bars (or cables) between nodes of a 3D displacement space.

    Parameters
    ----------
    space : the field's :class:`~skvalve.fem.space.Space` (3D); bars join its scalar dofs (mesh vertices
        for a linear space; nodes used by bars only must be numbered below the last cell vertex, since
        scikit-fem counts ``max(mesh.t) + 1`` vertices).
    nodes : (n_bars, 2) scalar dof indices of the bar ends.
    area : reference cross-section area, one number or one per bar.
    laws : a uniaxial law (:mod:`skvalve.materials.uniaxial`) or a sequence of laws with ``law_index``.
    law_index : (n_bars,) law number of each bar, with a sequence of laws.
    rest_length : rest length per bar (default: the reference distance of its ends); a slack cable's
        stretch is measured against it.
    slack_stretch : per-bar force-free stretch (<= 1) of tension-only laws, e.g. the reference distance over
        the rest length of a collapsed chain, so that a curved chain starts stress-free.
    name : shown in error messages.
    stiffness_scale : optional :math:`s(t) > 0` multiplying every bar's law (a tension-only cable's taut law only:
        its slack spring, which keeps slack cable ends supported, is not scaled): a continuation parameter, e.g.
        cables that start soft and stiffen to their law
        (:class:`~skvalve.fem.amplitudes.GeometricRamp`); ``None`` is :math:`s = 1`.
    """

    def __init__(self, space: Space, nodes, area, laws, law_index: np.ndarray | None = None,
                 rest_length: np.ndarray | None = None, slack_stretch: np.ndarray | None = None,
                 name: str = "truss", stiffness_scale: Callable[[float], float] | None = None) -> None:
        if space.dim != 3:
            raise ValueError(f"{name}: trusses need a 3D displacement space; got dimension {space.dim}")
        ends = _bar_ends(nodes, name, space.n_scalar)
        self.name = name
        self.stiffness_scale = stiffness_scale
        self.space = space
        self.ends = ends
        self.nodes = np.column_stack([end.nodes[np.arange(end.nodes.shape[0]), np.argmax(end.weights, axis=1)]
                                      for end in ends])
        self.n_bars = self.nodes.shape[0]
        self.dofs = np.ascontiguousarray(np.hstack([(3 * end.nodes[:, :, None] + np.arange(3)).reshape(self.n_bars, -1)
                                                    for end in ends]))
        # distributing ends: the constant (n, 6, m) map from the element dofs to the two end displacements
        self._spread = _spreading(ends) if any(end.nodes.shape[1] > 1 for end in ends) else None
        # a linear space numbers its scalar dofs like the mesh vertices; mesh.p also holds vertices that no
        # cell uses (nodes of the trusses only), for which the basis has no location
        X = (space.mesh.p if space.order == 1 else space.dof_coordinates).T
        self.reference = tuple(np.einsum("nk,nkd->nd", end.weights, X[end.nodes]) for end in ends)
        same = np.flatnonzero(np.all(self.reference[0] == self.reference[1], axis=1))
        if same.size:
            raise ValueError(f"{name}: bar(s) {same[:10].tolist()} join a point to itself")
        chord = np.linalg.norm(self.reference[1] - self.reference[0], axis=1)
        self.rest_length = chord if rest_length is None else np.asarray(rest_length, dtype=float).ravel()
        self.area = np.broadcast_to(np.asarray(area, dtype=float), (self.n_bars,)).copy()
        for label, values in (("rest_length", self.rest_length), ("area", self.area)):
            if values.shape != (self.n_bars,):
                raise ValueError(f"{name}: {label} must have one value per bar ({self.n_bars}); got {values.shape}")
            bad = np.flatnonzero(~(np.isfinite(values) & (values > 0.0)))
            if bad.size:
                raise ValueError(f"{name}: {label} must be positive and finite; bar(s) {bad[:10].tolist()}")
        self.laws = LawAssignment(laws, law_index, self.n_bars)
        self.slack_stretch = None
        if slack_stretch is not None:
            self.slack_stretch = np.broadcast_to(np.asarray(slack_stretch, dtype=float), (self.n_bars,)).copy()
            if np.any(~(self.slack_stretch > 0.0) | (self.slack_stretch > 1.0)):
                raise ValueError(f"{name}: slack_stretch must lie in (0, 1]")
            for k, law in enumerate(self.laws.laws):
                slack = self.slack_stretch[self.laws.index == k]
                if not isinstance(law, TensionOnly) and np.any(np.abs(slack - 1.0) > 1e-9):
                    raise TypeError(f"{name}: a slack stretch below 1 needs a tension-only law; bars of law {k} "
                                    f"({type(law).__name__}) have {slack.min():.6g}")

    def connectivity(self) -> list[np.ndarray]:
        return [self.dofs]

    def end_positions(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Current positions (n_bars, 3) of both ends of every bar at displacement ``u``."""
        nodal = u[: 3 * self.space.n_scalar].reshape(-1, 3)
        x_a, x_b = (ref + np.einsum("nk,nkd->nd", end.weights, nodal[end.nodes])
                    for ref, end in zip(self.reference, self.ends, strict=True))
        return x_a, x_b

    def response(self, u: np.ndarray, tangent: bool = False, scale: float = 1.0) -> BarResponse:
        """Stretch, axial force and element forces/tangents of every bar at displacement ``u`` (element vectors
        and matrices on ``self.dofs``: the nodes of both ends); ``scale`` as ``stiffness_scale``."""
        x_a, x_b = self.end_positions(u)
        state = bar_response(x_a, x_b, self.rest_length, self.area, self.laws, tangent, self.slack_stretch, scale)
        if self._spread is None:
            return state
        spread = self._spread
        spread_t = spread.transpose(0, 2, 1)
        state.forces = np.matmul(spread_t, state.forces[:, :, None])[:, :, 0]
        if state.matrices is not None:
            state.matrices = np.matmul(np.matmul(spread_t, state.matrices), spread)
            state.projected = np.matmul(np.matmul(spread_t, state.projected), spread)
        return state

    def _scale(self, t: float, step: int | None) -> float:
        if self.stiffness_scale is None:
            return 1.0
        scale = float(self.stiffness_scale(t))
        if not (np.isfinite(scale) and scale > 0.0):
            raise ValueError(f"{self.name}: stiffness_scale must be positive and finite; got {scale!r} at load "
                             f"factor {t} (load step {step})")
        return scale

    def energy(self, u: np.ndarray, t: float) -> float | None:
        r""":math:`\sum_\text{bars} A L\,W(\lambda)` (module docstring); ``None`` when a law has no energy."""
        x_a, x_b = self.end_positions(u)
        length = np.linalg.norm(x_b - x_a, axis=1)
        if not np.all(np.isfinite(length) & (length > 0.0)):
            return float("inf")
        W = self.laws.energy(length / self.rest_length, self.slack_stretch, self._scale(t, None))
        return None if W is None else float(np.sum(self.area * self.rest_length * W))

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        scale = self._scale(t, step)
        try:
            state = self.response(u, tangent, scale)
        except ValueError as err:
            raise ValueError(f"{err} (load step {step}, load factor {t})") from err
        internal = np.bincount(self.dofs.ravel(), state.forces.ravel(), minlength=self.space.n_dofs)
        return Contribution(internal=internal, blocks=[Blocks(self.dofs, state.matrices, state.projected)])


def _bar_ends(nodes, name: str, n_scalar: int) -> tuple[BarEnd, BarEnd]:
    """Two :class:`BarEnd` from an (n_bars, 2) node array or a pair of ends; checks indices and weights."""
    if isinstance(nodes, tuple | list) and len(nodes) == 2 and all(isinstance(e, BarEnd) for e in nodes):
        ends = tuple(BarEnd(np.asarray(e.nodes, dtype=np.int64), np.asarray(e.weights, dtype=float)) for e in nodes)
    else:
        nodes = np.asarray(nodes, dtype=np.int64)
        if nodes.ndim != 2 or nodes.shape[1] != 2:
            raise ValueError(f"{name}: nodes must have shape (n_bars, 2) or be two BarEnd; got {nodes.shape}")
        same = np.flatnonzero(nodes[:, 0] == nodes[:, 1])
        if same.size:
            raise ValueError(f"{name}: bar(s) {same[:10].tolist()} join a node to itself")
        ends = (BarEnd.single(nodes[:, 0]), BarEnd.single(nodes[:, 1]))
    for label, end in zip("ab", ends, strict=True):
        if end.nodes.ndim != 2 or end.nodes.shape != end.weights.shape or end.nodes.shape[0] != ends[0].nodes.shape[0]:
            raise ValueError(f"{name}: end {label}: nodes and weights must both be (n_bars, k)")
        if end.nodes.size and (end.nodes.min() < 0 or end.nodes.max() >= n_scalar):
            raise ValueError(f"{name}: node indices must lie in 0..{n_scalar - 1}")
        bad = np.flatnonzero(~np.isclose(end.weights.sum(axis=1), 1.0, rtol=0, atol=1e-12) |
                             np.any(~np.isfinite(end.weights), axis=1))
        if bad.size:
            raise ValueError(f"{name}: end {label}: weights of bar(s) {bad[:10].tolist()} do not sum to 1")
    return ends


def _spreading(ends: tuple[BarEnd, BarEnd]) -> np.ndarray:
    """(n_bars, 6, 3 (k_a + k_b)): the matrix taking the element dofs to the two end displacements."""
    n = ends[0].nodes.shape[0]
    blocks = []
    for e, end in enumerate(ends):
        k = end.nodes.shape[1]
        block = np.zeros((n, 6, 3 * k))
        for d in range(3):
            block[:, 3 * e + d, d::3] = end.weights
        blocks.append(block)
    return np.concatenate(blocks, axis=2)
