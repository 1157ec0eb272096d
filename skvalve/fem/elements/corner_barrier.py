r"""A barrier on the corner Jacobians of trilinear hexes: an element that cannot fold at a corner.

Why
---
A trilinear hex is checked for inversion at its quadrature points
(:class:`~skvalve.fem.errors.NonPositiveJacobianError`), but its map :math:`x(\xi)` can fold at a corner while every
Gauss point stays positive: the corner's Jacobian :math:`\det(\partial x/\partial\xi)` is not seen by the 2×2×2
rule, nor by the F-bar element's mean dilatation, so the stored energy offers no resistance. On the 1.0 diseased valve's
held load a free-edge hex of the septal leaflet folded that way (corner volume ratio -0.008), and two of its own edges
crossed, which contact cannot see when it excludes a hex's own vertices. This term makes the
fold cost energy without bound, the way IPC makes a contact gap cost it.

Formulation
-----------
At corner :math:`c` of a hex with the neighbours :math:`a_1, a_2, a_3` along the element's three axes, the corner
Jacobian is proportional to the triple product of its edges,

.. math::

    J_c(x) = \det\,[x_{a_1} - x_c,\; x_{a_2} - x_c,\; x_{a_3} - x_c], \qquad r_c = J_c(x)/J_c(X),

(the factor between them, :math:`\pm 1/8`, cancels in the ratio :math:`r_c`, which is 1 in the reference). With a
threshold :math:`\hat r` and :math:`s = r/\hat r`, each corner adds

.. math::

    \Pi_c = k_c\,\phi(s), \qquad \phi(s) = -(1 - s)^2 \ln s \quad (0 < s < 1), \qquad \phi = 0 \quad (s \ge 1),

IPC's barrier (Li et al. 2020, *ACM Trans. Graph.* 39(4) 49) in the corner's volume ratio: zero with its first and
second derivatives at :math:`r = \hat r`, convex and unbounded as :math:`r \to 0`. Its weight :math:`k_c = \mu_e V_e/8`
is the element's small-strain shear modulus times its reference volume's share at the corner, so :math:`\Pi_c` is an
elastic energy of the element's own scale: :math:`\phi(1/2) = 0.17`. States whose corners all keep
:math:`r \ge \hat r` are not changed at all.

Derivatives, with :math:`e_i = x_{a_i} - x_c`: :math:`\partial J/\partial e_1 = e_2\times e_3` (cyclic),
:math:`\partial^2 J/\partial e_i\partial e_j = -[e_k]_\times` for :math:`(i, j, k)` cyclic, and

.. math::

    \nabla\Pi_c = \frac{k_c\,\phi'(s)}{\hat r J_c(X)}\,\nabla J_c, \qquad
    \nabla^2\Pi_c = k_c\Big[\frac{\phi''(s)}{(\hat r J_c(X))^2}\,\nabla J_c\otimes\nabla J_c
        + \frac{\phi'(s)}{\hat r J_c(X)}\,\nabla^2 J_c\Big],

:math:`\phi'(s) = 2(1-s)\ln s - (1-s)^2/s`, :math:`\phi''(s) = -2\ln s + 4(1-s)/s + (1-s)^2/s^2`. The projected
tangent clamps each corner's 12×12 block's negative eigenvalues.

Like IPC's collision-free step, :meth:`CornerBarrier.step_fraction` caps a straight move :math:`x + \alpha d` before
any corner's :math:`J_c` reaches zero: :math:`J_c(\alpha)` is a cubic in :math:`\alpha`, split at its critical points
into monotone pieces, and the first root is bracketed and bisected; the cap is 0.9 of it.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import skfem as fem

from ..errors import NonPositiveJacobianError, TangledMeshError
from ..space import Space, node_dofs
from ..terms import Contribution, Term

__all__ = ["CornerBarrier", "corner_barrier_phi", "hex_corner_stencils"]

#: a capped move takes this share of the fold-free fraction (as the contact's collision-free step)
STEP_SAFETY = 0.9
#: bisection steps for the first root of a corner's cubic (2**-60 of the bracket)
BISECTIONS = 60


def hex_corner_stencils(element: fem.Element | None = None) -> np.ndarray:
    """(8, 4) local node numbers ``[c, a1, a2, a3]``: each corner and its neighbours along the reference axes."""
    locs = np.asarray((element or fem.ElementHex1()).doflocs, dtype=float)
    stencils = np.empty((8, 4), dtype=np.int64)
    for c in range(8):
        stencils[c, 0] = c
        for axis in range(3):
            other = locs[c].copy()
            other[axis] = 1.0 - other[axis]
            stencils[c, axis + 1] = int(np.flatnonzero(np.all(locs == other, axis=1))[0])
    return stencils


def corner_barrier_phi(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r""":math:`\phi(s) = -(1-s)^2\ln s` and its first two derivatives, for :math:`0 < s < 1` (module docstring)."""
    s = np.asarray(s, dtype=float)
    log, gap = np.log(s), 1.0 - s
    return -gap**2 * log, 2.0 * gap * log - gap**2 / s, -2.0 * log + 4.0 * gap / s + gap**2 / s**2


def _triple(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, np.cross(b, c))


def _skew(v: np.ndarray) -> np.ndarray:
    """(n, 3, 3) matrices with ``_skew(v) @ w == cross(v, w)``."""
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


#: node dofs (12) -> edge vectors (9): e_i = x_{a_i} - x_c
_EDGES = np.zeros((9, 12))
for _i in range(3):
    _EDGES[3 * _i: 3 * _i + 3, 0:3] = -np.eye(3)
    _EDGES[3 * _i: 3 * _i + 3, 3 * _i + 3: 3 * _i + 6] = np.eye(3)


class CornerBarrier(Term):
    """The corner-Jacobian barrier on the trilinear hexes of ``space`` (module docstring).

    Parameters
    ----------
    space : a :class:`~skvalve.fem.space.Space` of trilinear hexes (order 1).
    moduli : the small-strain shear modulus per element (nel,) or one for all: the barrier's weight.
    threshold : :math:`\\hat r`, the corner volume ratio below which the barrier acts (0 < threshold < 1).
    elements : the hexes it guards (default all).
    """

    name = "corner barrier"

    def __init__(self, space: Space, moduli, threshold: float = 0.1, elements: np.ndarray | None = None) -> None:
        if space.family != "hex" or space.order != 1:
            raise ValueError(f"CornerBarrier needs trilinear hexes; got {space.family} of order {space.order}")
        if not 0.0 < threshold < 1.0:
            raise ValueError(f"CornerBarrier threshold must lie in (0, 1); got {threshold!r}")
        self.space, self.threshold = space, float(threshold)
        self.elements = np.arange(space.nel) if elements is None else np.asarray(elements, dtype=np.int64).ravel()
        moduli = np.broadcast_to(np.asarray(moduli, dtype=float), (space.nel,))[self.elements]
        if not np.all(np.isfinite(moduli) & (moduli > 0.0)):
            bad = self.elements[~(np.isfinite(moduli) & (moduli > 0.0))]
            raise ValueError(f"CornerBarrier: the shear modulus must be finite and > 0; elements {bad[:10].tolist()}")
        hexes = space.mesh.t.T[self.elements]  # (n, 8)
        self.nodes = hexes[:, hex_corner_stencils(space.element_u)].reshape(-1, 4)  # (8 n, 4)
        self.owner = np.repeat(self.elements, 8)
        self.dofs = (3 * self.nodes[:, :, None] + np.arange(3)).reshape(-1, 12)
        self.reference = self._determinants(space.mesh.p.T)
        locs = np.asarray(space.element_u.doflocs, dtype=float)
        orientation = (-1.0) ** locs.sum(axis=1)  # the edges point against the axes where the corner's xi is 1
        sign = (np.sign(self.reference).reshape(-1, 8) * orientation[None, :])
        tangled = ~np.all(sign == sign[:, :1], axis=1) | (sign[:, 0] == 0)
        if np.any(tangled):
            raise TangledMeshError(self.elements[tangled], " (corner barrier)")
        volumes = space.dx.sum(axis=1)[self.elements]
        self.weight = np.repeat(moduli * volumes / 8.0, 8)

    # ---------------------------------------------------------------- geometry
    def _edges(self, x: np.ndarray) -> np.ndarray:
        corners = x[self.nodes]  # (m, 4, 3)
        return corners[:, 1:] - corners[:, :1]

    def _determinants(self, x: np.ndarray) -> np.ndarray:
        e = self._edges(x)
        return _triple(e[:, 0], e[:, 1], e[:, 2])

    def positions(self, u: np.ndarray) -> np.ndarray:
        return self.space.mesh.p.T + u[: self.space.n_u].reshape(-1, 3)

    def ratios(self, u: np.ndarray) -> np.ndarray:
        """:math:`r_c = J_c(x)/J_c(X)` of every guarded corner at ``u`` (8 per element, in element order)."""
        return self._determinants(self.positions(u)) / self.reference

    def _checked_ratios(self, edges: np.ndarray, t: float, step: int | None) -> np.ndarray:
        """The ratios from the corners' ``edges`` (:meth:`_edges`); a folded corner raises, naming its element."""
        r = _triple(edges[:, 0], edges[:, 1], edges[:, 2]) / self.reference
        bad = ~(np.isfinite(r) & (r > 0.0))
        if np.any(bad):
            raise NonPositiveJacobianError(np.unique(self.owner[bad]), step, t, term=f"{self.name} (a folded corner)")
        return r

    # ------------------------------------------------------------------ terms
    def energy(self, u: np.ndarray, t: float) -> float:
        s = self._checked_ratios(self._edges(self.positions(u)), t, None) / self.threshold
        active = s < 1.0
        return float(np.sum(self.weight[active] * corner_barrier_phi(s[active])[0]))

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        n = self.space.n_dofs
        edges = self._edges(self.positions(u))
        s = self._checked_ratios(edges, t, step) / self.threshold
        active = np.flatnonzero(s < 1.0)
        internal = np.zeros(n)
        if active.size == 0:
            empty = sp.csr_matrix((n, n)) if tangent else None
            return Contribution(internal=internal, matrix=empty, projected_matrix=empty)
        e = edges[active]  # (a, 3, 3): e[:, i] = e_i
        grad_e = np.stack([np.cross(e[:, 1], e[:, 2]), np.cross(e[:, 2], e[:, 0]), np.cross(e[:, 0], e[:, 1])], 1)
        grad = grad_e.reshape(-1, 9) @ _EDGES  # (a, 12) = dJ/dx
        _, d1, d2 = corner_barrier_phi(s[active])
        scale = 1.0 / (self.threshold * self.reference[active])
        k = self.weight[active]
        np.add.at(internal, self.dofs[active], (k * d1 * scale)[:, None] * grad)
        matrix = projected = None
        if tangent:
            H_e = np.zeros((active.size, 9, 9))
            for i, j, m in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
                block = -_skew(e[:, m])
                H_e[:, 3 * i: 3 * i + 3, 3 * j: 3 * j + 3] = block
                H_e[:, 3 * j: 3 * j + 3, 3 * i: 3 * i + 3] = block.transpose(0, 2, 1)
            H_J = _EDGES.T @ H_e @ _EDGES
            blocks = (k * d2 * scale**2)[:, None, None] * grad[:, :, None] * grad[:, None, :] \
                + (k * d1 * scale)[:, None, None] * H_J
            values, vectors = np.linalg.eigh(blocks)
            clamped = np.einsum("aij,aj,akj->aik", vectors, np.maximum(values, 0.0), vectors)
            matrix, projected = self._sparse(active, blocks, n), self._sparse(active, clamped, n)
        return Contribution(internal=internal, matrix=matrix, projected_matrix=projected)

    def _sparse(self, active: np.ndarray, blocks: np.ndarray, n: int) -> sp.csr_matrix:
        dofs = self.dofs[active]
        rows = np.broadcast_to(dofs[:, :, None], blocks.shape).ravel()
        cols = np.broadcast_to(dofs[:, None, :], blocks.shape).ravel()
        return sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n, n))

    # ------------------------------------------------------------ step control
    def step_fraction(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> float:
        """0.9 of the share of the straight move from ``u0`` to ``u1`` before any corner's Jacobian reaches zero (1 when
        none does)."""
        roots = self._first_roots(u0, u1)
        smallest = float(roots.min()) if roots.size else 2.0
        return 1.0 if smallest > 1.0 else max(STEP_SAFETY * smallest, 1e-12)

    def crossed(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The dofs of the hexes that fold along the straight move from ``u0`` to ``u1`` (a corner whose Jacobian
        reaches zero before :data:`STEP_SAFETY` of it), each moved by its hex's mean increment: a translated hex keeps
        its corner ratios (a node of several such hexes takes their mean). ``None`` when none folds.

        A carried step start (:func:`~skvalve.fem.solvers.step_start.carried_start`) moves nearly flat hexes rigidly
        this way: on the 1.0 clip input a hex crushed by an arm to a corner ratio of 0.002 folded at 0.52 of a carried
        start whose increments differed by 0.01 mm over the hex (0.12 mm mean)."""
        roots = self._first_roots(u0, u1)
        folding = np.unique(self.owner[np.flatnonzero(roots < 1.0 / STEP_SAFETY)]) if roots.size else roots
        if folding.size == 0:
            return None
        hexes = self.space.mesh.t.T[folding]  # (f, 8)
        increment = (np.asarray(u1, dtype=float) - np.asarray(u0, dtype=float))[: self.space.n_u].reshape(-1, 3)
        mean = increment[hexes].mean(axis=1)  # (f, 3)
        nodes, where = np.unique(hexes, return_inverse=True)
        sums, counts = np.zeros((nodes.size, 3)), np.zeros(nodes.size)
        np.add.at(sums, where.ravel(), np.repeat(mean, 8, axis=0))
        np.add.at(counts, where.ravel(), 1.0)
        return node_dofs(nodes), (sums / counts[:, None]).ravel()

    def _first_roots(self, u0: np.ndarray, u1: np.ndarray) -> np.ndarray:
        """Per corner, the first share in (0, 1] of the straight move at which its Jacobian reaches zero (2 where it
        does not)."""
        e = self._edges(self.positions(u0))
        d = self._edges(self.positions(u1)) - e
        e1, e2, e3, d1, d2, d3 = e[:, 0], e[:, 1], e[:, 2], d[:, 0], d[:, 1], d[:, 2]
        c0 = _triple(e1, e2, e3)
        c1 = _triple(d1, e2, e3) + _triple(e1, d2, e3) + _triple(e1, e2, d3)
        c2 = _triple(e1, d2, d3) + _triple(d1, e2, d3) + _triple(d1, d2, e3)
        c3 = _triple(d1, d2, d3)
        sign = np.sign(self.reference)  # J / J(X) > 0 is the admissible side
        c0, c1, c2, c3 = sign * c0, sign * c1, sign * c2, sign * c3
        near = np.abs(c1) + np.abs(c2) + np.abs(c3) >= c0  # J(alpha) >= c0 - sum |c_k| > 0 on [0, 1] elsewhere
        roots = np.full(c0.size, 2.0)
        if np.any(near):
            roots[near] = _first_root(c0[near], c1[near], c2[near], c3[near])
        return roots


def _cubic(c0, c1, c2, c3, a):
    return c0 + a * (c1 + a * (c2 + a * c3))


def _first_root(c0: np.ndarray, c1: np.ndarray, c2: np.ndarray, c3: np.ndarray) -> np.ndarray:
    """The first root in (0, 1] of each cubic ``c0 + c1 a + c2 a² + c3 a³`` with ``c0 > 0`` (2 where none): the
    critical points split [0, 1] into monotone pieces, the first piece whose end is <= 0 holds it."""
    a, b, c = 3.0 * c3, 2.0 * c2, c1  # J'(alpha) = a alpha² + b alpha + c
    crit = np.full((c0.size, 2), 1.0)
    quadratic = np.abs(a) > 1e-300
    disc = b * b - 4.0 * a * c
    ok = quadratic & (disc >= 0.0)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        crit[ok, 0] = ((-b - sq) / (2.0 * a))[ok]
        crit[ok, 1] = ((-b + sq) / (2.0 * a))[ok]
        linear = ~quadratic & (np.abs(b) > 1e-300)
        crit[linear, 0] = (-c / b)[linear]
    crit = np.where((crit > 0.0) & (crit < 1.0), crit, 1.0)
    breaks = np.sort(np.column_stack([crit, np.ones(c0.size)]), axis=1)  # (n, 3), the last is 1
    values = _cubic(c0[:, None], c1[:, None], c2[:, None], c3[:, None], breaks)
    bad = values <= 0.0
    found = bad.any(axis=1)
    root = np.full(c0.size, 2.0)
    if not np.any(found):
        return root
    first = np.argmax(bad, axis=1)[found]
    rows = np.flatnonzero(found)
    hi = breaks[rows, first]
    lo = np.where(first > 0, breaks[rows, np.maximum(first - 1, 0)], 0.0)
    k0, k1, k2, k3 = c0[found], c1[found], c2[found], c3[found]
    for _ in range(BISECTIONS):  # J(lo) > 0 >= J(hi), monotone between
        mid = 0.5 * (lo + hi)
        positive = _cubic(k0, k1, k2, k3, mid) > 0.0
        lo, hi = np.where(positive, mid, lo), np.where(positive, hi, mid)
    root[found] = lo
    return root
