"""IPC barrier contact (skvalve.fem.contact.ipc): derivatives against central differences, the plane-vertex pressure
in closed form, blocks and sheets pressed together and onto rigid surfaces without an intersection at any accepted
state, and a block that passes straight through an obstacle once the solvers' collision-free cap is removed."""

import dataclasses

import ipctk
import numpy as np
import pytest
import skfem
from scipy.optimize import brentq

from skvalve.fem import Solid, Space, solve
from skvalve.fem.contact import (
    ContactSurface,
    IntersectionError,
    IPCContact,
    Obstacle,
    Plane,
    barrier_pressure,
    stiffness_for_pressure,
)
from skvalve.fem.contact.ipc import Friction
from skvalve.fem.meshes import box
from skvalve.fem.solvers.incremental import IncrementalOptions, incremental_potential
from skvalve.fem.solvers.ptc import PseudoTransientOptions, pseudo_transient
from skvalve.fem.solvers.trust_steps import project_sparse_psd, step_matrix
from skvalve.materials import NeoHookean

MATERIAL = NeoHookean.from_shear_poisson(G=10.0, nu=0.3)


def _two_blocks(gap: float):
    """Two unit-ish blocks stacked along z with ``gap`` between them (one mesh, two components)."""
    lower = box((2, 2, 1), (1.0, 1.0, 0.5))
    upper = skfem.MeshHex.init_tensor(np.linspace(0.1, 0.9, 3), np.linspace(0.1, 0.9, 3),
                                      np.linspace(0.5 + gap, 1.0 + gap, 2))
    p = np.hstack([lower.p, upper.p])
    t = np.hstack([lower.t, upper.t + lower.p.shape[1]])
    return skfem.MeshHex(p, t)


def test_barrier_gradient_and_hessian_match_central_differences():
    mesh = _two_blocks(0.02)
    space = Space(mesh)
    contact = IPCContact(space, dhat=0.05, stiffness=50.0, planes=[Plane([0, 0, -0.01], [0, 0, 1])])
    rng = np.random.default_rng(7)
    u = 2e-3 * rng.standard_normal(space.n_dofs)
    assert contact.active_pairs(u, 0.0) > 10
    c = contact.assemble(u, 0.0, True, None)
    h = 1e-7
    for _ in range(3):
        v = rng.standard_normal(space.n_dofs)
        fd = (contact.energy(u + h * v, 0.0) - contact.energy(u - h * v, 0.0)) / (2 * h)
        assert fd == pytest.approx(c.internal @ v, rel=1e-6)
        g_plus = contact.assemble(u + h * v, 0.0, False, None).internal
        g_minus = contact.assemble(u - h * v, 0.0, False, None).internal
        assert np.linalg.norm((g_plus - g_minus) / (2 * h) - c.matrix @ v) <= 1e-6 * np.linalg.norm(c.matrix @ v)
    # the projected Hessian is symmetric positive semidefinite; the exact one is symmetric
    P = c.projected_matrix.toarray()
    assert np.allclose(P, P.T) and np.linalg.eigvalsh(P).min() > -1e-8 * np.abs(P).max()
    assert np.allclose(c.matrix.toarray(), c.matrix.toarray().T)


def test_plane_vertex_pressure_is_the_closed_form():
    """A block resting at distance d from a plane: every bottom node reports p(d) = -2 d kappa b'(d^2) / dhat^3."""
    mesh = box((2, 2, 1), (1.0, 1.0, 0.2)).translated([0.0, 0.0, 0.01])
    space = Space(mesh)
    contact = IPCContact(space, dhat=0.05, stiffness=10.0, planes=[Plane([0, 0, 0], [0, 0, 1])])
    u = np.zeros(space.n_dofs)
    bottom = mesh.p[2] < 0.011
    d, dhat = 0.01, 0.05
    s, sh = d * d, dhat * dhat
    closed = 2 * d * 10.0 * (2 * (s - sh) * np.log(s / sh) + (s - sh) ** 2 / s) / dhat ** 3
    assert contact.nodal_pressure(u, 0.0)[bottom] == pytest.approx(np.full(bottom.sum(), closed), rel=1e-12)
    assert barrier_pressure(d, dhat, 10.0) == pytest.approx(closed, rel=1e-14)
    assert barrier_pressure(dhat, dhat, 10.0) == 0.0
    assert barrier_pressure(0.5 * dhat, dhat, stiffness_for_pressure(3.0, dhat)) == pytest.approx(3.0, rel=1e-12)
    force = contact.assemble(u, 0.0, False, None).internal.reshape(-1, 3)
    assert force[bottom, 2].sum() == pytest.approx(-closed * contact.area[bottom].sum(), rel=1e-12)


