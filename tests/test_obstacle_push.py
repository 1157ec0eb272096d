"""A moving obstacle pushes the vertices pressed on it (:mod:`skvalve.fem.contact.push`): closest points checked against
ipctk's point-triangle distance, the pushed set and the crossing followers against their closed forms, and steps
whose obstacle sweeps into a pressed block (a plate; a spike that crosses a face no node faces) against the same
equilibrium reached by steps short enough to need no push."""

import logging

import ipctk
import numpy as np
import pytest

from skvalve.fem import Solid
from skvalve.fem.contact import IPCContact, Obstacle
from skvalve.fem.contact.push import closest_points_on_triangles, crossing_followers, pushed_vertices, rigid_motion
from skvalve.fem.meshes import box
from skvalve.fem.solvers import linsolve
from skvalve.fem.solvers.extension import MotionExtension
from skvalve.fem.solvers.incremental import IncrementalOptions, minimise_step
from skvalve.materials import NeoHookean

MATERIAL = NeoHookean.from_shear_poisson(1.0, 0.3)
OPTIONS = IncrementalOptions(rtol=1e-10, atol=1e-12)


def test_closest_points_are_ipctks_distances_and_lie_on_their_triangles():
    """Random triangles and points (every Voronoi region is met): the squared distance equals ipctk's
    ``point_triangle_distance`` and the barycentric coordinates are a convex combination that gives the point."""
    rng = np.random.default_rng(7)
    a, b, c = rng.normal(size=(3, 3000, 3))
    p = 2.0 * rng.normal(size=(3000, 3))
    q, beta = closest_points_on_triangles(p, a, b, c)
    reference = np.array([ipctk.point_triangle_distance(*x) for x in zip(p, a, b, c, strict=True)])
    np.testing.assert_allclose(np.sum((p - q) ** 2, axis=1), reference, rtol=1e-10, atol=1e-12)
    assert beta.min() >= 0.0 and np.abs(beta.sum(axis=1) - 1.0).max() < 1e-12
    np.testing.assert_allclose(beta[:, :1] * a + beta[:, 1:2] * b + beta[:, 2:] * c, q, atol=1e-12)
    corners = (beta == 1.0).any(axis=1).sum()
    edges = ((beta == 0.0).sum(axis=1) == 1).sum()
    assert corners > 100 and edges > 100 and len(p) - corners - edges > 100  # all three kinds of region met


def test_the_pushed_vertices_are_those_in_front_within_reach():
    """A unit square at z = 0 rising by 0.3 (dhat 0.02): a point 0.01 above it moves with it; 0.31 above (within
    dhat + travel) too; 0.33 above, 0.01 below (behind its motion) or beside it beyond the reach do not."""
    square = Obstacle.rectangle([0.0, 0.0, 0.0], [0, 0, 1], size=1.0, divisions=2)
    start = square.vertices
    end = start + [0.0, 0.0, 0.3]
    points = np.array([[0.1, 0.2, 0.01], [-0.3, 0.1, 0.31], [0.0, 0.0, 0.33], [0.2, 0.2, -0.01], [0.9, 0.0, 0.05]])
    index, increment = pushed_vertices(points, start, end, square.triangles, dhat=0.02)
    assert index.tolist() == [0, 1]
    np.testing.assert_allclose(increment, [[0.0, 0.0, 0.3]] * 2, atol=1e-14)
    assert pushed_vertices(points, start, start, square.triangles, dhat=0.02)[0].size == 0  # a parked obstacle


