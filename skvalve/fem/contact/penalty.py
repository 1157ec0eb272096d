r"""Frictionless penalty contact of surfaces (self-contact of leaflets): node-to-triangle, two-pass.

Choice and why
--------------
A penalty node-to-surface method (own code, search by :class:`scipy.spatial.cKDTree`), not the IPC barrier
of ``ipctk`` (which installs here): IPC keeps every Newton iterate intersection-free only with a
continuous-collision-detection limit on each line-search step, and the solver's line search
(:mod:`skvalve.fem.solvers.newton`) has no hook for a term to cap the step; its barrier also acts at a positive
distance :math:`\hat d` with an adaptively raised stiffness, which changes the problem between load steps.
A penalty term needs nothing from the solver beyond the :class:`~skvalve.fem.terms.Term` protocol; its
price is a penetration :math:`p/\varepsilon` that shrinks with the penalty :math:`\varepsilon`.

Formulation
-----------
Each quadrilateral face of the surface is split into two triangles. Every surface node :math:`s` (slave)
is tested against the triangles :math:`(x_1, x_2, x_3)` of the same surface (master, both passes, so the
treatment is symmetric). With :math:`m = (x_2 - x_1)\times(x_3 - x_1)`, :math:`n = m/|m|` the triangle's
outward normal, the gap is the signed distance of the node from the triangle's plane,

.. math::

    g = (x_s - x_1)\cdot n ,

negative when the node has passed through the face. A pair is active when the node's projection lies in
the triangle (barycentric coordinates :math:`\ge -\epsilon`: the band extends the surface past its free edges,
so a node that slides just past a free edge keeps its force instead of dropping it; of several triangles
the one it had at the previous search while it stays valid, else the one whose smallest barycentric
coordinate is largest), :math:`-g_\text{max} < g < 0`,
the node's own normal opposes the face (:math:`n_s\cdot n < -c`), and the triangle is not in the node's
topological neighbourhood (``exclude_rings`` rings of faces). The energy and its derivatives are

.. math::

    p(h) = \begin{cases} \varepsilon h^2/(2h_0) & 0 < h < h_0 \\ \varepsilon(h - h_0/2) & h \ge h_0
    \end{cases}, \qquad f = -A_s\,p(h)\,\nabla g, \qquad
    K = A_s\,\big(p'(h)\,\nabla g\otimes\nabla g - p(h)\,\nabla^2 g\big),

with the overlap :math:`h = -g`, :math:`A_s` the node's reference tributary area and :math:`p` the contact
pressure: a penalty :math:`\varepsilon` whose first :math:`h_0` is rounded (``smoothing``) so that force and
stiffness are continuous when a pair switches on (a kink there makes Newton chatter between active sets;
:mod:`~skvalve.fem.contact.laws`, which also has the optional depth barrier). With
:math:`d = x_s - x_1`, :math:`a = x_2 - x_1`, :math:`b = x_3 - x_1`, :math:`\mu = |m|`,
:math:`P = I - n\otimes n` and :math:`w = P d/\mu`:

.. math::

    \frac{\partial g}{\partial d} = n,\quad \frac{\partial g}{\partial a} = b\times w,\quad
    \frac{\partial g}{\partial b} = w\times a, \qquad
    \frac{\partial^2 g}{\partial m^2} = -\frac{(n\cdot d)P + n\otimes P d + P d\otimes n}{\mu^2},\quad
    \frac{\partial^2 g}{\partial d\,\partial m} = \frac{P}{\mu},

and :math:`\partial^2 g/\partial a_i\partial b_j = \partial^2 g/\partial m^2` mapped by
:math:`\partial m/\partial a = -[b]_\times`, :math:`\partial m/\partial b = [a]_\times`, plus
:math:`\varepsilon_{ijk} w_k` from the bilinearity of :math:`m`. The active set is found afresh at every
assembly (the tangent is exact for a fixed set), so the tangent is returned as a sparse matrix on all dofs.

With ``blend`` > 0 the closest-triangle rule (its dead zones over concave creases, its search memory) gives way
to blended pairs (:mod:`skvalve.fem.contact.blend`): every nearby triangle carries a smooth share of the node's
penalty energy :math:`\psi(h)` (:math:`\psi' = p`), whose gradient and Hessian are the force and tangent.

Contact pressure (Abaqus CPRESS/CAREA): the nodal traction is the normal component of the total contact
force on a node over its tributary area, :math:`p_i = \max(-f_i\cdot n_i, 0)/A_i`; a face's pressure is
the mean over its nodes, and the contact area is the current area of the faces with positive pressure.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..space import Space
from ..terms import Contribution, Term
from .blend import BARRIER_FLOOR, DEEP_FADE, free_edges, pair_weights, sheets, weighted_mean_energy
from .geometry import (
    barycentric,
    barycentric_derivatives,
    gap_derivatives,
    near_pairs,
    plane_gap,
    smooth_step,
)
from .laws import depth_barrier, rounded_penalty
from .surface import ContactSurface, oriented_quads

#: Blended contact: the facing factor rises from 0 at -n_s.n = opposing to 1 this much above it.
FACING_BAND = 0.2

__all__ = ["ContactSurface", "ActivePairs", "SurfaceContact", "gap_derivatives", "oriented_quads"]


@dataclass
class ActivePairs:
    """Active node-triangle pairs at one state: slave node, triangle, gap and barycentric coordinates."""

    node: np.ndarray       # (n,) scalar node index
    triangle: np.ndarray   # (n,) triangle index into ContactSurface.triangles
    gap: np.ndarray        # (n,) signed gap (< 0)
    weights: np.ndarray    # (n, 3) barycentric coordinates of the projection
    facing: np.ndarray | None = None  # (n,) blended contact: the smooth opposing-normals factor (lagged)

    @property
    def size(self) -> int:
        return int(self.node.size)

    @property
    def touching(self) -> int:
        """Nodes that have passed through a face (the closest-triangle rule has one pair per node; blended contact
        lists a node's pairs with every nearby triangle, some just above their face)."""
        return int(np.unique(self.node[self.gap < 0.0]).size)


class SurfaceContact(Term):
    """Frictionless penalty self-contact of one surface (two-pass node-to-triangle; module docstring).

    Parameters
    ----------
    space : the 3D displacement :class:`~skvalve.fem.space.Space` (linear; surface nodes are its scalar dofs).
    surface : the :class:`ContactSurface` (for contact between two bodies, give the union of their faces).
    penalty : :math:`\\varepsilon`, pressure per unit penetration (e.g. kPa/mm), or a callable ``t -> value``.
    max_penetration : :math:`g_\\text{max}`, deeper passes are ignored (default: the mean face edge length).
    exclude_rings : a node never contacts faces within this many face rings of itself (self-contact).
    opposing : :math:`c` in :math:`n_s\\cdot n < -c` (normals must oppose).
    tolerance : barycentric band :math:`\\epsilon` past a triangle's edges (neighbours and free edges).
    smoothing : :math:`h_0`, the overlap over which the penalty is rounded (default 1 % of the mean edge).
    exclude_within : a node never contacts a triangle whose reference centroid lies closer than this (self-contact of
        a thick surface: across a free edge's rim the two skins are a thickness apart and, bent, seem to overlap).
    blend : 0 (default) for the closest-triangle rule; a band beta in (0, 0.5] for blended contact
        (:mod:`skvalve.fem.contact.blend`: every triangle near a node takes a smooth share, no search memory, energy
        continuous with its gradient across triangle edges; ``tolerance`` is then unused).
    barrier : ``None`` (default) for the penalty alone; a fraction :math:`h_s/g_\\text{max}` below
        ``BARRIER_FLOOR`` (0.76) from which a log barrier adds pressure that grows without bound as the overlap nears
        ``BARRIER_FLOOR`` :math:`g_\\text{max}`, just past the floor of the clearance limit (0.75), and fades past
        it by the deep fade (:func:`~skvalve.fem.contact.laws.depth_barrier`).
    """

    name = "contact"
    symmetric = True

    def __init__(self, space: Space, surface: ContactSurface, penalty, max_penetration: float | None = None,
                 exclude_rings: int = 2, opposing: float = 0.2, tolerance: float = 0.05,
                 smoothing: float | None = None, exclude_within: float = 0.0, blend: float = 0.0,
                 barrier: float | None = None) -> None:
        if space.dim != 3 or space.order != 1:
            raise ValueError("contact: needs a linear 3D displacement space")
        if surface.nodes.max() >= space.n_scalar:
            raise ValueError(f"contact: surface node {surface.nodes.max()} beyond the space's {space.n_scalar} nodes")
        self.space, self.surface = space, surface
        self.penalty = penalty if callable(penalty) else _constant(float(penalty), "penalty")
        self.X = space.mesh.p.T
        Q = self.X[surface.quads]
        edges = np.linalg.norm(Q - np.roll(Q, 1, axis=1), axis=2)
        self.max_penetration = float(edges.mean()) if max_penetration is None else float(max_penetration)
        if not (self.max_penetration > 0.0):
            raise ValueError(f"contact: max_penetration must be positive; got {max_penetration!r}")
        self.opposing, self.tolerance = float(opposing), float(tolerance)
        self.smoothing = 0.01 * float(edges.mean()) if smoothing is None else float(smoothing)
        if not (self.smoothing >= 0.0):
            raise ValueError(f"contact: smoothing must be >= 0; got {smoothing!r}")
        self.area = np.zeros(space.n_scalar)
        self.area[surface.nodes] = surface.nodal_area
        self._excluded = _neighbourhood_keys(surface, exclude_rings)
        if not (np.isfinite(exclude_within) and exclude_within >= 0.0):
            raise ValueError(f"contact: exclude_within must be finite and >= 0; got {exclude_within!r}")
        self.exclude_within = float(exclude_within)
        if not (0.0 <= blend <= 0.5):
            raise ValueError(f"contact: blend must lie in [0, 0.5]; got {blend!r}")
        self.blend = float(blend)
        if barrier is not None and not (0.0 <= barrier < BARRIER_FLOOR):
            raise ValueError(f"contact: barrier must lie in [0, {BARRIER_FLOOR}) (a fraction of max_penetration); "
                             f"got {barrier!r}")
        self.barrier = None if barrier is None else float(barrier)
        self._free_edges = free_edges(surface.triangles) if self.blend > 0.0 else None
        self._reference_centroids = self.X[surface.triangles].mean(axis=1)
        self.last_pairs: ActivePairs | None = None
        self._previous = np.full(space.n_scalar, -1, dtype=np.int64)  # triangle of each node at the last search
        self.last_force = np.zeros(space.n_u)
        self.last_energy = 0.0
        self.last_load_factor: float | None = None  # of the last assembly (the penalty's argument)
        self._assembled_u: np.ndarray | None = None
        self._committed_u: np.ndarray | None = None  # blended contact: the state whose normals give the facing

    def may_contact(self, node: np.ndarray, triangle: np.ndarray) -> np.ndarray:
        """(n,) bool: the node-triangle pairs that are not excluded (topological neighbours, or closer than
        ``exclude_within`` in the reference); the search and :mod:`~skvalve.fem.contact.clearance` both use it."""
        keys = node * self.surface.triangles.shape[0] + triangle
        if self._excluded.size:  # sorted unique keys: a binary search (np.isin re-sorts them on every call)
            at = np.minimum(np.searchsorted(self._excluded, keys), self._excluded.size - 1)
            keep = self._excluded[at] != keys
        else:
            keep = np.ones(keys.shape, dtype=bool)
        if self.exclude_within > 0.0:
            keep &= np.linalg.norm(self.X[node] - self._reference_centroids[triangle], axis=1) >= self.exclude_within
        return keep

    # ------------------------------------------------------------------ search
    def active_pairs(self, u: np.ndarray) -> ActivePairs:
        """Node-triangle pairs in contact at displacement ``u`` (module docstring for the rules)."""
        surface = self.surface
        x = self.X + u[: self.space.n_u].reshape(-1, 3)
        tri = surface.triangles
        corners = x[tri]  # (nt, 3, 3)
        centroid = corners.mean(axis=1)
        slaves = surface.nodes
        # each triangle's nodes within its own radius (one radius for all, the largest triangle's, listed 4.7
        # million candidates for 600 pairs on the 1.0 valve); node-major, as every later rule expects
        node, triangle = near_pairs(x[slaves], centroid, self.search_radius(corners, centroid))
        if node.size == 0:
            self._previous[:] = -1
            return _no_pairs()
        node = slaves[node]
        keep = self.may_contact(node, triangle)
        node, triangle = node[keep], triangle[keep]
        c = corners[triangle]
        gap, normal = plane_gap(x[node], c)
        if self.blend > 0.0:
            return self._blended_candidates(x, node, triangle, gap, c)
        ok = (gap < 0.0) & (gap > -self.max_penetration)
        ok &= np.einsum("ij,ij->i", self.node_normals(x)[node], normal) < -self.opposing
        node, triangle, gap, c, normal = node[ok], triangle[ok], gap[ok], c[ok], normal[ok]
        weights = barycentric(x[node], c)
        inside = weights.min(axis=1)
        ok = inside >= -self.tolerance
        node, triangle, gap, weights, inside = node[ok], triangle[ok], gap[ok], weights[ok], inside[ok]
        # one triangle per node: the one it had at the last search if still valid (a node on a vertex or an
        # edge of non-coplanar triangles would otherwise flip between them from one Newton iterate to the
        # next), else the one its projection lies deepest in
        kept = self._previous[node] == triangle
        order = np.lexsort((-inside, ~kept, node))
        first = np.ones(order.size, dtype=bool)
        first[1:] = node[order][1:] != node[order][:-1]
        pick = order[first]
        self._previous[:] = -1
        self._previous[node[pick]] = triangle[pick]
        return ActivePairs(node[pick], triangle[pick], gap[pick], weights[pick])

    def search_radius(self, corners: np.ndarray, centroid: np.ndarray) -> np.ndarray:
        """(n_triangles,) distance from each triangle's centroid within which every node it can pair with lies: a
        projection whose barycentric coordinates are >= -band lies in the triangle scaled by 1 + 3 band about its
        centroid, so within (1 + 3 band) r of it (r the triangle's largest centroid-corner distance), and the node
        within the search depth of it."""
        band = 2.0 * self.blend if self.blend > 0.0 else self.tolerance
        return (1.0 + 3.0 * band) * np.linalg.norm(corners - centroid[:, None], axis=2).max(axis=1) \
            + self.max_penetration

    def _blended_candidates(self, x, node, triangle, gap, corners) -> ActivePairs:
        r"""Every pair whose blended share is positive (:mod:`~skvalve.fem.contact.blend`), with its facing factor
        :math:`S((-n_s\cdot n - c)/0.2)` taken at the last committed state (the current one before any commit:
        its tangent then leaves out the factor's change) (lagged: a node normal depends on the
        node's neighbours, outside the pair; frozen within a step, the factor leaves the energy a function of the
        pair's four nodes and still switches a pair on and off smoothly as the normals turn)."""
        ok = (gap < self.above) & (gap > -self.max_penetration)
        node, triangle, gap, corners = node[ok], triangle[ok], gap[ok], corners[ok]
        weights = barycentric(x[node], corners)
        ok = np.all(weights > self.band_lower(triangle), axis=1)
        node, triangle, gap, weights = node[ok], triangle[ok], gap[ok], weights[ok]
        facing = self.facing(node, triangle, x)
        ok = facing > 0.0
        return ActivePairs(node[ok], triangle[ok], gap[ok], weights[ok], facing[ok])

    def band_lower(self, triangle: np.ndarray) -> np.ndarray:
        """(n, 3) the smallest barycentric coordinates at which a node's projection still pairs with each triangle:
        ``-tolerance`` (closest-triangle rule); blended, ``-2 blend`` opposite a free edge and ``-blend`` opposite a
        shared one."""
        if self.blend == 0.0:
            return np.full((np.size(triangle), 3), -self.tolerance)
        return np.where(self._free_edges[triangle], -2.0 * self.blend, -self.blend)

    def facing(self, node: np.ndarray, triangle: np.ndarray, x: np.ndarray) -> np.ndarray:
        """(n,) how far each node and triangle face each other: blended contact, the smooth factor
        :math:`S((-n_s\\cdot n - c)/0.2)` at the last committed state (``x``, the current positions, before any
        commit); closest-triangle rule, 1 where :math:`n_s\\cdot n < -c` at ``x``, else 0."""
        if self.blend > 0.0 and self._committed_u is not None:
            x = self.X + self._committed_u[: self.space.n_u].reshape(-1, 3)
        c = x[self.surface.triangles[triangle]]
        m = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
        cosine = np.einsum("ij,ij->i", self.node_normals(x)[node], m / np.linalg.norm(m, axis=1, keepdims=True))
        if self.blend == 0.0:
            return (cosine < -self.opposing).astype(float)
        return smooth_step((-cosine - self.opposing) / FACING_BAND)[0]

    def commit(self) -> None:
        """Blended contact: the last assembled state becomes the one whose normals set the facing factors."""
        if self.blend > 0.0 and self._assembled_u is not None:
            self._committed_u = self._assembled_u

    @property
    def above(self) -> float:
        """g_a of blended contact: a triangle this far above a node still counts in its normalisation."""
        return 0.25 * self.max_penetration

    def state(self) -> dict[str, np.ndarray]:
        """The search's memory: the triangle each node had at the last search (-1: none). With ``u`` it fixes the
        active set, which prefers those triangles (saved with a state that is to be evaluated again). Blended
        contact: the committed displacement whose normals set the facing factors (if any)."""
        out = {"previous_triangle": self._previous.copy()}
        if self._committed_u is not None:
            out["committed_displacement"] = self._committed_u.copy()
        return out

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        """Give back what :meth:`state` took (nothing given: nothing changes)."""
        committed = arrays.get("committed_displacement")
        if committed is not None:
            committed = np.asarray(committed, dtype=float)
            if committed.shape != (self.space.n_dofs,) or not np.all(np.isfinite(committed)):
                raise ValueError(f"contact: committed_displacement must be {self.space.n_dofs} finite values; got "
                                 f"shape {committed.shape}")
            self._committed_u = committed.copy()
        previous = arrays.get("previous_triangle")
        if previous is None:
            return
        previous = np.asarray(previous)
        if previous.shape != self._previous.shape or (previous.size and (
                previous.min() < -1 or previous.max() >= self.surface.triangles.shape[0])):
            raise ValueError(f"contact: previous_triangle must be {self._previous.shape[0]} triangle indices "
                             f"(-1 for none); got shape {previous.shape}")
        self._previous[:] = previous

    def node_normals(self, x: np.ndarray) -> np.ndarray:
        """Unit normal (n_nodes, 3) of each surface node at positions ``x``: the mean of its faces' (zero off the
        surface)."""
        Q = x[self.surface.quads]
        face = np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1])
        normals = np.zeros_like(x)
        np.add.at(normals, self.surface.quads.ravel(), np.repeat(face, 4, axis=0))
        length = np.linalg.norm(normals, axis=1, keepdims=True)
        return np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)

    # ---------------------------------------------------------------- assembly
    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        self.last_load_factor = float(t)
        if self.blend > 0.0:  # the state whose normals give the facing factors once committed
            self._assembled_u = np.array(u, dtype=float)
        pairs = self.active_pairs(u)
        return self.assemble_pairs(u, t, pairs, tangent)

    def assemble_pairs(self, u: np.ndarray, t: float, pairs: ActivePairs, tangent: bool) -> Contribution:
        """Forces and tangent of a given (fixed) active set."""
        n_dofs = self.space.n_dofs
        self.last_pairs = pairs
        internal = np.zeros(n_dofs)
        if pairs.size == 0:
            self.last_force = np.zeros(self.space.n_u)
            self.last_energy = 0.0
            return Contribution(internal=internal, matrix=sp.csr_matrix((n_dofs, n_dofs)) if tangent else None)
        x = self.X + u[: self.space.n_u].reshape(-1, 3)
        tri = self.surface.triangles[pairs.triangle]
        corners = (x[pairs.node], x[tri[:, 0]], x[tri[:, 1]], x[tri[:, 2]])
        g, grad, hess = gap_derivatives(*corners, tangent)
        dofs = (3 * np.column_stack([pairs.node, tri])[:, :, None] + np.arange(3)).reshape(-1, 12)
        penalty = float(self.penalty(t))
        if self.blend > 0.0:
            return self._assemble_blended(pairs, corners, (g, grad, hess), penalty, dofs, tangent)
        energy, pressure, stiffness = self.contact_law(-g, penalty)
        area = self.area[pairs.node]
        forces = -(area * pressure)[:, None] * grad
        self.last_energy = float(np.sum(area * energy))
        np.add.at(internal, dofs.ravel(), forces.ravel())
        self.last_force = internal[: self.space.n_u].copy()
        matrix = None
        if tangent:
            blocks = area[:, None, None] * (stiffness[:, None, None] * grad[:, :, None] * grad[:, None, :]
                                            - pressure[:, None, None] * hess)
            rows = np.repeat(dofs, 12, axis=1).ravel()
            cols = np.tile(dofs, (1, 12)).ravel()
            matrix = sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n_dofs, n_dofs))
        return Contribution(internal=internal, matrix=matrix)

    def _assemble_blended(self, pairs, corners, gap, penalty: float, dofs, tangent) -> Contribution:
        """Blended contact (:mod:`skvalve.fem.contact.blend`) of the candidate pairs (some above their face)."""
        g, g_grad, g_hess = gap
        overlap = np.maximum(-g, 0.0)
        psi, pressure, stiffness = self.contact_law(overlap, penalty)
        stiffness = np.where(g < 0.0, stiffness, 0.0)  # an unrounded law has stiffness at zero overlap
        psi_grad = -pressure[:, None] * g_grad
        psi_hess = None
        if tangent:
            psi_hess = stiffness[:, None, None] * g_grad[:, :, None] * g_grad[:, None, :] \
                - pressure[:, None, None] * g_hess
        lam, lam_grad, lam_hess = barycentric_derivatives(*corners, tangent)
        phi, phi_grad, phi_hess = pair_weights(lam, lam_grad, lam_hess, g, g_grad, g_hess,
                                               self._free_edges[pairs.triangle], self.blend, self.max_penetration,
                                               self.above, tangent)
        facing = np.ones(pairs.size) if pairs.facing is None else pairs.facing
        phi, phi_grad = facing * phi, facing[:, None] * phi_grad
        if tangent:
            phi_hess = facing[:, None, None] * phi_hess
        group = sheets(pairs.node, self.surface.triangles[pairs.triangle])
        internal, matrix, self.last_energy = weighted_mean_energy(
            pairs.node, group, dofs, self.area, phi, phi_grad, phi_hess, psi, psi_grad, psi_hess, self.space.n_dofs,
            tangent)
        self.last_force = internal[: self.space.n_u].copy()
        return Contribution(internal=internal, matrix=matrix)

    def energy(self, u: np.ndarray, t: float = 1.0) -> float:
        """The contact energy at ``u`` (load factor ``t`` for the penalty): its gradient is the internal force."""
        self.assemble(u, t, False, None)
        return self.last_energy

    def contact_law(self, overlap: np.ndarray, penalty: float):
        """Energy per area psi(h), pressure p(h) = psi'(h) and dp/dh at overlaps ``h`` >= 0: the rounded penalty plus,
        with ``barrier``, the depth barrier (:mod:`~skvalve.fem.contact.laws`)."""
        energy, pressure, stiffness = rounded_penalty(overlap, penalty, self.smoothing)
        if self.barrier is None:
            return energy, pressure, stiffness
        extra = depth_barrier(overlap, penalty, self.barrier * self.max_penetration,
                              BARRIER_FLOOR * self.max_penetration, DEEP_FADE * self.max_penetration)
        return energy + extra[0], pressure + extra[1], stiffness + extra[2]

    # ----------------------------------------------------------------- output
    def nodal_pressure(self, u: np.ndarray, force: np.ndarray | None = None) -> np.ndarray:
        """Contact pressure per node (n_scalar,): compressive normal contact force over tributary area.

        ``force``: the term's internal force (n_u,) at ``u`` (default: that of the last assembly)."""
        force = self.last_force if force is None else force
        x = self.X + u[: self.space.n_u].reshape(-1, 3)
        normals = self.node_normals(x)
        # ``force`` is the residual contribution (internal force): the contact acts on the node with -force
        normal_force = np.einsum("ij,ij->i", force.reshape(-1, 3), normals)
        pressure = np.zeros(self.space.n_scalar)
        nodes = self.surface.nodes
        pressure[nodes] = np.maximum(normal_force[nodes], 0.0) / self.area[nodes]
        return pressure

    def face_pressure(self, u: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Contact pressure per face (n_faces,) at ``u`` (load factor ``t`` for the penalty): mean of its nodes'."""
        force = self.assemble(u, t, False, None).internal[: self.space.n_u]
        return self.nodal_pressure(u, force)[self.surface.quads].mean(axis=1)

    def contact_area(self, u: np.ndarray, pressure: np.ndarray | None = None, threshold: float = 0.0,
                     t: float = 0.0) -> float:
        """Current area of the faces whose pressure exceeds ``threshold`` (Abaqus CAREA of the surface)."""
        pressure = self.face_pressure(u, t) if pressure is None else pressure
        x = self.X + u[: self.space.n_u].reshape(-1, 3)
        Q = x[self.surface.quads]
        area = 0.5 * np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]), axis=1)
        return float(area[pressure > threshold].sum())