def _pressed_sheet(pressure: float, dhat: float, kappa: float):
    """A sheet on rollers (u_x = u_y = 0) pushed by a follower pressure on its bottom against a plane above it; its
    top face is the contact surface (area weights summing to the pressed area)."""
    mesh = box((3, 3, 1), (1.0, 1.0, 0.1))
    solid = Solid(mesh, MATERIAL)
    solid.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), 0.0, components=[0, 1])
    solid.add_pressure(lambda x: x[2] < 1e-9, pressure)
    top = ContactSurface.from_facets(mesh, solid.space.facets_of(lambda x: x[2] > 0.1 - 1e-9))
    contact = IPCContact(solid.space, top, dhat=dhat, stiffness=kappa, planes=[Plane([0, 0, 0.108], [0, 0, -1])],
                         check_intersections=True)
    contact.supports = True
    solid.add_term(contact)
    return solid, contact, mesh


def test_sheet_inflated_against_a_plane_carries_the_pressure_at_the_closed_form_gap():
    """At equilibrium the plane carries the whole inflation pressure, and the gaps bracket d* with p(d*) = P (the
    barrier's area weights are thirds of triangles, the pressure's quarters of quads: measured spread 0.0083-0.0088
    about d* = 0.00865, the same for 3 and 6 divisions)."""
    P, dhat, kappa = 2.0, 0.01, 5.0
    solid, contact, mesh = _pressed_sheet(P, dhat, kappa)
    result = solve(solid, steps=8, rtol=1e-10, progress=False)
    u = result.solutions[-1]
    top = np.flatnonzero(mesh.p[2] > 0.1 - 1e-9)
    gap = 0.108 - (mesh.p[2, top] + u[3 * top + 2])
    expected = brentq(lambda d: barrier_pressure(d, dhat, kappa) - P, 1e-9, dhat * (1 - 1e-12))
    assert gap.min() < expected < gap.max() < dhat
    assert np.ptp(gap) < 0.1 * expected
    force = contact.assemble(u, 1.0, False, None).internal.reshape(-1, 3)
    assert -force[:, 2].sum() == pytest.approx(-P * 1.0, rel=1e-9)  # pushes the sheet down with P times its area
    assert contact.area.sum() == pytest.approx(1.0, rel=1e-12)
    assert contact.contact_area(u, 1.0) == pytest.approx(1.0, rel=1e-6)


def _block_over_obstacle(drop: float, gap: float, dhat: float, size: float = 2.0, rollers: bool = False):
    """A block whose top face is moved down by ``drop`` towards a fixed square obstacle ``gap`` below it (of side
    ``size``; ``rollers``: every node held laterally, so the compression is one-dimensional)."""
    mesh = box((2, 2, 2), (1.0, 1.0, 0.5))
    solid = Solid(mesh, MATERIAL)
    if rollers:
        solid.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), 0.0, components=[0, 1])
    solid.add_dirichlet(lambda X: X[2] > 0.5 - 1e-9, np.array([0.0, 0.0, -drop]))
    sheet = Obstacle.rectangle([0.5, 0.5, -gap], [0, 0, 1], size=size, divisions=2)
    contact = IPCContact(solid.space, dhat=dhat, stiffness=20.0, obstacles=[sheet], check_intersections=True)
    solid.add_term(contact)
    return solid, contact, mesh