def _block_on_rising_obstacle(rise: float, spike: bool = False):
    """A 1 x 1 x 0.5 block held at its top face, 0.01 above a plate of side 2 (``spike``: above the tip of a spike
    under its base's inside, which no base node faces) that rises by ``rise`` (dhat 0.02); every node on rollers
    (held laterally: the barrier's edge-edge pairs give a frictionless base lateral minima)."""
    solid = Solid(box((1, 1, 1) if spike else (2, 2, 2), (1.0, 1.0, 0.5)), MATERIAL)
    solid.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), 0.0, components=[0, 1])
    solid.add_dirichlet(lambda X: X[2] > 0.5 - 1e-9, 0.0)
    motion = lambda t: np.array([0.0, 0.0, rise * t])  # noqa: E731
    if spike:
        obstacle = Obstacle.rigid([[0.3, 0.6, -0.01], [0.1, 0.6, -1.0], [0.5, 0.6, -1.0]], [[0, 1, 2]], motion,
                                  name="spike")
    else:
        obstacle = Obstacle.rectangle([0.5, 0.5, -0.01], [0, 0, 1], size=2.0, divisions=2, motion=motion)
    contact = IPCContact(solid.space, dhat=0.02, stiffness=20.0, obstacles=[obstacle], check_intersections=True)
    solid.add_term(contact)
    return solid, contact


def _short_steps(spike: bool) -> np.ndarray:
    """The rise of 0.1 in 20 steps of 0.005, each shorter than the gap the barrier leaves (no push needed)."""
    solid, _ = _block_on_rising_obstacle(0.1, spike)
    u, t = np.zeros(solid.space.n_dofs), 0.0
    for t_new in np.linspace(0.05, 1.0, 20):
        u, _, _ = minimise_step(solid, u, t, t_new, u, np.zeros_like(u), 1, OPTIONS, "pardiso")
        solid.commit()
        t = t_new
    return u


@pytest.mark.skipif("pardiso" not in linsolve.available_solvers(), reason="the step's directions need PARDISO")
def test_a_plate_sweeping_into_a_block_pushes_it_to_the_equilibrium_of_short_steps():
    """The plate rises 0.1 in one step, ten times the gap: the plate's motion alone crosses the block's base (a
    step cannot start there); pushed, the base rides on the plate, the extension compresses the block between it and
    the held top, and the step ends where 20 steps of 0.005 (each less than the gap the barrier leaves, no push
    needed) end, with no intersection."""
    solid, contact = _block_on_rising_obstacle(0.1)
    u0 = np.zeros(solid.space.n_dofs)
    assert contact.intersects(u0, 1.0)  # the plate moved alone cuts through the block
    assert solid.pushed(u0, 0.0, 1.0)[0].size == 9  # the base's 9 nodes, vertically (the rollers hold the rest)
    extension = MotionExtension(solid, [solid.terms[0]])
    pushed, _, _ = minimise_step(solid, u0, 0.0, 1.0, u0, np.zeros_like(u0), 1, OPTIONS, "pardiso", carry=extension)
    assert not contact.intersects(pushed, 1.0) and 0.0 < contact.minimum_distance(pushed, 1.0) < 0.02
    np.testing.assert_allclose(pushed, _short_steps(False), atol=1e-7)
    base = solid.mesh.p[2] < 1e-9
    rise = pushed.reshape(-1, 3)[base, 2]
    assert rise.min() > 0.09 and rise.max() < 0.09 + 0.03  # on the risen plate (at 0.09), within the barrier's range


@pytest.mark.skipif("pardiso" not in linsolve.available_solvers(), reason="the step's directions need PARDISO")
def test_a_spike_crossing_a_face_that_no_node_faces_carries_the_face_to_the_equilibrium_of_short_steps(caplog):
    """The spike's tip rises 0.1 into the base's inside: no base node lies in front of the spike (nothing is
    pushed), the tip crosses a base triangle, whose nodes then ride with it (one crossing round), and the step ends
    where 20 short steps end."""
    solid, contact = _block_on_rising_obstacle(0.1, spike=True)
    u0 = np.zeros(solid.space.n_dofs)
    assert solid.pushed(u0, 0.0, 1.0) is None
    extension = MotionExtension(solid, [solid.terms[0]])
    with caplog.at_level(logging.DEBUG, logger="skvalve.fem"):
        u, _, _ = minimise_step(solid, u0, 0.0, 1.0, u0, np.zeros_like(u0), 1, OPTIONS, "pardiso", carry=extension)
    rounds = [r.getMessage() for r in caplog.records if "push round" in r.getMessage()]
    assert len(rounds) == 1 and "3 dofs ride" in rounds[0], rounds  # the crossed triangle's nodes, vertically
    assert not contact.intersects(u, 1.0) and 0.0 < contact.minimum_distance(u, 1.0) < 0.02
    np.testing.assert_allclose(u, _short_steps(True), atol=1e-7)
    assert u.reshape(-1, 3)[:, 2].max() > 0.05  # the base is lifted


