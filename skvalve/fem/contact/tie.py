r"""Body vertices that touch a moving obstacle stay with it: rough, no-separation contact after capture.

Choice and why
--------------
Abaqus' ``*Friction, rough`` with ``*Surface Behavior, no separation`` (the clip arms' interaction in the Texas TriValve
1.0 clip repair) lets a point that has touched neither slip nor leave. IPC friction (:class:`~.ipc.Friction`) is
Coulomb's law with a finite coefficient and lets a surface leave; neither is that interaction. So a body vertex that
comes within ``capture`` of an active obstacle's surface at a committed state is *captured*: its position is written
in the affine frame of the nearest obstacle triangle :math:`(y_0, y_1, y_2)`,

.. math::

    x = y_0 + a\,(y_1 - y_0) + b\,(y_2 - y_0) + c\,n, \qquad n = \frac{(y_1 - y_0)\times(y_2 - y_0)}
        {\lvert (y_1 - y_0)\times(y_2 - y_0)\rvert},

and from then on a stiff spring holds it at that point of the moving frame:

.. math::

    \Pi = \tfrac12\,k \sum_{v\ \text{captured}} A_v\,\lvert x_v - z_v(t)\rvert^2, \qquad
    z_v(t) = y_0(t) + a_v\,(y_1 - y_0)(t) + b_v\,(y_2 - y_0)(t) + c_v\,n(t),

with :math:`A_v` the vertex's area weight and :math:`k` a stiffness per area and length (MPa/mm for N and mm). For a
rigid obstacle the frame moves rigidly, so a captured vertex follows the obstacle's rigid motion exactly as
:math:`k\to\infty`; at capture :math:`z_v = x_v` and the spring starts force-free. A captured vertex is never released.
The force is :math:`kA_v(x_v - z_v)`, the tangent the constant diagonal :math:`kA_v I`; :math:`z_v` depends on the load
factor only (obstacles have no unknowns), so the term is load dependent and conservative at a fixed load factor.

Captures are decided in :meth:`ObstacleTie.commit` at the state of the last assembly with a tangent (the solvers
assemble the tangent at the state they accept, line-search and quadrature trials without), so within a step the
problem does not change; :meth:`ObstacleTie.state` keeps them for a resumed run.
"""

from __future__ import annotations

from collections.abc import Sequence

import ipctk
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..space import Space, node_dofs
from ..terms import Contribution, Term
from .obstacles import Obstacle

__all__ = ["ObstacleTie"]