def test_block_pressed_onto_an_obstacle_never_intersects_and_balances_forces():
    solid, contact, mesh = _block_over_obstacle(drop=0.2, gap=0.05, dhat=0.02)
    result = solve(solid, steps=1, rtol=1e-9, progress=False)
    u = result.solutions[-1]
    assert not contact.intersects(u, 1.0)
    distance = contact.minimum_distance(u, 1.0)
    assert 0.0 < distance < 0.02
    top = lambda X: X[2] > 0.5 - 1e-9
    reaction = result.reaction(top)
    contact_force = contact.assemble(u, 1.0, False, None).internal.reshape(-1, 3).sum(axis=0)
    assert reaction[2] == pytest.approx(contact_force[2], rel=1e-6)  # the residual at the supports is the barrier's
    assert reaction[2] < 0.0


@pytest.mark.parametrize("capped", [True, False])
def test_without_the_collision_free_cap_the_block_passes_through(monkeypatch, capped):
    """A sheet smaller than the block's base: with the cap the block stops on it; without, Newton's first iterate
    (a rigid translation) carries the base past it, beyond the barrier's range, and the solve 'converges' with the
    sheet swallowed inside the block. No surface then crosses another, so ``has_intersections`` cannot see it: only
    the capped line search prevents it."""
    solid, contact, mesh = _block_over_obstacle(drop=0.2, gap=0.05, dhat=0.02, size=0.6)
    if not capped:
        monkeypatch.setattr(IPCContact, "step_fraction", lambda self, u0, t0, u1, t1: 1.0)
    u = solve(solid, steps=1, rtol=1e-9, atol=1e-10, progress=False).solutions[-1]
    centre = int(np.argmin(np.linalg.norm(mesh.p.T - [0.5, 0.5, 0.0], axis=1)))  # the base node over the sheet
    if capped:
        assert u[3 * centre + 2] > -0.05 and 0.0 < contact.minimum_distance(u, 1.0) < 0.02
    else:
        assert u[3 * centre + 2] == pytest.approx(-0.2, abs=1e-9)  # through the sheet at z = -0.05
        assert not contact.intersects(u, 1.0)


def test_incremental_potential_presses_two_blocks_with_no_intersection_at_any_iterate():
    """Self-contact of two blocks: the lower one clamped at its base, the upper one's top moved down past the gap.
    Every line-search trial is checked, not only the accepted states."""
    mesh = _two_blocks(0.05)
    solid = Solid(mesh, MATERIAL)
    solid.add_dirichlet(lambda X: X[2] < 1e-9, 0.0)
    solid.add_dirichlet(lambda X: X[2] > 1.05 - 1e-9, np.array([0.0, 0.0, -0.12]))
    contact = IPCContact(solid.space, dhat=0.02, stiffness=20.0, check_intersections=True)
    solid.add_term(contact)
    trials = []
    original = IPCContact.assemble

    def watched(self, u, t, tangent, step):
        trials.append(self.intersects(u, t))
        return original(self, u, t, tangent, step)

    IPCContact.assemble = watched
    try:
        result = incremental_potential(solid, steps=2, options=IncrementalOptions(rtol=1e-9), progress=False)
    finally:
        IPCContact.assemble = original
    u = result.solutions[-1]
    assert len(trials) > 5 and not any(trials)
    assert 0.0 < contact.minimum_distance(u, 1.0) < 0.02
    upper_top = lambda X: X[2] > 1.05 - 1e-9
    lower_base = lambda X: X[2] < 1e-9
    assert result.reaction(upper_top)[2] == pytest.approx(-result.reaction(lower_base)[2], rel=1e-6)
    history = [record for step in result.histories for record in step]
    assert any(record["energy_merit"] for record in history)
    assert history[-1]["newton"]  # the last iterations use the unprojected tangent