def test_a_crossed_triangle_rides_with_the_vertex_that_crosses_it():
    """A body triangle at z = 0 and an obstacle spike whose tip, 0.01 below the triangle's inside, rises by 0.1: the
    tip's move crosses the triangle (no body vertex lies in front of an obstacle face, so nothing is pushed), the
    three body vertices follow the tip's motion, and moved so the step is collision-free. A point above a body
    triangle that sweeps through it (both body): the four vertices form one cluster, translated by their mean motion."""
    body = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    spike = np.array([[0.3, 0.3, -0.01], [0.0, 0.3, -1.0], [0.6, 0.3, -1.0]])
    V0 = np.vstack([body, spike])
    faces = np.array([[0, 1, 2], [3, 4, 5]])
    mesh = ipctk.CollisionMesh(V0, ipctk.edges(faces), faces)
    V1 = V0 + np.r_[np.zeros((3, 3)), np.tile([0.0, 0.0, 0.1], (3, 1))]
    assert pushed_vertices(body, spike, V1[3:], faces[1:] - 3, dhat=0.02)[0].size == 0
    vertices, increments = crossing_followers(mesh, V0, V1, n_body=3)
    assert sorted(vertices.tolist()) == [0, 1, 2]
    np.testing.assert_allclose(increments, [[0.0, 0.0, 0.1]] * 3, atol=1e-15)
    V1[:3] += increments[np.argsort(vertices)]
    assert ipctk.is_step_collision_free(mesh, V0, V1)
    assert crossing_followers(mesh, V0, V1, n_body=3)[0].size == 0
    # two body pieces: a point above the triangle that the triangle (moving 0.1 up) sweeps through
    V0 = np.vstack([body, [[0.2, 0.2, 0.05]]])
    mesh = ipctk.CollisionMesh(V0, ipctk.edges(faces[:1]), faces[:1])
    V1 = V0 + np.r_[np.tile([0.0, 0.0, 0.1], (3, 1)), np.zeros((1, 3))]
    vertices, increments = crossing_followers(mesh, V0, V1, n_body=4)
    assert sorted(vertices.tolist()) == [0, 1, 2, 3]
    np.testing.assert_allclose(increments, [[0.0, 0.0, 0.075]] * 4, atol=1e-15)  # (3 x 0.1 + 0) / 4


