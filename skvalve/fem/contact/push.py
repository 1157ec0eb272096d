r"""Where a moving obstacle pushes a body: the start of a step whose obstacles sweep into vertices pressed on them.

A kinematic obstacle (:class:`~.obstacles.Obstacle`) moves from :math:`y(t_0)` to :math:`y(t_1)` in a step. A body
vertex :math:`p` already within the barrier's range of it, in front of its motion, would be crossed by that motion
alone: the step's start (the body where it was, the obstacle moved) is not collision-free, and an IPC step cannot
begin there. Shorter steps only help while the obstacle moves less than the gap, which the barrier keeps at a
fraction of :math:`\hat d`: on the Texas TriValve 1.0 clip input the arms' turn went on in steps of
:math:`3\times10^{-4}` step time.

So the obstacle pushes: each body vertex :math:`p` whose closest obstacle point :math:`q` (barycentric
:math:`\beta` on its triangle) lies within :math:`\hat d + |\Delta q|` and moves towards it,

.. math::

    |p - q| < \hat d + |\Delta q|, \qquad \Delta q\cdot(p - q) > 0, \qquad
    \Delta q = \sum_i \beta_i\,\big(y_i(t_1) - y_i(t_0)\big),

starts the step moved by :math:`\Delta q`. Along the straight move of the CCD the point
:math:`\sum_i\beta_i y_i(s)` is exactly the moved vertex minus its old offset :math:`p - q`, so a pushed vertex keeps
its place on the moving facet (its distance to the facet's plane changes by the cosine of the facet's turn). Where
the obstacle moves rigidly, :math:`y(t_1) = R\,y(t_0) + c` (:func:`rigid_motion`), the vertex moves by that motion
instead, :math:`(R - I)\,p + c`, and keeps its distance exactly. The
rest of the body follows by the harmonic extension
(:class:`~skvalve.fem.solvers.extension.MotionExtension`, pushed dofs as prescribed ones), and the step's
minimisation then finds where the pushed body comes to rest. The push is a start, not a constraint: it changes no
minimiser.
"""

from __future__ import annotations

from collections.abc import Sequence

import ipctk
import numpy as np
from scipy.spatial import cKDTree

__all__ = ["closest_points_on_triangles", "rigid_motion", "pushed_vertices", "crossing_followers"]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def closest_points_on_triangles(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
                                ) -> tuple[np.ndarray, np.ndarray]:
    r"""``(q, beta)``: the closest point ``q`` (k, 3) of each triangle ``(a, b, c)`` (k, 3 each) to the point ``p``
    (k, 3), and its barycentric coordinates ``beta`` (k, 3).

    The triangle's plane splits into seven Voronoi regions: the three corners, the three edges and the inside. A
    corner region holds the points whose projections on both adjacent edges fall before that corner; an edge region
    the points outside that edge (signed area of the sub-triangle :math:`\le 0`) whose projection falls within it.
    The regions are tested from the inside outwards, each overriding the last, so a point takes the region a
    sequential test (corners, then edges, then inside) would give it."""
    p, a, b, c = (np.asarray(x, dtype=float) for x in (p, a, b, c))
    ab, ac = b - a, c - a
    d1, d2 = _dot(ab, p - a), _dot(ac, p - a)
    d3, d4 = _dot(ab, p - b), _dot(ac, p - b)
    d5, d6 = _dot(ab, p - c), _dot(ac, p - c)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2  # sub-areas opposite a, b, c (scaled)

    def ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
        safe = np.where(den != 0.0, den, 1.0)
        return np.clip(np.where(den != 0.0, num / safe, 0.0), 0.0, 1.0)

    total = va + vb + vc
    v, w = ratio(vb, total), ratio(vc, total)
    beta = np.stack([1.0 - v - w, v, w], axis=1)  # inside
    edge = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)  # edge bc
    s = ratio(d4 - d3, (d4 - d3) + (d5 - d6))[edge]
    beta[edge] = np.stack([np.zeros_like(s), 1.0 - s, s], axis=1)
    edge = (vb <= 0) & (d2 >= 0) & (d6 <= 0)  # edge ac
    s = ratio(d2, d2 - d6)[edge]
    beta[edge] = np.stack([1.0 - s, np.zeros_like(s), s], axis=1)
    beta[(d6 >= 0) & (d5 <= d6)] = (0.0, 0.0, 1.0)  # corner c
    edge = (vc <= 0) & (d1 >= 0) & (d3 <= 0)  # edge ab
    s = ratio(d1, d1 - d3)[edge]
    beta[edge] = np.stack([1.0 - s, s, np.zeros_like(s)], axis=1)
    beta[(d3 >= 0) & (d4 <= d3)] = (0.0, 1.0, 0.0)  # corner b
    beta[(d1 <= 0) & (d2 <= 0)] = (1.0, 0.0, 0.0)  # corner a
    q = beta[:, :1] * a + beta[:, 1:2] * b + beta[:, 2:] * c
    return q, beta