def test_incremental_potential_agrees_with_newton_on_the_pressed_block():
    """On rollers the pressed block has one equilibrium; both solvers find it. (Free to bulge, the barrier over a
    coarse obstacle has several: measured 0.013 apart, energies 0.14904 and 0.14793, each with |R_f| < 1e-11.)"""
    solid, contact, _ = _block_over_obstacle(drop=0.1, gap=0.05, dhat=0.02, rollers=True)
    newton = solve(solid, steps=2, rtol=1e-10, atol=1e-12, max_iter=100, progress=False).solutions[-1]
    solid2, _, _ = _block_over_obstacle(drop=0.1, gap=0.05, dhat=0.02, rollers=True)
    minimised = incremental_potential(solid2, steps=2, options=IncrementalOptions(rtol=1e-10, atol=1e-12),
                                      progress=False).solutions[-1]
    assert np.abs(minimised - newton).max() <= 1e-7 * np.abs(newton).max()


def test_pseudo_transient_steps_are_capped_too():
    solid, contact, _ = _block_over_obstacle(drop=0.15, gap=0.05, dhat=0.02)
    weights = np.ones(solid.space.n_dofs) * 1e-3
    result = pseudo_transient(solid, weights, 1.0, PseudoTransientOptions(first_step=0.5, rtol=1e-8), progress=False)
    assert result.converged
    assert not contact.intersects(result.u, 1.0)
    assert 0.0 < contact.minimum_distance(result.u, 1.0) < 0.02


@pytest.mark.parametrize("mu", [0.0, 0.5])
def test_friction_holds_the_base_of_a_block_pressed_and_sheared_on_a_sheet(mu):
    """The top of a block moved down onto a sheet and sideways: frictionless, the base slides with the top (measured
    0.0503 of the top's 0.05); with mu = 0.5 it sticks to a third of it (measured 0.0148)."""
    mesh = box((2, 2, 1), (1.0, 1.0, 0.4))
    solid = Solid(mesh, MATERIAL)
    solid.add_dirichlet(lambda X: X[2] > 0.4 - 1e-9, np.array([0.05, 0.0, -0.06]))
    sheet = Obstacle.rectangle([0.5, 0.5, -0.03], [0, 0, 1], size=3.0, divisions=3)
    contact = IPCContact(solid.space, dhat=0.02, stiffness=20.0, obstacles=[sheet], check_intersections=True,
                         friction=Friction(mu=mu, slip=1e-3) if mu else None)
    solid.add_term(contact)
    u = solve(solid, steps=8, rtol=1e-8, atol=1e-10, max_iter=60, progress=False).solutions[-1]
    assert 0.0 < contact.minimum_distance(u, 1.0) < 0.02
    centre = int(np.argmin(np.linalg.norm(mesh.p.T - [0.5, 0.5, 0.0], axis=1)))
    if mu:
        assert 0.0 < u[3 * centre] < 0.5 * 0.05
    else:
        assert u[3 * centre] == pytest.approx(0.05, rel=0.05)


def test_an_obstacles_motion_enters_the_collision_free_step():
    """A punch moved up into a block that stands still: the step over the load factor is cut where they would
    meet (gap 0.03 closed by a 0.1 move: about 0.3 of it, times the safety factors)."""
    mesh = box((2, 2, 1), (1.0, 1.0, 0.4))
    space = Space(mesh)
    punch = Obstacle.rectangle([0.5, 0.5, -0.03], [0, 0, 1], size=0.6, divisions=1,
                               motion=lambda t: np.array([0.0, 0.0, 0.1 * t]))
    contact = IPCContact(space, dhat=0.01, stiffness=20.0, obstacles=[punch])
    u = np.zeros(space.n_dofs)
    assert contact.step_fraction(u, 0.0, u, 0.2) == 1.0  # 0.02 of travel: still short of the base
    fraction = contact.step_fraction(u, 0.0, u, 1.0)
    assert 0.5 * 0.3 < fraction < 0.3
    assert contact.positions(u, 1.0)[contact.n_body:, 2] == pytest.approx(np.full(4, 0.07))


