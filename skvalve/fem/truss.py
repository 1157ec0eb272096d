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

from ..materials.uniaxial import TensionOnly, UniaxialLaw
from .space import Space
from .terms import Blocks, Contribution, Term

__all__ = ["BarResponse", "bar_response", "LawAssignment", "Truss"]


@dataclass
class BarResponse:
    """Per-bar state: stretch, axial force and current length; element forces (n, 6) and tangents (n, 6, 6)."""

    stretch: np.ndarray
    axial_force: np.ndarray
    length: np.ndarray
    forces: np.ndarray
    matrices: np.ndarray | None


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

    def evaluate(self, stretch: np.ndarray, slack_stretch: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Nominal stress and slope of every bar (``slack_stretch`` per bar for tension-only laws)."""
        P, dP = np.empty_like(stretch), np.empty_like(stretch)
        for k, law in enumerate(self.laws):
            mine = self.index == k
            if np.any(mine):
                if slack_stretch is None:
                    P[mine], dP[mine] = law.nominal_stress(stretch[mine])
                else:
                    P[mine], dP[mine] = law.nominal_stress(stretch[mine], slack_stretch[mine])
        return P, dP


def bar_response(x_a: np.ndarray, x_b: np.ndarray, rest_length: np.ndarray, area: np.ndarray,
                 laws: LawAssignment, tangent: bool = True, slack_stretch: np.ndarray | None = None) -> BarResponse:
    """Forces and tangents of bars with current end positions ``x_a, x_b`` of shape (n, 3) (module docstring).

    ``slack_stretch``: per-bar force-free stretch of tension-only laws
    (:class:`~skvalve.materials.uniaxial.TensionOnly`).
    Raises ``ValueError`` naming the bars whose current length is zero or not finite.
    """
    d = x_b - x_a
    length = np.linalg.norm(d, axis=1)
    bad = ~(np.isfinite(length) & (length > 0.0))
    if np.any(bad):
        raise ValueError(f"truss: zero or non-finite current length in bar(s) {np.flatnonzero(bad)[:10].tolist()}")
    n = d / length[:, None]
    stretch = length / rest_length
    P, dP = laws.evaluate(stretch, slack_stretch)
    N = area * P
    f = N[:, None] * n
    forces = np.hstack([-f, f])
    matrices = None
    if tangent:
        nn = n[:, :, None] * n[:, None, :]
        k = (area * dP / rest_length)[:, None, None] * nn + (N / length)[:, None, None] * (np.eye(3) - nn)
        matrices = np.empty((n.shape[0], 6, 6))
        matrices[:, :3, :3] = k
        matrices[:, 3:, 3:] = k
        matrices[:, :3, 3:] = -k
        matrices[:, 3:, :3] = -k
    return BarResponse(stretch, N, length, forces, matrices)


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
    stiffness_scale : optional :math:`s(t) > 0` multiplying every bar's force and tangent (the stored energy
        :math:`s W`): a continuation parameter, e.g. cables that start soft and stiffen to their law
        (:class:`~skvalve.fem.amplitudes.GeometricRamp`); ``None`` is :math:`s = 1`.
    """

    def __init__(self, space: Space, nodes: np.ndarray, area, laws, law_index: np.ndarray | None = None,
                 rest_length: np.ndarray | None = None, slack_stretch: np.ndarray | None = None,
                 name: str = "truss", stiffness_scale: Callable[[float], float] | None = None) -> None:
        if space.dim != 3:
            raise ValueError(f"{name}: trusses need a 3D displacement space; got dimension {space.dim}")
        nodes = np.asarray(nodes, dtype=np.int64)
        if nodes.ndim != 2 or nodes.shape[1] != 2:
            raise ValueError(f"{name}: nodes must have shape (n_bars, 2); got {nodes.shape}")
        if nodes.size and (nodes.min() < 0 or nodes.max() >= space.n_scalar):
            raise ValueError(f"{name}: node indices must lie in 0..{space.n_scalar - 1}")
        same = np.flatnonzero(nodes[:, 0] == nodes[:, 1])
        if same.size:
            raise ValueError(f"{name}: bar(s) {same[:10].tolist()} join a node to itself")
        self.name = name
        self.stiffness_scale = stiffness_scale
        self.space = space
        self.nodes = nodes
        self.n_bars = nodes.shape[0]
        self.dofs = np.ascontiguousarray((3 * nodes[:, :, None] + np.arange(3)).reshape(self.n_bars, 6))
        # a linear space numbers its scalar dofs like the mesh vertices; mesh.p also holds vertices that no
        # cell uses (nodes of the trusses only), for which the basis has no location
        X = (space.mesh.p if space.order == 1 else space.dof_coordinates).T
        self.reference = (X[nodes[:, 0]], X[nodes[:, 1]])
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
            for law in self.laws.laws:
                if not isinstance(law, TensionOnly):
                    raise TypeError(f"{name}: slack_stretch needs tension-only laws; got {type(law).__name__}")

    def connectivity(self) -> list[np.ndarray]:
        return [self.dofs]

    def response(self, u: np.ndarray, tangent: bool = False) -> BarResponse:
        """Stretch, axial force and element forces/tangents of every bar at displacement ``u``."""
        ue = u[self.dofs]
        return bar_response(self.reference[0] + ue[:, :3], self.reference[1] + ue[:, 3:], self.rest_length,
                            self.area, self.laws, tangent, self.slack_stretch)

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        try:
            state = self.response(u, tangent)
        except ValueError as err:
            raise ValueError(f"{err} (load step {step}, load factor {t})") from err
        forces, matrices = state.forces, state.matrices
        if self.stiffness_scale is not None:
            scale = float(self.stiffness_scale(t))
            if not (np.isfinite(scale) and scale > 0.0):
                raise ValueError(f"{self.name}: stiffness_scale must be positive and finite; got {scale!r} at load "
                                 f"factor {t} (load step {step})")
            forces = scale * forces
            matrices = None if matrices is None else scale * matrices
        internal = np.bincount(self.dofs.ravel(), forces.ravel(), minlength=self.space.n_dofs)
        return Contribution(internal=internal, blocks=[Blocks(self.dofs, matrices)])