def _constant(value: float, name: str):
    if not (np.isfinite(value) and value > 0.0):
        raise ValueError(f"contact: {name} must be positive and finite; got {value!r}")
    return lambda t: value


def _no_pairs() -> ActivePairs:
    empty = np.zeros(0, dtype=np.int64)
    return ActivePairs(empty, empty, np.zeros(0), np.zeros((0, 3)))


def _neighbourhood_keys(surface: ContactSurface, rings: int) -> np.ndarray:
    """Sorted keys ``node * n_triangles + triangle`` of the pairs excluded as topological neighbours."""
    n_nodes = int(surface.quads.max()) + 1
    n_faces = surface.quads.shape[0]
    incidence = sp.csr_matrix((np.ones(surface.quads.size), (np.repeat(np.arange(n_faces), 4),
                                                             surface.quads.ravel())), shape=(n_faces, n_nodes))
    near = incidence.T.tocsr()  # node -> faces containing it (ring 1)
    for _ in range(max(rings, 1) - 1):
        near = ((near @ incidence) @ incidence.T).tocsr()  # faces sharing a node with the current ring
    near = near.tocoo()
    n_triangles = surface.triangles.shape[0]
    node, face = near.row.astype(np.int64), near.col.astype(np.int64)
    keys = np.concatenate([node * n_triangles + 2 * face, node * n_triangles + 2 * face + 1])
    return np.unique(keys)