def test_an_obstacle_joins_the_contact_at_its_active_from():
    """A sheet through the middle of a block, active from load factor 1: before, it is no part of the collision mesh
    (no intersection, no energy, no pairs), a move into its activation while the block overlaps it is refused naming
    it, and once the block is lifted clear the sheet repels it and caps a move back down."""
    mesh = box((2, 2, 1), (1.0, 1.0, 0.4))
    space = Space(mesh)
    sheet = dataclasses.replace(Obstacle.rectangle([0.5, 0.5, 0.2], [0, 0, 1], 2.0, name="arm"), active_from=1.0)
    contact = IPCContact(space, dhat=0.01, stiffness=20.0, obstacles=[sheet])
    u = np.zeros(space.n_dofs)
    assert not contact.intersects(u, 0.5) and contact.energy(u, 0.5) == 0.0 and contact.active_pairs(u, 0.5) == 0
    assert contact.intersects(u, 1.0)
    with pytest.raises(IntersectionError, match="arm join the contact by load factor 1 while the body overlaps"):
        contact.step_fraction(u, 0.5, u, 1.0)
    lifted = u.copy()
    lifted[2::3] = 0.205  # the block's base 0.005 above the sheet, within dhat
    assert contact.step_fraction(lifted, 0.5, lifted, 1.0) == 1.0
    assert contact.energy(lifted, 0.5) == 0.0 and contact.energy(lifted, 1.0) > 0.0
    force = contact.assemble(lifted, 1.0, False, None).internal[2::3]
    base = mesh.p[2] == 0.0
    assert np.all(force[base] < 0.0) and np.all(force[~base] == 0.0)  # lifting the base lowers the barrier
    lowered = lifted.copy()
    lowered[2::3] = 0.195
    assert contact.step_fraction(lifted, 1.0, lowered, 1.0) < 0.5


def test_bad_input_is_named():
    space = Space(box(1))
    with pytest.raises(ValueError, match="dhat"):
        IPCContact(space, dhat=0.0, stiffness=1.0)
    with pytest.raises(ValueError, match="stiffness"):
        IPCContact(space, dhat=0.1, stiffness=float("nan"))
    with pytest.raises(ValueError, match="threads"):
        IPCContact(space, dhat=0.1, stiffness=1.0, threads=0)
    with pytest.raises(ValueError, match="obstacle 'arm'"):
        Obstacle(np.zeros((3, 3)), [[0, 1, 5]], name="arm")
    with pytest.raises(ValueError, match="plane"):
        Plane([0, 0, 0], [0, 0, 0])
    with pytest.raises(IntersectionError, match="reference"):  # an obstacle cutting through the body at rest
        IPCContact(space, dhat=0.1, stiffness=1.0, obstacles=[Obstacle.rectangle([0.5, 0.5, 0.5], [0, 0, 1], 2.0)])


def test_plane_barrier_matches_ipctk_where_ipctk_builds_plane_pairs():
    """The closed-form plane barrier (skvalve.fem.contact.plane_barrier) against ipctk's plane-vertex pairs, at
    distances below dhat/2 where ipctk 1.6.1 builds them: energy and gradient to round-off."""
    mesh = box((3, 3, 1), (1.0, 1.0, 0.1))
    space = Space(mesh)
    dhat, kappa = 0.05, 7.0
    ours = IPCContact(space, dhat=dhat, stiffness=kappa, planes=[Plane([0, 0, -0.004], [0, 0, 1])])
    rng = np.random.default_rng(3)
    u = np.zeros(space.n_dofs)
    u[2::3] = 0.01 * rng.random(space.n_scalar)  # distances 0.004-0.014 < dhat / 2
    V = ours.positions(u, 0.0)
    reference = ipctk.CollisionMesh(ours.rest, ipctk.edges(ours.mesh.faces), ours.mesh.faces)
    reference.planes = [ipctk.Hyperplane(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -0.004]))]
    reference.can_collide = ipctk.make_vertex_patches_filter(np.zeros(V.shape[0], dtype=np.int32))  # planes only
    collisions = ipctk.NormalCollisions()
    collisions.use_area_weighting = True
    collisions.build(reference, V, dhat)
    assert len(collisions.pv_collisions) == int((mesh.p[2] < 1e-9).sum())
    barrier = ipctk.BarrierPotential(dhat, kappa, True)
    assert ours.energy(u, 0.0) == pytest.approx(barrier(collisions, reference, V), rel=1e-12)
    gradient = ours.assemble(u, 0.0, False, None).internal[: space.n_u].reshape(-1, 3)[ours.nodes]
    assert gradient.ravel() == pytest.approx(barrier.gradient(collisions, reference, V), rel=1e-10, abs=1e-12)


