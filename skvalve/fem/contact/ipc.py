r"""Incremental Potential Contact: a barrier that never lets surfaces pass through (ipctk).

Choice and why
--------------
Contact by the IPC barrier of Li et al. (2020, *ACM Trans. Graph.* 39(4) 49) through the well-kept library
``ipctk`` (MIT; collision sets, barrier derivatives with per-stencil PSD projection, exact continuous collision
detection), not our own code: its guarantee -- no accepted state ever intersects -- needs exact CCD of
point–triangle and edge–edge trajectories, which is hard to get right and is what ipctk does best. The penalty law of
:mod:`skvalve.fem.contact.penalty` admits pass-through minima by construction (past its search depth a node feels no
force); this one has none: the energy grows without bound as any distance goes to zero, and every solver caps its
trial steps at the collision-free fraction (:meth:`IPCContact.step_fraction`, continuous collision detection times
0.9), so iterates stay on the side they started.

Formulation
-----------
The collision mesh is the body's boundary (hex faces split into triangles, :class:`~.surface.ContactSurface`) with any
:class:`~.obstacles.Obstacle` surfaces (prescribed motion); fixed :class:`~.obstacles.Plane` s have their own closed
form (:mod:`.plane_barrier`: ipctk 1.6.1 finds plane–vertex pairs only within :math:`\hat d/2`). For the set
:math:`\mathcal C` of primitive pairs (point–triangle, edge–edge, point–plane and their degenerate cases) closer than
:math:`\hat d`, the barrier potential is

.. math::

    B(x) = \kappa \sum_{k\in\mathcal C} w_k\, \frac{b(d_k^2(x))}{\hat d^{\,3}}, \qquad
    b(s) = -(s - \hat d^2)^2 \ln\frac{s}{\hat d^2} \quad (0 < s < \hat d^2),

with :math:`w_k` the pair's area weight (ipctk's area weighting: the vertex area for a point–plane pair) and the
physical scaling :math:`\hat d^{-3}`, so that :math:`\kappa` is a **pressure** (force per area; kPa for N, mm and
the valve's units): a vertex of area :math:`A` at distance :math:`d` from a plane carries the force
:math:`A\,p(d)`, :math:`p(d) = -2d\,\kappa\,b'(d^2)/\hat d^3` (:func:`barrier_pressure`). :math:`\hat d` is a length
(the range of the barrier: keep it below the smallest gap that must stay open at rest, e.g. a leaflet's thickness, and
below the mesh size); :func:`stiffness_for_pressure` picks :math:`\kappa` so that a given pressure is carried at a
given fraction of :math:`\hat d`, and :meth:`IPCContact.suggest_stiffness` is IPC's own rule
(``initial_barrier_stiffness``: the stiffness that balances the elastic gradient). With ``adaptive`` the stiffness is
doubled after a step whose smallest distance fell below :math:`10^{-9}` of the bounding box diagonal
(``update_barrier_stiffness``), which changes the problem between steps; it is off by default.

Pairs of body vertices closer than ``exclude_within`` in the reference never collide (ipctk ``make_sparse_filter``:
the two skins of a thin shell across a free edge), nor do two obstacle vertices (``make_vertex_patches_filter``).

Friction (optional, :class:`Friction`): the smoothed Coulomb potential of IPC, lagged: the normal forces and the
tangent bases are those of the last committed state, and the sliding is the displacement of the collision vertices
since then, mollified below the slip length :math:`\epsilon` (Li et al. 2020, Sect. 5; ipctk
``TangentialCollisions``/``FrictionPotential``); planes are frictionless.

Output: per-vertex contact pressure is the barrier force's magnitude over the vertex's area weight (a third of the
reference area of its triangles, so that a vertex facing a plane reports exactly :math:`p(d)`); a face's pressure is
the mean of its nodes', and the contact area (Abaqus CAREA) the current area of the faces all of whose nodes touch
(both touching sides count). Between two surfaces the forces balance exactly, but ipctk's collision set is not a
consistent surface integral, so the pressure there is not :math:`p(d)` of the local gap: two parallel unit squares at
one gap weigh 5.7, 6.3 and 6.7 times :math:`b` for 4, 8 and 16 divisions (measured; 1.6–1.7 with its improved max
approximation), so :math:`\kappa` sets the gap's scale, not a calibrated pressure law, for surface pairs.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass

import ipctk
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..errors import StateRefused
from ..space import Space, node_dofs
from ..terms import Contribution, Term
from .activation import CollisionPhase, CollisionPhases
from .obstacles import Obstacle, Plane
from .plane_barrier import PlaneBarrier
from .push import crossing_followers, pushed_vertices
from .surface import ContactSurface

__all__ = ["IPCContact", "Friction", "IntersectionError", "barrier_pressure", "stiffness_for_pressure"]

logger = logging.getLogger("skvalve.fem")

#: a capped step takes this share of the collision-free fraction (IPC's line search)
STEP_SAFETY = 0.9
#: the smallest fraction a term returns (a start state in touching contact would otherwise give 0)
SMALLEST_FRACTION = 1e-12
#: the longest move (in mean surface-edge lengths) that one CCD sweeps; a longer trial is checked on its first part.
#: The broad phase's candidate pairs grow with the square of the swept length on a sheet: on the 1.0 annuloplasty
#: valve one Newton direction of its path made ipctk's broad phase allocate more than 11 GB
CCD_REACH_EDGES = 10.0


class IntersectionError(StateRefused):
    """A state whose collision mesh intersects itself (:meth:`IPCContact.check_state`): where the collision-free step
    cannot prevent it, between primitives excluded from contact (``exclude_within``)."""


@dataclass(frozen=True)
class Friction:
    """Smoothed, lagged Coulomb friction: coefficient ``mu`` and slip length ``slip`` (below it, sticking is
    a stiff spring; in length units)."""

    mu: float
    slip: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.mu) and self.mu >= 0.0):
            raise ValueError(f"friction: mu must be finite and >= 0; got {self.mu!r}")
        if not (np.isfinite(self.slip) and self.slip > 0.0):
            raise ValueError(f"friction: slip must be a positive length; got {self.slip!r}")


def barrier_pressure(distance, dhat: float, stiffness: float) -> np.ndarray:
    r"""Pressure :math:`p(d) = -2d\,\kappa\,b'(d^2)/\hat d^3` of the area-weighted physical barrier at ``distance``
    (0 at and beyond :math:`\hat d`): the force per area on a vertex facing a plane (module docstring)."""
    d = np.asarray(distance, dtype=float)
    s, sh = d * d, dhat * dhat
    with np.errstate(divide="ignore", invalid="ignore"):
        derivative = -2.0 * (s - sh) * np.log(s / sh) - (s - sh) ** 2 / s
        p = -2.0 * d * stiffness * derivative / dhat ** 3
    return np.where(d < dhat, p, 0.0)


def stiffness_for_pressure(pressure: float, dhat: float, at: float = 0.5) -> float:
    """The barrier stiffness :math:`\\kappa` (a pressure) carrying ``pressure`` at the distance ``at`` × ``dhat``."""
    if not (0.0 < at < 1.0):
        raise ValueError(f"stiffness_for_pressure: at must lie in (0, 1); got {at!r}")
    if not (np.isfinite(pressure) and pressure > 0.0 and np.isfinite(dhat) and dhat > 0.0):
        raise ValueError(f"stiffness_for_pressure: pressure and dhat must be positive; got {pressure!r}, {dhat!r}")
    return float(pressure / barrier_pressure(at * dhat, dhat, 1.0))


class IPCContact(Term):
    r"""IPC barrier contact of a body's surface with itself, with moving obstacles and with planes.

    Parameters
    ----------
    space : the 3D displacement :class:`~skvalve.fem.space.Space` (linear; surface nodes are its scalar dofs).
    surface : the body's :class:`~.surface.ContactSurface` (default: every boundary facet of the mesh).
    dhat : :math:`\hat d`, the barrier's range (length).
    stiffness : :math:`\kappa`, a pressure (module docstring; :func:`stiffness_for_pressure`).
    obstacles, planes : kinematic surfaces and fixed planes the body must not pass.
    exclude_within : body vertices closer than this in the reference never collide with each other.
    friction : optional :class:`Friction` (lagged).
    check_intersections : after each accepted state, raise :class:`IntersectionError` if the surface intersects
        (ipctk ``has_intersections``; costs a full check: for debug runs and tests).
    adaptive : raise :math:`\kappa` as IPC does after steps that bring surfaces very close (off: a fixed problem).
    self_contact : False to drop contact of the body with itself (obstacles and planes only).
    threads : ipctk's thread count, a process-wide setting (None: leave it as it is). 1 by default: ipctk's threaded
        sums differ in the last bits from run to run, and a closure whose path branches (a symmetric two-leaflet
        valve whose free edges meet) then took 118-121 iterations to different states in four runs; on one thread the
        runs are bitwise the same (``tests/test_valve_close_mini.py``).
    """

    name = "ipc contact"
    symmetric = True

    def __init__(self, space: Space, surface: ContactSurface | None = None, *, dhat: float, stiffness: float,
                 obstacles: Sequence[Obstacle] = (), planes: Sequence[Plane] = (), exclude_within: float = 0.0,
                 friction: Friction | None = None, check_intersections: bool = False, adaptive: bool = False,
                 self_contact: bool = True, threads: int | None = 1) -> None:
        if threads is not None:
            if not isinstance(threads, int) or isinstance(threads, bool) or threads < 1:
                raise ValueError(f"ipc contact: threads must be None or an integer >= 1; got {threads!r}")
            ipctk.set_num_threads(threads)
        if space.dim != 3 or space.order != 1:
            raise ValueError("ipc contact: needs a linear 3D displacement space")
        if not (np.isfinite(dhat) and dhat > 0.0):
            raise ValueError(f"ipc contact: dhat must be a positive length; got {dhat!r}")
        if not (np.isfinite(stiffness) and stiffness > 0.0):
            raise ValueError(f"ipc contact: stiffness must be a positive pressure; got {stiffness!r}")
        if not (np.isfinite(exclude_within) and exclude_within >= 0.0):
            raise ValueError(f"ipc contact: exclude_within must be a length >= 0; got {exclude_within!r}")
        mesh = space.mesh
        if surface is None:
            surface = ContactSurface.from_facets(mesh, mesh.boundary_facets())
        if surface.nodes.max() >= space.n_scalar:
            raise ValueError(f"ipc contact: surface node {surface.nodes.max()} beyond the space's {space.n_scalar}")
        self.space, self.surface = space, surface
        self.dhat, self.stiffness = float(dhat), float(stiffness)
        self.obstacles, self.planes = list(obstacles), list(planes)
        self.friction, self.check_intersections, self.adaptive = friction, bool(check_intersections), bool(adaptive)
        self.X = mesh.p.T
        self.nodes = surface.nodes
        self.n_body = self.nodes.size
        local = np.full(space.n_scalar, -1, dtype=np.int64)
        local[self.nodes] = np.arange(self.n_body)
        rest = [self.X[self.nodes]]
        offset = self.n_body
        self._obstacle_rows = []
        for obstacle in self.obstacles:
            rest.append(obstacle.at(0.0))
            self._obstacle_rows.append(slice(offset, offset + obstacle.vertices.shape[0]))
            offset += obstacle.vertices.shape[0]
        self.rest = np.ascontiguousarray(np.concatenate(rest))
        self.diagonal = float(ipctk.world_bbox_diagonal_length(self.rest))
        corners = self.X[surface.triangles]
        edge = float(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).mean())
        self.reach = CCD_REACH_EDGES * edge  # the longest move one CCD sweeps (step_fraction)
        self.barrier = ipctk.BarrierPotential(self.dhat, self.stiffness, True)
        self.collisions = ipctk.NormalCollisions()
        self.collisions.use_area_weighting = True
        self._built_for: tuple[tuple[bool, ...], np.ndarray] | None = None
        rows = node_dofs(self.nodes)
        select = sp.csr_matrix((np.ones(rows.size), (rows, np.arange(rows.size))),
                               shape=(space.n_dofs, 3 * self.rest.shape[0]))
        self._phases = CollisionPhases(self.rest, self.n_body, local[surface.triangles], self.obstacles,
                                       self._obstacle_rows, self._body_filter(exclude_within, self_contact),
                                       self_contact, select)
        phase = self._enter(0.0)
        self.area = np.zeros(space.n_scalar)  # the barrier's area weights: a third of each adjacent triangle
        self.area[self.nodes] = np.asarray(phase.mesh.vertex_areas)[: self.n_body]  # the body's faces in any phase
        self._planes = PlaneBarrier(self.planes, self.area[self.nodes], self.dhat) if self.planes else None
        self._friction_potential = None if friction is None else ipctk.FrictionPotential(friction.slip)
        self._tangential = None
        self._lagged = self.rest.copy()
        self._committed_u = np.zeros(space.n_dofs)
        self._committed_t = 0.0
        self._last: tuple[np.ndarray, float] | None = None
        self._previous_distance: float | None = None
        self.max_stiffness = 1e3 * self.stiffness
        self.last_force = np.zeros(space.n_dofs)
        self.last_distance = np.inf
        if self.intersects(np.zeros(space.n_dofs), 0.0):
            raise IntersectionError("ipc contact: the reference collision mesh intersects itself (check the surface "
                                    "and the obstacles' positions at load factor 0)")

    # ------------------------------------------------------------------ set-up
    def _body_filter(self, exclude_within: float, self_contact: bool) -> ipctk.CollisionFilter | None:
        """Body vertices closer than ``exclude_within`` in the reference never collide (obstacle vertices never
        collide with each other, nor, without ``self_contact``, body vertices: :mod:`.activation`)."""
        if not (exclude_within > 0.0 and self_contact):
            return None
        pairs = cKDTree(self.rest[: self.n_body]).query_pairs(exclude_within, output_type="ndarray")
        return ipctk.make_sparse_filter({(int(min(a, b)), int(max(a, b))): False for a, b in pairs}, True)

    def _enter(self, t: float) -> CollisionPhase:
        """Make the phase at load factor ``t`` (the obstacles active then) the current collision mesh."""
        phase = self._phases.at(t)
        self.mesh, self._select, self._phase = phase.mesh, phase.select, phase
        return phase

    def _collisions_at(self, V: np.ndarray) -> ipctk.NormalCollisions:
        """The collision set at positions ``V``, built once per state (assembly, energy and output share it)."""
        key = self._phase.key
        if self._built_for is None or self._built_for[0] != key or not np.array_equal(self._built_for[1], V):
            self.collisions.build(self.mesh, V, self.dhat)
            self._built_for = (key, V.copy())
        return self.collisions

    def forget_collisions(self) -> None:
        """Drop the collision set kept for the last state (the next evaluation builds it again)."""
        self._built_for = None

    def positions(self, u: np.ndarray, t: float, phase_at: float | None = None) -> np.ndarray:
        """Collision-mesh vertex positions (n, 3): the body's surface at ``u``, the obstacles active at load factor
        ``phase_at`` (default ``t``; that phase becomes the current mesh) where they are at ``t``."""
        phase = self._enter(t if phase_at is None else phase_at)
        V = self.rest[phase.rows]
        V[: self.n_body] += u[: self.space.n_u].reshape(-1, 3)[self.nodes]
        for obstacle, rows in zip(self.obstacles, phase.slices, strict=True):
            if rows is not None:
                V[rows] = obstacle.at(t)
        return V

    def suggest_stiffness(self, elastic_gradient: np.ndarray, u: np.ndarray, t: float,
                          average_mass: float = 1.0) -> tuple[float, float]:
        """IPC's initial stiffness (ipctk ``initial_barrier_stiffness``) at state ``u``: the :math:`\\kappa` whose
        barrier gradient balances ``elastic_gradient`` (n_dofs,: the other terms' residual), and its upper bound."""
        V = self.positions(u, t)
        self._collisions_at(V)
        unit = ipctk.BarrierPotential(self.dhat, 1.0, True)
        grad_barrier = unit.gradient(self.collisions, self.mesh, V)
        grad_barrier[3 * self.n_body:] = 0.0  # obstacle vertices are no unknowns: their reactions must not count
        grad_energy = self._select.T @ np.asarray(elastic_gradient, dtype=float)
        return tuple(float(v) for v in ipctk.initial_barrier_stiffness(
            self.diagonal, unit.barrier, self.dhat, average_mass, grad_energy, grad_barrier))

    # ---------------------------------------------------------------- assembly
    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        V = self.positions(u, t)
        self._collisions_at(V)
        grad = self.barrier.gradient(self.collisions, self.mesh, V)
        matrix = projected = None
        if tangent:
            H = self.barrier.hessian(self.collisions, self.mesh, V, ipctk.PSDProjectionMethod.NONE)
            Hp = self.barrier.hessian(self.collisions, self.mesh, V, ipctk.PSDProjectionMethod.CLAMP)
        if self._planes is not None:
            plane_grad, plane_H, plane_Hp = self._planes.derivatives(V, self.stiffness, tangent)
            grad = grad + plane_grad
            if tangent:
                H, Hp = H + plane_H, Hp + plane_Hp
        if self._tangential is not None and len(self._tangential) and self._lagged.shape == V.shape:
            slip = V - self._lagged
            grad = grad + self._friction_potential.gradient(self._tangential, self.mesh, slip)
            if tangent:
                Hf = self._friction_potential.hessian(self._tangential, self.mesh, slip,
                                                      ipctk.PSDProjectionMethod.NONE)
                H = H + Hf
                Hp = Hp + self._friction_potential.hessian(self._tangential, self.mesh, slip,
                                                           ipctk.PSDProjectionMethod.CLAMP)
        internal = self._select @ grad
        if tangent:
            matrix = (self._select @ H @ self._select.T).tocsr()
            projected = (self._select @ Hp @ self._select.T).tocsr()
        self.last_force = internal
        self._last = (np.array(u, copy=True), float(t))
        return Contribution(internal=internal, matrix=matrix, projected_matrix=projected)

    def energy(self, u: np.ndarray, t: float) -> float:
        """:math:`B(x)` (plus the lagged friction potential)."""
        V = self.positions(u, t)
        self._collisions_at(V)
        value = float(self.barrier(self.collisions, self.mesh, V))
        if self._planes is not None:
            value += self._planes.energy(V, self.stiffness)
        if self._tangential is not None and len(self._tangential) and self._lagged.shape == V.shape:
            value += float(self._friction_potential(self._tangential, self.mesh, V - self._lagged))
        return value

    def minimum_distance(self, u: np.ndarray, t: float) -> float:
        """The smallest distance between primitives that may collide, within :math:`\\hat d` (inf beyond it)."""
        return self._minimum_distance(self.positions(u, t))

    def _minimum_distance(self, V: np.ndarray) -> float:
        distance = float("inf")
        if len(self._collisions_at(V)):
            distance = float(np.sqrt(self.collisions.compute_minimum_distance(self.mesh, V)))
        for plane in self.planes:
            near = plane.distance(V[: self.n_body])
            near = near[near < self.dhat]
            if near.size:
                distance = min(distance, float(near.min()))
        return distance

    def active_pairs(self, u: np.ndarray, t: float) -> int:
        """The number of primitive pairs within :math:`\\hat d` at ``u``, ``t``."""
        return len(self._collisions_at(self.positions(u, t)))

    # ------------------------------------------------------------ step control
    def step_fraction(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> float:
        """0.9 of the collision-free share of the straight move (ipctk ``compute_collision_free_stepsize``), 1 when
        the whole move is free. A move on which some vertex travels farther than :attr:`reach` (``CCD_REACH_EDGES``
        mean edge lengths) is checked on its first ``reach`` only: the share up to there when that part is free (the
        caller's line search starts there), else 0.9 of the collision-free share as before."""
        V0 = self.positions(u0, t0, phase_at=t1)  # the obstacles active at the end of the move, from its start
        before = self._phases.key(t0)
        if before != self._phase.key and ipctk.has_intersections(self.mesh, V0):
            joining = [o.name for o, was, now in zip(self.obstacles, before, self._phase.key, strict=True)
                       if now and not was]
            raise IntersectionError(f"ipc contact: obstacle(s) {', '.join(joining)} join the contact by load factor "
                                    f"{t1:.6g} while the body overlaps them (at {t0:.6g})")
        V1 = self.positions(u1, t1)
        move = float(np.sqrt(np.max(np.sum((V1 - V0) ** 2, axis=1), initial=0.0)))
        share = 1.0
        if move > self.reach:
            share = self.reach / move
            V1 = V0 + share * (V1 - V0)
            logger.debug("ipc contact: a trial move of %.3g (reach %.3g): CCD on its first %.3g", move, self.reach,
                         share)
        fraction = float(ipctk.compute_collision_free_stepsize(self.mesh, V0, V1))
        if self._planes is not None:
            fraction = min(fraction, self._planes.step_fraction(V0, V1))
        return share if fraction >= 1.0 else max(STEP_SAFETY * share * fraction, SMALLEST_FRACTION)

    def pushed(self, u: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The body's surface dofs that the obstacles in contact at ``t1`` push on their way from ``t0`` (the
        surface at ``u``), with the motion of their closest obstacle points (:mod:`.push`; the first obstacle's
        where two push one vertex)."""
        V = self.positions(u, t0, phase_at=t1)
        nodes, increments = [], []
        for obstacle, rows in zip(self.obstacles, self._phase.slices, strict=True):
            if rows is None:
                continue
            index, increment = pushed_vertices(V[: self.n_body], V[rows], obstacle.at(t1), obstacle.triangles,
                                               self.dhat)
            nodes.append(self.nodes[index])
            increments.append(increment)
        if not nodes or not sum(n.size for n in nodes):
            return None
        nodes, first = np.unique(np.concatenate(nodes), return_index=True)
        return node_dofs(nodes), np.concatenate(increments)[first].ravel()

    def crossed(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The body's surface dofs on a side of a primitive pair (point-triangle, edge-edge) whose straight move from
        ``(u0, t0)`` to ``(u1, t1)`` collides (ipctk's narrow-phase CCD), each moving with the other side, which
        crosses it: an obstacle's side always (by its rigid motion), else the side that moves more
        (:func:`~.push.crossing_followers`)."""
        V0 = self.positions(u0, t0, phase_at=t1)
        rows = [r for r in self._phase.slices if r is not None]
        local, increments = crossing_followers(self.mesh, V0, self.positions(u1, t1), self.n_body, rows)
        if local.size == 0:
            return None
        return node_dofs(self.nodes[local]), increments.ravel()

    def intersects(self, u: np.ndarray, t: float) -> bool:
        """True when the collision mesh intersects itself at ``u``, ``t`` (ipctk ``has_intersections``) or a surface
        vertex lies on or behind a plane."""
        V = self.positions(u, t)
        behind = any(np.any(plane.distance(V[: self.n_body]) <= 0.0) for plane in self.planes)
        return behind or bool(ipctk.has_intersections(self.mesh, V))

    def check_state(self, u: np.ndarray, t: float) -> None:
        if self.check_intersections and self.intersects(u, t):
            raise IntersectionError(f"ipc contact: the accepted state at load factor {t:.6g} intersects itself")

    # ------------------------------------------------------------------- state
    def commit(self) -> None:
        """Accept the last assembled state: lag friction there, and (``adaptive``) update the stiffness."""
        if self._last is None:
            return
        u, t = self._last
        self._committed_u, self._committed_t = u, t
        V = self.positions(u, t)
        distance = self._minimum_distance(V)
        self.last_distance = distance
        if self.adaptive and np.isfinite(distance):
            previous = distance if self._previous_distance is None else self._previous_distance
            kappa = float(ipctk.update_barrier_stiffness(previous ** 2, distance ** 2, self.max_stiffness,
                                                         self.stiffness, self.diagonal))
            if kappa != self.stiffness:
                self.stiffness = kappa
                self.barrier = ipctk.BarrierPotential(self.dhat, kappa, True)
        self._previous_distance = distance if np.isfinite(distance) else None
        if self.friction is not None:
            self._lagged = V
            self._tangential = ipctk.TangentialCollisions()
            self._tangential.build(self.mesh, V, self.collisions, self.barrier, self.friction.mu)

    def rewind(self) -> None:
        self._last = (self._committed_u, self._committed_t)

    def state(self) -> dict[str, np.ndarray]:
        """The committed state: displacement and load factor of the lag, and the stiffness."""
        return {"u": self._committed_u, "t": np.array(self._committed_t), "stiffness": np.array(self.stiffness)}

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        if not arrays:
            return
        self.stiffness = float(arrays["stiffness"])
        self.barrier = ipctk.BarrierPotential(self.dhat, self.stiffness, True)
        self._last = (np.asarray(arrays["u"], dtype=float), float(arrays["t"]))
        self.commit()

    # ------------------------------------------------------------------ output
    def nodal_pressure(self, u: np.ndarray, t: float) -> np.ndarray:
        """Contact pressure per node (n_scalar,): the barrier force's magnitude over the vertex's area weight."""
        force = self.assemble(u, t, False, None).internal[: self.space.n_u].reshape(-1, 3)
        pressure = np.zeros(self.space.n_scalar)
        pressure[self.nodes] = np.linalg.norm(force[self.nodes], axis=1) / self.area[self.nodes]
        return pressure

    def face_pressure(self, u: np.ndarray, t: float) -> np.ndarray:
        """Contact pressure per face of the surface (n_faces,): the mean of its nodes'."""
        return self.nodal_pressure(u, t)[self.surface.quads].mean(axis=1)

    def contact_area(self, u: np.ndarray, t: float, threshold: float = 0.0) -> float:
        """Current area of the faces all of whose nodes carry a pressure above ``threshold`` (CAREA; both touching
        sides count; a face beside the contact, with only some nodes touching, does not)."""
        touching = self.nodal_pressure(u, t)[self.surface.quads].min(axis=1) > threshold
        x = self.X + u[: self.space.n_u].reshape(-1, 3)
        Q = x[self.surface.quads]
        area = 0.5 * np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]), axis=1)
        return float(area[touching].sum())