def test_crossing_body_pairs_that_share_vertices_translate_as_one_cluster():
    """A body edge along x lifts and turns (its ends rise 0.1 and 0.3) under a crossing body edge 0.01 above it at
    x = 0.9, and a third edge hangs from the crossing edge's end 3, 0.01 above a fourth that rises 0.2 through it. The
    two crossing pairs share vertex 3, so their seven vertices are one cluster, translated by their mean motion
    (0.7 / 7 = 0.1): every gap among them stays as it was, and the move is collision-free. The vertices of no crossing
    pair are not returned."""
    V0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.9, -0.5, 0.01], [0.9, 0.5, 0.01], [0.9, 1.5, 0.01],
                   [1.4, 1.0, 0.0], [0.4, 1.0, 0.0], [5.0, 5.0, 5.0], [6.0, 5.0, 5.0]])
    edges = np.array([[0, 1], [2, 3], [3, 4], [5, 6], [7, 8]])
    mesh = ipctk.CollisionMesh(V0, edges, np.zeros((0, 3), dtype=np.int64))
    V1 = V0.copy()
    V1[[0, 1, 5, 6], 2] += [0.1, 0.3, 0.15, 0.15]
    V1[[7, 8], 0] += 0.5  # far from everything
    assert not ipctk.is_step_collision_free(mesh, V0, V1)
    vertices, increments = crossing_followers(mesh, V0, V1, n_body=9)
    ride = dict(zip(vertices.tolist(), increments, strict=True))
    assert sorted(ride) == [0, 1, 2, 3, 4, 5, 6]
    for vertex in ride:
        np.testing.assert_allclose(ride[vertex], [0.0, 0.0, 0.1], atol=1e-15)
    moved = V0.copy()
    moved[vertices] += increments
    assert ipctk.is_step_collision_free(mesh, V0, moved)
    pairs = [[0, 1, 2, 3], [3, 4, 5, 6]]
    before = [ipctk.edge_edge_distance(*V0[pair]) for pair in pairs]
    after = [ipctk.edge_edge_distance(*moved[pair]) for pair in pairs]
    np.testing.assert_allclose(after, before, rtol=1e-12)


def test_rigid_motion_is_recovered_from_a_turned_plate_and_refused_for_a_deforming_one():
    """Kabsch's fit on a flat plate (coplanar points) turned by 0.7 rad about a tilted axis and shifted: the rotation
    and shift come back to round-off, and a point off the plate moved by (R - I) p + c lands where the rigid map puts
    it; a plate stretched by 1e-6 is not rigid (None)."""
    rng = np.random.default_rng(3)
    plate = np.column_stack([rng.uniform(-1, 1, (12, 2)), np.zeros(12)])
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(0.7) * K + (1 - np.cos(0.7)) * K @ K
    c = np.array([0.1, 0.2, -0.3])
    fit = rigid_motion(plate, plate @ R.T + c)
    assert fit is not None
    np.testing.assert_allclose(fit[0], R, atol=1e-13)
    np.testing.assert_allclose(fit[1], c, atol=1e-13)
    p = np.array([[0.2, 0.1, 0.05]])
    np.testing.assert_allclose(p + p @ (fit[0] - np.eye(3)).T + fit[1], p @ R.T + c, atol=1e-13)
    stretched = plate @ R.T + c
    stretched[:, 0] *= 1.0 + 1e-6
    assert rigid_motion(plate, stretched) is None
    assert rigid_motion(plate[:2], plate[:2] + c) is None  # two points fix no rotation


def test_what_a_turning_rigid_obstacle_crosses_rides_with_its_rigid_motion():
    """A square plate (kinematic, rows 2-5) turns 0.1 rad about the x-axis, its far edge rising through a body edge
    that lies askew 1e-3 above it. The body edge's ends ride with the plate's rigid motion (R - I) p, in closed form,
    and moved so the step is collision-free."""
    body = np.array([[0.5, 0.8, 1e-3], [0.9, 1.2, 1e-3]])
    plate = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    angle = 0.1
    R = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])
    V0 = np.vstack([body, plate])
    faces = np.array([[2, 3, 4], [2, 4, 5]])
    edges = np.vstack([[[0, 1]], ipctk.edges(faces)])
    mesh = ipctk.CollisionMesh(V0, edges, faces)
    V1 = np.vstack([body, plate @ R.T])
    assert not ipctk.is_step_collision_free(mesh, V0, V1)
    vertices, increments = crossing_followers(mesh, V0, V1, n_body=2, obstacles=[slice(2, 6)])
    assert sorted(vertices.tolist()) == [0, 1]
    ride = dict(zip(vertices.tolist(), increments, strict=True))
    for v in (0, 1):
        np.testing.assert_allclose(ride[v], body[v] @ R.T - body[v], atol=1e-14)
    moved = V1.copy()
    moved[:2] += np.array([ride[0], ride[1]])
    assert ipctk.is_step_collision_free(mesh, V0, moved)