def _cylinder_on_plane(divisions: int):
    """A plane-strain block with a parabolic base z = x^2 / 2R (R = 1) pressed 0.004 onto a plane: the contact width
    and the line load, for Hertz's half-width b = sqrt(4 F R / (pi E*))."""
    radius, half, height, depth = 1.0, 0.4, 0.4, 0.05
    mesh = box((divisions, 1, divisions // 4), (2 * half, depth, height)).translated([-half, 0.0, 0.0])
    x, y, z = mesh.p
    mesh = skfem.MeshHex(np.vstack([x, y, z + (1.0 - z / height) * x ** 2 / (2.0 * radius)]), mesh.t)
    solid = Solid(mesh, MATERIAL)
    solid.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), 0.0, components=[1])  # plane strain
    top = lambda X: np.isclose(X[2], height)
    solid.add_dirichlet(top, np.array([0.0, -0.004]), components=[0, 2])
    contact = IPCContact(solid.space, dhat=5e-4, stiffness=200.0, planes=[Plane([0, 0, -4e-4], [0, 0, 1])])
    contact.supports = True
    solid.add_term(contact)
    result = solve(solid, steps=4, rtol=1e-8, atol=1e-10, max_iter=60, progress=False)
    load = -result.reaction(top)[2] / depth
    E = 2.0 * 10.0 * 1.3
    half_width = np.sqrt(4.0 * load * radius / (np.pi * E / (1.0 - 0.3 ** 2)))
    return contact.contact_area(result.solutions[-1], 1.0) / depth, 2.0 * half_width, 2.0 * half / divisions


def test_contact_width_of_a_cylinder_on_a_plane_converges_to_hertz():
    """Measured: width / 2b = 0.72, 0.90, 0.99 for element sizes 0.02, 0.01, 0.005 (the contact area counts faces
    all of whose nodes touch, so it misses up to about one element at each edge of the strip)."""
    errors = []
    for divisions in (80, 160):
        width, hertz, size = _cylinder_on_plane(divisions)
        assert abs(width - hertz) <= 1.5 * size
        errors.append(abs(width - hertz))
    assert errors[1] < 0.5 * errors[0]
    assert width == pytest.approx(hertz, rel=0.05)


def test_suggested_stiffness_balances_the_elastic_gradient():
    """IPC's initial stiffness: -g_E.g_B / |g_B|^2 (g_B the barrier gradient at unit stiffness) where that exceeds
    IPC's floor; the floor itself for small elastic gradients."""
    _, contact, _ = _block_over_obstacle(drop=0.0, gap=0.01, dhat=0.02)
    space = contact.space
    u = np.zeros(space.n_dofs)
    unit = IPCContact(space, dhat=0.02, stiffness=1.0, obstacles=contact.obstacles).assemble(u, 0.0, False, None)
    g = np.zeros(space.n_dofs)
    g[2::3] = 1e4
    kappa, largest = contact.suggest_stiffness(g, u, 0.0)
    assert kappa == pytest.approx(-(g @ unit.internal) / (unit.internal @ unit.internal), rel=1e-9)
    floor, _ = contact.suggest_stiffness(1e-3 * g, u, 0.0)
    assert 0.0 < floor < kappa < largest