def rigid_motion(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    r"""``(R, c)`` with ``end`` :math:`= R\,` ``start`` :math:`+ c` (rows; Kabsch's fit of a rotation and a
    translation), or ``None`` where ``start`` (m, 3) spans no plane or the fit misses ``end`` by more than
    :math:`10^{-9}` of the points' extent (an obstacle that deforms). Every point riding with a rigid obstacle moves by
    :math:`(R - I)\,p + c`, the same affine map as the obstacle along the straight move :math:`p + s\,((R-I)p + c)`,
    so a pair riding together keeps its gap's sign for all :math:`s` (the map :math:`I + s(R - I)` is invertible for
    turns below 180°)."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    if start.shape[0] < 3:
        return None
    c0, c1 = start.mean(axis=0), end.mean(axis=0)
    U, sigma, Vt = np.linalg.svd((start - c0).T @ (end - c1))
    extent = float(np.max(np.linalg.norm(start - c0, axis=1)))
    if not sigma[1] > 1e-12 * max(sigma[0], 1e-300):
        return None
    d = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
    c = c1 - R @ c0
    if np.max(np.linalg.norm(start @ R.T + c - end, axis=1)) > 1e-9 * max(extent, 1e-300):
        return None
    return R, c


def _rigid_increments(rigid: tuple[np.ndarray, np.ndarray], points: np.ndarray) -> np.ndarray:
    r"""The increments (k, 3) of ``points`` riding with the rigid motion ``(R, c)``: :math:`(R - I)\,p + c`."""
    R, c = rigid
    return points @ (R - np.eye(3)).T + c


def pushed_vertices(points: np.ndarray, start: np.ndarray, end: np.ndarray, triangles: np.ndarray, dhat: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """``(index, increment)``: the rows of ``points`` (n, 3) that an obstacle moving from vertex positions ``start``
    to ``end`` (m, 3; facets ``triangles``) pushes (module docstring), and their increments (k, 3): the obstacle's
    rigid motion where it moves rigidly, else the motion of their closest obstacle points."""
    points = np.asarray(points, dtype=float)
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    triangles = np.asarray(triangles, dtype=np.int64)
    motion = end - start
    travel = float(np.sqrt(np.max(np.sum(motion ** 2, axis=1), initial=0.0)))
    empty = np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    if travel == 0.0 or points.shape[0] == 0:
        return empty
    corners = start[triangles]
    centroids = corners.mean(axis=1)
    radius = float(np.max(np.linalg.norm(corners - centroids[:, None], axis=2)))
    near = cKDTree(centroids).query_ball_point(points, dhat + travel + radius)
    rows = np.repeat(np.arange(points.shape[0]), [len(k) for k in near])
    if rows.size == 0:
        return empty
    facets = np.concatenate([np.asarray(k, dtype=np.int64) for k in near])
    q, beta = closest_points_on_triangles(points[rows], *(corners[facets, i] for i in range(3)))
    distance = np.linalg.norm(points[rows] - q, axis=1)
    order = np.lexsort((distance, rows))  # per point, its closest facet first
    first = order[np.r_[True, rows[order][1:] != rows[order][:-1]]]
    rows, distance, q = rows[first], distance[first], q[first]
    dq = np.einsum("ki,kij->kj", beta[first], motion[triangles[facets[first]]])
    pushed = (distance < dhat + np.linalg.norm(dq, axis=1)) & (_dot(dq, points[rows] - q) > 0.0)
    rigid = rigid_motion(start, end) if np.any(pushed) else None
    return rows[pushed], (dq[pushed] if rigid is None else _rigid_increments(rigid, points[rows[pushed]]))


def _motion_at(points: np.ndarray, corners: np.ndarray, motion: np.ndarray) -> np.ndarray:
    """The motion (k, 3) of the closest points to ``points`` (k, 3) on the primitive with vertices ``corners`` (m, 3;
    a point, a segment or a triangle) moving by ``motion`` (m, 3), interpolated linearly over the primitive."""
    if len(corners) == 1:
        return np.repeat(motion, len(points), axis=0)
    if len(corners) == 2:
        axis = corners[1] - corners[0]
        s = np.clip((points - corners[0]) @ axis / max(float(axis @ axis), 1e-300), 0.0, 1.0)
        return (1.0 - s)[:, None] * motion[0] + s[:, None] * motion[1]
    k = len(points)
    _, beta = closest_points_on_triangles(points, *(np.repeat(corners[i:i + 1], k, axis=0) for i in range(3)))
    return beta @ motion


def crossing_followers(mesh: ipctk.CollisionMesh, V0: np.ndarray, V1: np.ndarray, n_body: int,
                       obstacles: Sequence[slice] = ()) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices, increments)``: the body vertices (rows below ``n_body``) of the primitive pairs (point-triangle,
    edge-edge) whose straight move from ``V0`` to ``V1`` collides (ipctk's narrow-phase CCD), with the motion (k, 3)
    that takes them across without the collision:

    * a pair with an obstacle's side: the body side rides with the obstacle (its rigid motion, :func:`rigid_motion`,
      which keeps it exactly where it is relative to the obstacle; the motion of its closest point on the obstacle's
      side, interpolated linearly, where the obstacle deforms);
    * pairs of body sides: the body vertices of all such pairs that share vertices form one cluster, translated by
      its vertices' mean motion, so every gap within the cluster stays as it is. A cluster with a vertex that rides
      with an obstacle is translated by the mean of those vertices' rides.

    Why clusters: on the 1.0 clip input at step time 1.840 a leaflet folded against itself had 132 barrier pairs
    closer than 1e-4 mm (17 closer than 1e-5 mm) while the carried start moved their vertices 1e-3 mm apart; moved
    with their closest points on the crossing side (the rule before), each round crossed a neighbouring pair (300,
    90, 36, 24, 12, 33 vertices in six rounds for a step of 0.001) and the step was refused; as clusters the start was
    collision-free after one round (also at step time 1.777 and 1.790, steps of 0.004). Before that the followers
    moved with the crossing side's mean (crossed again when the side turned) and with the closest point of a turning
    arm's edge (crossed again where the edges lie askew), hence the obstacle's rigid motion."""
    candidates = ipctk.Candidates()
    candidates.build(mesh, V0, V1)
    motion = V1 - V0
    follows: dict[int, np.ndarray] = {}  # body vertices riding with an obstacle
    parent: dict[int, int] = {}  # union-find over the body vertices of body-body pairs
    fits: dict[int, tuple[np.ndarray, np.ndarray] | None] = {}

    def rigid_of(vertex: int) -> tuple[np.ndarray, np.ndarray] | None:
        for k, rows in enumerate(obstacles):
            if rows.start <= vertex < rows.stop:
                if k not in fits:
                    fits[k] = rigid_motion(V0[rows], V1[rows])
                return fits[k]
        return None

    def root(vertex: int) -> int:
        while parent.setdefault(vertex, vertex) != vertex:
            parent[vertex] = parent[parent[vertex]]
            vertex = parent[vertex]
        return vertex

    for stencils, split in ((candidates.fv_candidates, 1), (candidates.ee_candidates, 2)):
        for stencil in stencils:
            ids = np.asarray(stencil.vertex_ids(mesh.edges, mesh.faces))
            if not stencil.ccd(V0[ids].ravel(), V1[ids].ravel())[0]:
                continue
            sides = [ids[:split], ids[split:]]
            kinematic = [bool(np.any(side >= n_body)) for side in sides]
            if not any(kinematic):
                first = root(int(ids[0]))
                for vertex in ids[1:].tolist():
                    parent[root(vertex)] = first
                continue
            leader, follower = (sides[0], sides[1]) if kinematic[0] else (sides[1], sides[0])
            rigid = rigid_of(int(leader.max()))
            riding = (_motion_at(V0[follower], V0[leader], motion[leader]) if rigid is None
                      else _rigid_increments(rigid, V0[follower]))
            for vertex, increment in zip(follower.tolist(), riding, strict=True):
                if vertex < n_body:
                    follows.setdefault(vertex, increment)
    clusters: dict[int, list[int]] = {}
    for vertex in list(parent):
        clusters.setdefault(root(vertex), []).append(vertex)
    ride = dict(follows)
    for members in clusters.values():
        anchored = [follows[v] for v in members if v in follows]
        shift = np.mean(anchored, axis=0) if anchored else motion[members].mean(axis=0)
        ride.update({v: shift for v in members})
    if not ride:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    vertices = np.fromiter(ride, dtype=np.int64, count=len(ride))
    return vertices, np.array([ride[v] for v in vertices.tolist()]).reshape(-1, 3)
