"""The obstacle tie: captured vertices follow a moving obstacle's rigid motion exactly, only touching vertices are
captured, forces are the energy's gradient, and the captures survive a state round trip."""

import numpy as np
import pytest
import skfem

from skvalve.fem import Solid, solve
from skvalve.fem.contact.obstacles import Obstacle
from skvalve.fem.contact.tie import ObstacleTie
from skvalve.materials import NeoHookean


def _rotation_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


CENTRE = np.array([0.5, 0.5, -0.05])


def _turning_plate(active_from: float = 0.0) -> Obstacle:
    """A plate 0.05 below the unit cube's bottom face, turning by 0.6 t about the vertical axis through its centre
    and sliding by (0.3 t, -0.2 t, 0.1 t)."""
    plate = Obstacle.rectangle(CENTRE, [0.0, 0.0, 1.0], 2.0, divisions=4)
    return Obstacle.rigid(plate.vertices, plate.triangles, lambda t: np.array([0.3, -0.2, 0.1]) * t,
                          lambda t: _rotation_z(0.6 * t), centre=CENTRE, active_from=active_from)


def _tied_cube(active_from: float = 0.0, capture: float = 0.1):
    mesh = skfem.MeshHex()
    solid = Solid(mesh, NeoHookean(1.0, 10.0))
    nodes = np.arange(mesh.p.shape[1])
    tie = solid.add_term(ObstacleTie(solid.space, nodes, np.full(nodes.size, 0.25), [_turning_plate(active_from)],
                                     capture=capture, stiffness=100.0))
    return mesh, solid, tie


def test_captured_vertices_follow_the_obstacles_rigid_motion():
    """A cube held only by its bottom face's capture moves with the plate: u = R(X - c) + c + a - X exactly."""
    mesh, solid, tie = _tied_cube()
    tie.assemble(np.zeros(solid.space.n_dofs), 0.0, True, None)
    tie.commit()
    bottom = np.flatnonzero(mesh.p[2] == 0.0)
    assert sorted(tie.captured.tolist()) == sorted(bottom.tolist())  # the top face is 1.05 away
    result = solve(solid, steps=4, progress=False, atol=1e-12)  # no loads, no reactions: an absolute tolerance
    X = mesh.p.T
    exact = (X - CENTRE) @ _rotation_z(0.6).T + CENTRE + np.array([0.3, -0.2, 0.1]) - X
    assert np.abs(result.u()[: solid.space.n_u].reshape(-1, 3) - exact).max() < 1e-9


def test_captured_vertices_are_pushed_by_the_obstacles_rigid_motion():
    """``pushed``: a vertex captured at 0.25 starts a step to 0.75 moved as its point of the plate moves, in closed
    form c + R(0.45) R(0.15)^T (X - c - 0.25 a) + 0.75 a - X; nothing before a capture, nothing where the plate does
    not move."""
    mesh, solid, tie = _tied_cube()
    u = np.zeros(solid.space.n_dofs)
    assert tie.pushed(u, 0.25, 0.75) is None
    tie.assemble(u, 0.25, True, None)
    tie.commit()
    dofs, increments = tie.pushed(u, 0.25, 0.75)
    X = mesh.p.T[tie.captured]  # fixed in the plate's frame from 0.25: y = c + R(t)(Y - c) + a t
    a = np.array([0.3, -0.2, 0.1])
    reference = CENTRE + (X - CENTRE - 0.25 * a) @ _rotation_z(0.15) @ _rotation_z(0.45).T + 0.75 * a - X
    np.testing.assert_allclose(increments.reshape(-1, 3), reference, atol=1e-12)
    assert np.array_equal(dofs, (3 * tie.captured[:, None] + np.arange(3)).ravel())
    assert not np.any(tie.pushed(u, 0.75, 0.75)[1])


def test_nothing_is_captured_before_the_obstacle_is_active_or_out_of_reach():
    _, solid, tie = _tied_cube(active_from=0.5)
    u = np.zeros(solid.space.n_dofs)
    tie.assemble(u, 0.2, True, None)
    tie.commit()
    assert tie.captured.size == 0
    _, solid, tie = _tied_cube(capture=0.04)
    tie.assemble(u, 0.0, True, None)
    tie.commit()
    assert tie.captured.size == 0


def _captured_cube():
    """The tied cube with its bottom face captured at the reference state (``n``: its dofs)."""
    _, solid, tie = _tied_cube()
    n = solid.space.n_dofs
    tie.assemble(np.zeros(n), 0.0, True, None)
    tie.commit()
    return tie, n


def test_forces_are_the_energy_gradient_and_the_tangent_its_hessian():
    tie, n = _captured_cube()
    u = 0.05 * np.random.default_rng(1).standard_normal(n)
    contribution = tie.assemble(u, 0.4, True, None)
    h = 1e-6
    gradient = np.array([(tie.energy(u + h * e, 0.4) - tie.energy(u - h * e, 0.4)) / (2 * h) for e in np.eye(n)])
    assert np.abs(gradient - contribution.internal).max() <= 1e-8 * np.abs(contribution.internal).max()
    K = contribution.matrix.toarray()
    hessian = np.column_stack([(tie.assemble(u + h * e, 0.4, False, None).internal
                                - tie.assemble(u - h * e, 0.4, False, None).internal) / (2 * h) for e in np.eye(n)])
    assert np.abs(hessian - K).max() <= 1e-6 * np.abs(K).max()


def test_captures_survive_a_state_round_trip():
    tie, n = _captured_cube()
    u = 0.05 * np.random.default_rng(2).standard_normal(n)
    _, _, fresh = _tied_cube()
    fresh.restore({key: np.array(value) for key, value in tie.state().items()})
    assert fresh.energy(u, 0.7) == pytest.approx(tie.energy(u, 0.7), rel=1e-14) and fresh.energy(u, 0.7) > 0.0


def test_bad_parameters_are_refused():
    mesh = skfem.MeshHex()
    solid = Solid(mesh, NeoHookean(1.0, 10.0))
    with pytest.raises(ValueError, match="areas"):
        ObstacleTie(solid.space, np.arange(8), np.zeros(8), [_turning_plate()], 0.1, 1.0)
    with pytest.raises(ValueError, match="capture and stiffness"):
        ObstacleTie(solid.space, np.arange(8), np.ones(8), [_turning_plate()], 0.0, 1.0)
    with pytest.raises(ValueError, match="capture_from needs one finite load factor per obstacle"):
        ObstacleTie(solid.space, np.arange(8), np.ones(8), [_turning_plate()], 0.1, 1.0, capture_from=[0.0, 1.0])


def test_an_obstacle_in_contact_grips_only_from_capture_from():
    """A plate active from 0 that grips from 0.5: the cube's bottom face, 0.01 above the risen plate at 0.4 (within
    the capture distance 0.1, so an obstacle gripping from its activation would take it), is free there and captured
    at 0.5."""
    mesh = skfem.MeshHex()
    solid = Solid(mesh, NeoHookean(1.0, 10.0))
    nodes = np.arange(mesh.p.shape[1])
    tie = ObstacleTie(solid.space, nodes, np.full(nodes.size, 0.25), [_turning_plate()], capture=0.1,
                      stiffness=100.0, capture_from=[0.5])
    u = np.zeros(solid.space.n_dofs)
    tie.assemble(u, 0.4, True, None)
    tie.commit()
    assert tie.captured.size == 0
    tie.assemble(u, 0.5, True, None)
    tie.commit()
    assert sorted(tie.captured.tolist()) == sorted(np.flatnonzero(mesh.p[2] == 0.0).tolist())