@pytest.mark.parametrize("velocity", [False, True])
def test_incremental_step_with_mass_is_implicit_euler(velocity):
    """With a mass M and time step h each step's state satisfies R(u) + M (u - u~) / h^2 = 0 on the free dofs, with
    u~ = u_n (pseudo-mass) or u_n + h v_n (inertia, v_n = (u_n - u_{n-1}) / h): the stationarity of the step's
    incremental potential, checked from the residual the problem assembles afterwards."""
    solid, contact, _ = _block_over_obstacle(drop=0.1, gap=0.05, dhat=0.02, rollers=True)
    h = 0.5
    mass = np.full(solid.space.n_dofs, 3.0)
    result = incremental_potential(solid, steps=3, mass=mass, time_step=h, velocity=velocity,
                                   options=IncrementalOptions(rtol=1e-11, atol=1e-13), progress=False)
    u0, u1, u2 = result.solutions[-3:]
    predictor = u1 + (u1 - u0 if velocity else 0.0)
    residual, _ = solid.assemble(u2, 1.0, tangent=False)
    free = solid.pattern.free
    balance = residual[free] + mass[free] * (u2 - predictor)[free] / h ** 2
    assert np.linalg.norm(balance) <= 1e-9 * np.linalg.norm(residual[free])
    assert np.linalg.norm(residual[free]) > 1e-6  # the inertia carries part of the load: not the static state


def test_a_move_longer_than_the_reach_is_checked_on_its_first_part():
    """A trial on which a vertex travels farther than ``reach`` (CCD_REACH_EDGES mean edge lengths) is swept only up to
    there: free there, the share is reach/move; hitting the other block within it, 0.9 of the first contact's share of
    the whole move, the first contact taken from ipctk's collision-free step of a hundredth of that move."""
    mesh = _two_blocks(0.02)
    space = Space(mesh)
    contact = IPCContact(space, dhat=0.005, stiffness=50.0)
    upper = mesh.p[2] > 0.5 + 1e-9
    n, zero = space.n_dofs, np.zeros(space.n_dofs)
    away = np.zeros(n)
    away[2::3][upper] = 100.0 * contact.reach  # upwards, away from the lower block: free but very long
    assert contact.step_fraction(zero, 0.0, away, 0.0) == pytest.approx(0.01, rel=1e-12)
    down = np.zeros(n)
    down[2::3][upper] = -0.03 * (1.0 + 0.2 * mesh.p[0][upper])  # a tilting move through the 0.02 gap
    first = float(ipctk.compute_collision_free_stepsize(contact.mesh, contact.positions(zero, 0.0),
                                                        contact.positions(down, 0.0)))
    assert 0.3 < first < 1.0
    contact.reach = 0.1  # a hundredfold move then reaches 0.1 of 3.6: its first contact lies within the reach
    assert contact.step_fraction(zero, 0.0, 100.0 * down, 0.0) == pytest.approx(0.9 * first / 100.0, rel=1e-2)


def test_the_trust_regions_step_matrix_projects_the_barrier_stencil_by_stencil():
    """``step_matrix`` with the contact named for projection (the valve's settle stage) is the symmetric tangent with
    the barrier's exact Hessian replaced by ipctk's per-stencil projection (the term's ``projected_matrix``), not by
    the projection of each connected patch as a whole: the two differ here, and only the per-stencil one is what
    the load path's projected steps use."""
    mesh = _two_blocks(0.02)
    solid = Solid(mesh, MATERIAL)
    contact = IPCContact(solid.space, dhat=0.05, stiffness=50.0)
    solid.add_term(contact)
    u = 2e-3 * np.random.default_rng(7).standard_normal(solid.space.n_dofs)
    assert contact.active_pairs(u, 0.0) > 10
    _, tangent = solid.assemble(u, 0.0, tangent=True)
    own = contact.assemble(u, 0.0, True, None)
    free = solid.pattern.free

    def on_free(matrix):
        return (0.5 * (matrix + matrix.T)).tocsr()[free][:, free].toarray()

    plain = step_matrix(solid, tangent, False).toarray()
    stencils = step_matrix(solid, tangent, False, (contact.name,)).toarray()
    expected = plain - on_free(own.matrix) + on_free(own.projected_matrix)
    np.testing.assert_allclose(stencils, expected, atol=1e-12 * np.abs(expected).max())
    patches = plain - on_free(own.matrix) + on_free(project_sparse_psd(own.matrix))
    assert np.abs(stencils - patches).max() > 1e-6 * np.abs(on_free(own.matrix)).max()
    everything = step_matrix(solid, tangent, True).toarray()  # every term projected (the descend stage): semidefinite
    assert np.linalg.eigvalsh(everything).min() >= -1e-9 * np.abs(everything).max()