def _frames(y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Edges ``y1 - y0``, ``y2 - y0`` and the unit normal of triangles with vertex positions ``y`` (k, 3, 3)."""
    e1, e2 = y[:, 1] - y[:, 0], y[:, 2] - y[:, 0]
    n = np.cross(e1, e2)
    return e1, e2, n / np.linalg.norm(n, axis=1, keepdims=True)


class ObstacleTie(Term):
    """Vertices ``nodes`` of the body captured by the ``obstacles`` they touch (module docstring).

    Parameters
    ----------
    space : the body's space.
    nodes : body node numbers that may be captured (e.g. the contact surface's).
    areas : their area weights :math:`A_v` (same length).
    obstacles : the moving surfaces.
    capture : the distance (length) within which a vertex is captured.
    stiffness : :math:`k` (force per area and length).
    capture_from : load factor from which each obstacle captures (default: its ``active_from``); a surface may be in
        contact before it grips (a clip arm that the leaflets press against before it closes).
    """

    name = "obstacle tie"
    load_dependent = True

    @property
    def supports(self) -> bool:
        """True once a vertex is captured: the tie then holds the body elastically
        (:meth:`~skvalve.fem.problem.Problem.check_supports`)."""
        return self.vertex.size > 0

    def __init__(self, space: Space, nodes: np.ndarray, areas: np.ndarray, obstacles: Sequence[Obstacle],
                 capture: float, stiffness: float, capture_from: Sequence[float] | None = None) -> None:
        self.space = space
        self.nodes = np.asarray(nodes, dtype=np.int64).ravel()
        self.areas = np.asarray(areas, dtype=float).ravel()
        if self.areas.shape != self.nodes.shape or not np.all(np.isfinite(self.areas) & (self.areas > 0.0)):
            raise ValueError(f"obstacle tie: areas must be finite, > 0 and one per node ({self.nodes.size}); got "
                             f"{self.areas.shape}")
        if not (np.isfinite(capture) and capture > 0.0 and np.isfinite(stiffness) and stiffness > 0.0):
            raise ValueError(f"obstacle tie: capture and stiffness must be finite and > 0; got {capture!r}, "
                             f"{stiffness!r}")
        self.obstacles = list(obstacles)
        self.capture, self.stiffness = float(capture), float(stiffness)
        starts = [o.active_from for o in self.obstacles] if capture_from is None else list(capture_from)
        if len(starts) != len(self.obstacles) or not all(np.isfinite(start) for start in starts):
            raise ValueError(f"obstacle tie: capture_from needs one finite load factor per obstacle "
                             f"({len(self.obstacles)}); got {capture_from!r}")
        self.capture_from = [max(float(start), o.active_from) for start, o in zip(starts, self.obstacles, strict=True)]
        # the longest triangle edge of each obstacle: a vertex within capture of a triangle is within capture + edge
        # of one of its corners
        self._reach = [capture + float(np.max(np.linalg.norm(o.vertices[o.triangles]
                                                             - o.vertices[o.triangles[:, [1, 2, 0]]], axis=2)))
                       for o in self.obstacles]
        self._triangles_at = [_triangles_by_vertex(o.triangles, o.vertices.shape[0]) for o in self.obstacles]
        self._set(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)))
        self._last: tuple[np.ndarray, float] | None = None

    def _set(self, vertex, obstacle, triangle, coords) -> None:
        self.vertex, self.obstacle, self.triangle, self.coords = vertex, obstacle, triangle, coords
        node = self.nodes[vertex]
        self._dofs = node_dofs(node)
        self._weights = np.repeat(self.stiffness * self.areas[vertex], 3)

    @property
    def captured(self) -> np.ndarray:
        """Body node numbers captured so far."""
        return self.nodes[self.vertex]

    # ------------------------------------------------------------------ geometry
    def _positions(self, u: np.ndarray, which: np.ndarray) -> np.ndarray:
        return self.space.mesh.p.T[self.nodes[which]] + u[: self.space.n_u].reshape(-1, 3)[self.nodes[which]]

    def targets(self, t: float) -> np.ndarray:
        """:math:`z_v(t)` (k, 3) of the captured vertices."""
        z = np.zeros((self.vertex.size, 3))
        for k, obstacle in enumerate(self.obstacles):
            mine = np.flatnonzero(self.obstacle == k)
            if mine.size:
                y = obstacle.at(t)[obstacle.triangles[self.triangle[mine]]]  # (k, 3, 3)
                e1, e2, n = _frames(y)
                y0 = y[:, 0]
                a, b, c = self.coords[mine].T
                z[mine] = y0 + a[:, None] * e1 + b[:, None] * e2 + c[:, None] * n
        return z

    # --------------------------------------------------------------------- term
    def pushed(self, u: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The captured vertices ride with their points on the obstacles: :math:`z_v(t_1) - z_v(t_0)` (a step's
        start, :meth:`~skvalve.fem.terms.Term.pushed`)."""
        if self.vertex.size == 0:
            return None
        return self._dofs, (self.targets(t1) - self.targets(t0)).ravel()

    def energy(self, u: np.ndarray, t: float) -> float:
        if self.vertex.size == 0:
            return 0.0
        gap = self._positions(u, self.vertex) - self.targets(t)
        return float(0.5 * self.stiffness * np.sum(self.areas[self.vertex] * np.sum(gap * gap, axis=1)))

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        if tangent:  # the solvers assemble the tangent at the state they accept, not at line-search trials
            self._last = (np.array(u, copy=True), float(t))
        n = self.space.n_dofs
        internal = np.zeros(n)
        if self.vertex.size:
            gap = self._positions(u, self.vertex) - self.targets(t)
            internal[self._dofs] = self._weights * gap.ravel()
        matrix = None
        if tangent:
            matrix = sp.csr_matrix((self._weights, (self._dofs, self._dofs)), shape=(n, n))
        return Contribution(internal=internal, matrix=matrix, projected_matrix=matrix)

    # -------------------------------------------------------------------- state
    def commit(self) -> None:
        """Capture the free vertices within ``capture`` of an active obstacle at the state of the last assembly with
        a tangent."""
        if self._last is None:
            return
        u, t = self._last
        free = np.setdiff1d(np.arange(self.nodes.size), self.vertex)
        found = [self._captures(u, t, k, free) for k in range(len(self.obstacles))]
        best: dict[int, tuple[float, int, int, np.ndarray]] = {}
        for k, (vertices, triangles, distances, coords) in enumerate(found):
            for v, tri, d, c in zip(vertices, triangles, distances, coords, strict=True):
                if int(v) not in best or d < best[int(v)][0]:
                    best[int(v)] = (float(d), k, int(tri), c)
        if best:
            order = sorted(best)
            self._set(np.concatenate([self.vertex, np.array(order, dtype=np.int64)]),
                      np.concatenate([self.obstacle, [best[v][1] for v in order]]).astype(np.int64),
                      np.concatenate([self.triangle, [best[v][2] for v in order]]).astype(np.int64),
                      np.vstack([self.coords, np.array([best[v][3] for v in order])]))

    def _captures(self, u: np.ndarray, t: float, k: int, free: np.ndarray):
        """Free vertices within ``capture`` of obstacle ``k`` at ``(u, t)``: vertex, triangle, distance, frame
        coordinates of each."""
        obstacle = self.obstacles[k]
        empty = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3)))
        if t < self.capture_from[k] or free.size == 0:
            return empty
        y = obstacle.at(t)
        x = self._positions(u, free)
        near = cKDTree(y).query_ball_point(x, self._reach[k])
        triangles_at = self._triangles_at[k]
        vertices, tris, distances, coords = [], [], [], []
        for i, corners in enumerate(near):
            if not corners:
                continue
            candidates = np.unique(np.concatenate([triangles_at[j] for j in corners]))
            d2 = np.array([ipctk.point_triangle_distance(x[i], *y[obstacle.triangles[c]]) for c in candidates])
            best = int(np.argmin(d2))
            if d2[best] < self.capture**2:
                tri = int(candidates[best])
                e1, e2, n = _frames(y[obstacle.triangles[[tri]]])
                frame = np.column_stack([e1[0], e2[0], n[0]])
                vertices.append(free[i])
                tris.append(tri)
                distances.append(float(np.sqrt(d2[best])))
                coords.append(np.linalg.solve(frame, x[i] - y[obstacle.triangles[tri, 0]]))
        if not vertices:
            return empty
        return np.array(vertices), np.array(tris), np.array(distances), np.array(coords)

    def state(self) -> dict[str, np.ndarray]:
        return {"vertex": self.vertex, "obstacle": self.obstacle, "triangle": self.triangle, "coords": self.coords}

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        if not arrays:
            return
        self._set(np.asarray(arrays["vertex"], dtype=np.int64), np.asarray(arrays["obstacle"], dtype=np.int64),
                  np.asarray(arrays["triangle"], dtype=np.int64),
                  np.asarray(arrays["coords"], dtype=float).reshape(-1, 3))
        self._last = None


def _triangles_by_vertex(triangles: np.ndarray, n: int) -> list[np.ndarray]:
    """The triangles at each of ``n`` vertices."""
    order = np.argsort(triangles.ravel(), kind="stable")
    counts = np.bincount(triangles.ravel(), minlength=n)
    return np.split(order // 3, np.cumsum(counts)[:-1])
