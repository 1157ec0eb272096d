"""Energy trust-region Newton (:mod:`skvalve.fem.solvers.trust_region`): it ends where Newton and closed forms end,
crosses a
region of negative curvature to the stable equilibrium, measures the energy change exactly where it can, and fails
clearly."""

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
import skfem
from _truss_checks import sheared_block
from scipy.optimize import brentq

from skvalve.fem import HyperelasticTerm, MaterialRegions, NodalForce, Problem, Solid, Space, solve
from skvalve.fem.elements.truss import Truss
from skvalve.fem.errors import ConvergenceError, StateRefused
from skvalve.fem.loads import FollowerPressure
from skvalve.fem.solvers.block_relaxation import BlockRelaxation
from skvalve.fem.solvers.incremental import IncrementalOptions, minimise_step
from skvalve.fem.solvers.linsolve import LinearSolver, available_solvers, solver_name
from skvalve.fem.solvers.trust_region import (
    TrustRegionOptions,
    fitted_shift,
    project_psd,
    project_sparse_psd,
    step_matrix,
    trust_region,
    work_along,
)
from skvalve.fem.solvers.trust_steps import shift_psd
from skvalve.fem.terms import Contribution, Term
from skvalve.materials import NeoHookean
from skvalve.materials.uniaxial import OgdenUniaxial, TensionOnly


def test_ends_where_load_stepped_newton_ends_and_finishes_with_newton_steps():
    """Path independence: from the reference at the full load (no load steps), the trust region must reach the
    state of 10 converged Newton load steps, every accepted step lowering the energy, the last steps Newton's."""
    newton = solve(sheared_block(), 10, progress=False, rtol=1e-11)
    block = sheared_block()
    seen = []
    result = trust_region(block, 1.0, np.zeros(block.space.n_dofs), TrustRegionOptions(rtol=1e-11, radius=0.1),
                          progress=False, callbacks=[seen.append])
    assert result.converged
    assert np.abs(result.u - newton.u()).max() <= 1e-9 * np.abs(newton.u()).max()
    residual, _ = block.assemble(result.u, 1.0, tangent=False)
    assert np.linalg.norm(residual[block.pattern.free]) <= 1e-11 * np.linalg.norm(residual[block.pattern.fixed])
    assert all(change < 0.0 for change in result.energy_changes)
    assert min(result.ratios) >= 0.1 and result.newton_steps >= 1 and result.shifts[-1] == 0.0
    assert result.largest_increments[0] == pytest.approx(0.1)  # the first step was held to the radius
    assert [event.step for event in seen] == list(range(1, len(result.residuals) + 1))


def _flap(pressure: float = 2e-3):
    """A 4 x 1 x 0.2 neo-Hookean flap clamped at x = 0 under a follower pressure on its top: the pressure on a surface
    with free edges is not conservative, and at this load the curled flap's symmetric tangent is indefinite."""
    mesh = skfem.MeshHex.init_tensor(np.linspace(0.0, 4.0, 9), np.linspace(0.0, 1.0, 2), np.linspace(0.0, 0.2, 2))
    flap = Solid(mesh, NeoHookean(1.0, 10.0))
    flap.add_dirichlet(lambda X: np.isclose(X[0], 0.0), 0.0)
    top = mesh.facets_satisfying(lambda x: np.isclose(x[2], 0.2), boundaries_only=True)
    flap.add_term(FollowerPressure(flap.space, top, pressure))
    return flap


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="the inertia needs PARDISO")
def test_newton_tries_converge_where_the_energy_model_of_a_follower_load_stalls():
    """The curled flap: the load-stepped Newton state has one negative eigenvalue of K_s, so it is no minimum of any
    energy and the energy trust region circles it (300 steps, residual 1e-2 to 1e-6); with full-tangent Newton tries
    below 1e-2 the run ends on that state, and reports the eigenvalue."""
    newton = solve(_flap(), 10, progress=False, rtol=1e-10).u()
    options = TrustRegionOptions(rtol=1e-10, radius=0.2, max_radius=2.0, max_steps=150)
    with pytest.raises(ConvergenceError, match="150 steps without converging"):
        trust_region(_flap(), 1.0, np.zeros(newton.size), options, progress=False)
    result = trust_region(_flap(), 1.0, np.zeros(newton.size), replace(options, newton_below=1e-2), progress=False)
    assert result.converged and result.negative_eigenvalues == 1
    assert np.abs(result.u - newton).max() <= 1e-9 * np.abs(newton).max()
    assert 1 <= result.newton_tries and np.isnan(result.ratios[-1])  # the last step was a kept Newton try
    tail = np.array(result.residuals[-3:])  # quadratic: each residual about the square of the one before
    assert np.log(tail[2] / tail[1]) / np.log(tail[1] / tail[0]) >= 1.6


def test_a_failed_newton_try_is_rewound():
    """Tries asked to cut the residual to 1e-14 of itself, without backtracking, all fail: the run ends where the plain
    trust region ends."""
    plain = trust_region(sheared_block(), 1.0, np.zeros(sheared_block().space.n_dofs),
                         TrustRegionOptions(rtol=1e-11, radius=0.1), progress=False)
    tried = trust_region(sheared_block(), 1.0, np.zeros(plain.u.size),
                         TrustRegionOptions(rtol=1e-11, radius=0.1, newton_below=1.0, newton_decrease=1e-14,
                                            newton_backtracks=0),
                         progress=False)
    assert tried.converged and tried.newton_tries >= 1 and tried.newton_steps == plain.newton_steps
    assert np.abs(tried.u - plain.u).max() <= 1e-9 * np.abs(plain.u).max()
    assert tried.residuals == pytest.approx(plain.residuals, rel=1e-6)


def test_a_newton_try_that_overshoots_backtracks_to_the_fraction_that_lowers_the_residual():
    """The arch's apex lifted to y = 0.4 under a load of 0.02 (above its limit load: the equilibrium lies below the
    supports): Newton's full step lowers the residual only to about 0.6 of itself, its half to about 0.66. Without
    backtracking the try fails (the first step is an energy step); with it the half step is kept (1 - 0.5 x 0.5 =
    0.75 allowed). Both runs end on the closed-form equilibrium."""
    problem, law, h, dof = _arch(0.02)
    start = np.zeros(problem.space.n_dofs)
    start[dof] = 0.4 - h
    residual, tangent = problem.assemble(start, 1.0)
    full = -residual[dof] / problem.tangent_matrix(tangent).toarray()[0, 0]

    def ratio(fraction):
        trial = start.copy()
        trial[dof] += fraction * full
        return abs(problem.assemble(trial, 1.0, tangent=False)[0][dof]) / abs(residual[dof])

    assert ratio(1.0) > 0.5 and ratio(0.5) <= 0.75  # the case this test is about
    options = TrustRegionOptions(rtol=1e-12, radius=0.05, max_radius=1.0, project=False, newton_below=1e9)
    first = []
    result = trust_region(problem, 1.0, start, options, progress=False,
                          callbacks=[lambda event: first.append(event.u[dof] - start[dof]) if not first else None])
    assert result.converged and np.isnan(result.ratios[0])  # the first step a kept Newton try ...
    assert first[0] == pytest.approx(0.5 * full, rel=1e-12)  # ... of half Newton's step
    root = brentq(lambda yy: _arch_force(law, yy) + 0.02, -2.0, -0.13, xtol=1e-15)  # past the limit load
    assert h + result.u[dof] == pytest.approx(root, rel=1e-9)
    plain = trust_region(_arch(0.02)[0], 1.0, start, replace(options, newton_backtracks=0), progress=False)
    assert plain.converged and not np.isnan(plain.ratios[0])  # without backtracking the first try fails
    assert h + plain.u[dof] == pytest.approx(root, rel=1e-9)


def _arch(load: float):
    """A shallow two-bar (von Mises) arch of incompressible Ogden bars: supports at x = 0 and 2, apex at (1, h), only
    the apex's vertical dof free, a dead load ``load`` pushing it down. Returns problem, law, h, apex y dof."""
    mesh = skfem.MeshHex().scaled([2.0, 0.4, 1.0]).refined(1)  # vertices at y = 0, 0.2, 0.4
    space = Space(mesh)
    X = space.dof_coordinates
    def node(x, y, z):
        return int(np.flatnonzero(np.isclose(X[0], x) & np.isclose(X[1], y) & np.isclose(X[2], z))[0])
    left, right, apex = node(0, 0, 0), node(2, 0, 0), node(1, 0.2, 0)
    law = OgdenUniaxial((1.0,), (2.0,))
    problem = Problem(space, [Truss(space, [[left, apex], [right, apex]], 0.1, law)])
    nodes = np.arange(space.n_scalar)
    problem.add_dirichlet(nodes=nodes, value=0.0, components=[0, 2])
    problem.add_dirichlet(nodes=nodes[nodes != apex], value=0.0, components=[1])
    problem.add_term(NodalForce(space, np.array([apex]), np.array([0.0, -load, 0.0]), ramp=False))
    return problem, law, 0.2, 3 * apex + 1


def _arch_force(law, y, h=0.2, a=1.0, area=0.1):
    """The bars' internal force on the apex's vertical dof at height y, the derivative of their energy
    2 A L0 W(lambda(y)) (closed form): 2 A P(lambda) y / L; a compressed arch (P < 0, y > 0) pushes the apex up."""
    length = np.hypot(a, y)
    stretch = length / np.hypot(a, h)
    return 2.0 * area * law.nominal_stress(np.array([stretch]))[0][0] * y / length


def test_snaps_through_a_limit_point_to_the_stable_equilibrium():
    """Past the arch's limit load the only equilibria have the apex below the supports: the tangent turns negative on
    the way (the region between the limit points), the inertia test shifts it, and the run ends on the closed-form
    root with a positive stiffness."""
    heights = np.linspace(0.0, 0.2, 401)
    upward = np.array([-_arch_force(OgdenUniaxial((1.0,), (2.0,)), y) for y in heights])  # compression holds it up
    limit = upward.max()
    load = 1.5 * limit
    problem, law, h, dof = _arch(load)
    options = TrustRegionOptions(rtol=1e-12, radius=0.05, max_radius=0.5, project=False)
    heights_seen = []
    result = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), options, progress=False,
                          callbacks=[lambda event: heights_seen.append(h + event.u[dof])])
    assert result.converged
    y = h + result.u[dof]
    root = brentq(lambda yy: _arch_force(OgdenUniaxial((1.0,), (2.0,)), yy) + load, -2.0, -1e-9, xtol=1e-15)
    assert y == pytest.approx(root, rel=1e-9)
    stiffness = (_arch_force(law, y + 1e-6) - _arch_force(law, y - 1e-6)) / 2e-6
    assert stiffness > 0.0  # a stable equilibrium
    # accepted states inside the unstable branch (negative stiffness): the region was crossed, not jumped
    assert sum(_arch_force(law, yy + 1e-6) < _arch_force(law, yy - 1e-6) for yy in heights_seen) >= 2
    assert all(change < 0.0 for change in result.energy_changes)


def test_work_along_a_step_is_exact_for_a_quartic_energy():
    """Simpson's rule integrates the residual's work exactly when the energy is a quartic polynomial along the step."""
    rng = np.random.default_rng(4)
    a, b, c = rng.normal(size=(3, 5))

    def energy(x):
        return float(a @ x + (b @ x) ** 2 + (c @ x) ** 4 / 4.0)

    def gradient(x):
        return a + 2.0 * (b @ x) * b + (c @ x) ** 3 * c

    u, p = rng.normal(size=(2, 5))
    work = work_along(gradient(u), gradient(u + 0.5 * p), gradient(u + p), p)
    assert work == pytest.approx(energy(u + p) - energy(u), rel=1e-12)


def test_projected_blocks_are_the_nearest_semidefinite_ones():
    rng = np.random.default_rng(5)
    blocks = rng.normal(size=(20, 6, 6))
    projected = project_psd(blocks)
    symmetric = 0.5 * (blocks + np.swapaxes(blocks, 1, 2))
    assert np.allclose(projected, np.swapaxes(projected, 1, 2))
    assert np.linalg.eigvalsh(projected).min() >= -1e-12
    values, vectors = np.linalg.eigh(symmetric)
    # the difference is exactly the negative spectral part
    negative = np.einsum("eik,ek,ejk->eij", vectors, np.minimum(values, 0.0), vectors)
    np.testing.assert_allclose(symmetric - projected, negative, atol=1e-12)
    definite = np.einsum("eij,ekj->eik", blocks, blocks)
    np.testing.assert_allclose(project_psd(definite), definite, atol=1e-12)
    # a sparse matrix (contact's): each connected block projected on its own; the pattern's other entries stay zero
    a, b = rng.normal(size=(2, 3, 3))
    dense = np.zeros((8, 8))
    dense[np.ix_([0, 2, 5], [0, 2, 5])] = a + a.T
    dense[np.ix_([1, 6, 7], [1, 6, 7])] = b @ b.T  # already semidefinite: unchanged
    projected_sparse = project_sparse_psd(sp.csr_matrix(dense)).toarray()
    expected = np.zeros((8, 8))
    expected[np.ix_([0, 2, 5], [0, 2, 5])] = project_psd((a + a.T)[None])[0]
    expected[np.ix_([1, 6, 7], [1, 6, 7])] = b @ b.T
    np.testing.assert_allclose(projected_sparse, expected, atol=1e-12)
    # on a solid in compression, the step matrix is the projected blocks assembled: positive semidefinite
    block = sheared_block()
    u = np.zeros(block.space.n_dofs)
    u[block.pattern.fixed] = block.constrained(1.0)[1]
    _, tangent = block.assemble(u, 1.0)
    H = step_matrix(block, tangent, project=True).toarray()
    assert np.allclose(H, H.T) and np.linalg.eigvalsh(H).min() >= -1e-10 * np.abs(H).max()


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="PARDISO reports the inertia")
def test_the_symmetric_factorisation_reports_the_inertia():
    values = np.array([3.0, -1.0, 2.0, -4.0, 5.0, 1e-3])
    rng = np.random.default_rng(6)
    Q, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    A = sp.csr_matrix(Q @ np.diag(values) @ Q.T)
    solver = LinearSolver("pardiso", symmetric=True)
    solver.analyse(A).factorize(A)
    assert solver.inertia() == (4, 2)
    assert LinearSolver("scipy", symmetric=True).analyse(A).factorize(A).inertia() is None


def test_bad_options_and_giving_up_keep_the_last_state():
    for bad in ({"radius": 0.0}, {"eta": 0.5}, {"min_radius": 1.0, "radius": 0.5}, {"max_strain_increment": -1.0},
                {"max_steps": 0}, {"atol": float("nan")}, {"min_shift": 10.0, "max_shift": 1.0},
                {"newton_below": -1.0}, {"newton_decrease": 1.0}):
        with pytest.raises(ValueError, match="TrustRegionOptions"):
            TrustRegionOptions(**bad)
    block = sheared_block()
    with pytest.raises(ValueError, match="finite"):
        trust_region(block, 1.0, np.full(block.space.n_dofs, np.nan), progress=False)
    with pytest.raises(ConvergenceError, match="2 steps without converging") as info:
        trust_region(block, 1.0, np.zeros(block.space.n_dofs), TrustRegionOptions(max_steps=2, radius=0.01),
                     progress=False)
    state = info.value.last_state
    assert len(state.residuals) == 2 and np.isfinite(state.u).all() and state.relative_residual < 1.0


def _tethered_block(slack_fraction: float = 1e-6):
    """A unit block (2x2x2 hexes) clamped at x = 0, tethered from its x = 1 face by four tension-only Ogden cables to
    a hub (a vertex of no cell) that a fifth cable ties to an anchor pulled 0.4 along x. Returns problem, hub, law."""
    block = skfem.MeshHex().refined(1)
    extra = np.array([[1.6, 0.5, 0.5], [2.0, 0.5, 0.5]]).T  # hub, anchor: numbered first (below the cells' vertices)
    mesh = skfem.MeshHex(np.hstack([extra, block.p]), block.t + 2)
    space = Space(mesh)
    X = mesh.p
    corners = [int(np.flatnonzero(np.all(np.isclose(X.T, c), axis=1))[0])
               for c in ([1, 0, 0], [1, 1, 0], [1, 0, 1], [1, 1, 1])]
    law = TensionOnly(OgdenUniaxial((0.5,), (8.0,)), slack_fraction=slack_fraction)
    cables = [[c, 0] for c in corners] + [[0, 1]]
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 5.0)))])
    truss = problem.add_term(Truss(space, cables, 0.01, law))
    problem.add_dirichlet(nodes=np.flatnonzero(np.isclose(X[0], 0.0) & (np.arange(X.shape[1]) >= 2)), value=0.0)
    problem.add_dirichlet(nodes=[1], value=np.array([0.4, 0.0, 0.0]))
    return problem, truss, 0


def test_block_relaxation_of_a_hub_keeps_it_balanced_and_the_end_state():
    """Relaxing the hub (only cables pull on it) after every accepted step leaves it in balance at every step, lowers
    the energy, and changes the path, not the equilibrium: the end state is the one reached without it."""
    problem, truss, hub = _tethered_block()
    plain = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), TrustRegionOptions(rtol=1e-10),
                         progress=False)
    problem, truss, hub = _tethered_block()
    relax = BlockRelaxation(problem, problem.space.displacement_dofs(np.array([hub])).ravel(), [truss], tol=1e-12)
    balance = []

    def hub_residual(event):
        balance.append(float(np.linalg.norm(relax.residual(event.u, 1.0)[0])))

    relaxed = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), TrustRegionOptions(rtol=1e-10),
                           progress=False, relax=relax, callbacks=[hub_residual])
    assert plain.converged and relaxed.converged
    np.testing.assert_allclose(relaxed.u, plain.u, atol=1e-8 * np.abs(plain.u).max())
    assert max(balance) <= 1e-12 and all(change < 0.0 for change in relaxed.energy_changes)
    # the block's residual is the cables' force on the hub, and a term left out that touches it is refused
    with pytest.raises(ValueError, match="also acts"):
        face_node = int(np.flatnonzero(np.isclose(problem.space.mesh.p[0], 1.0))[0])  # in a hex and a cable
        BlockRelaxation(problem, problem.space.displacement_dofs(np.array([face_node])).ravel(), [truss])


def test_block_relaxation_inside_a_load_step_balances_the_proximal_block_and_keeps_the_minimiser():
    """Inside a load step of the incremental potential the hub's sweep carries the step's proximal term: at the
    relaxed state the whole problem's force on the hub (assembled apart) plus w (u - u~) vanishes, and the step's
    minimiser is the one reached without the sweep."""
    problem, truss, hub = _tethered_block()
    n = problem.space.n_dofs
    inertia, predictor = np.full(n, 0.3), np.zeros(n)
    hub_dofs = problem.space.displacement_dofs(np.array([hub])).ravel()
    relax = BlockRelaxation(problem, hub_dofs, [truss], tol=1e-12)
    u = np.zeros(n)
    _, values = problem.constrained(1.0)
    u[problem.pattern.fixed] = values  # the anchor pulled: the hub is out of balance
    _, before = problem.assemble(u, 1.0, tangent=True)
    relaxed, info = relax(u, 1.0, proximal=(inertia, predictor))
    force, full = problem.assemble(relaxed, 1.0, tangent=True)
    partial, reused = problem.assemble(relaxed, 1.0, tangent=True, reuse=before, fresh=relax.terms)
    np.testing.assert_array_equal(partial, force)  # only the cables touch the hub: their re-assembly suffices
    assert (problem.tangent_matrix(reused) != problem.tangent_matrix(full)).nnz == 0
    assert info.iterations > 0 and info.energy_change < 0.0 and info.initial_norm > 1e-3
    assert np.linalg.norm(force[hub_dofs] + inertia[hub_dofs] * relaxed[hub_dofs]) <= 1e-11
    opts = IncrementalOptions(rtol=1e-11, reference=1.0)
    ends, counts = [], []
    for with_sweep in (False, True):
        problem, truss, hub = _tethered_block()
        sweep = BlockRelaxation(problem, hub_dofs, [truss], tol=1e-12) if with_sweep else None
        end, _, history = minimise_step(problem, np.zeros(n), 0.0, 1.0, predictor, inertia, 1, opts,
                                        solver_name(None), relax=sweep)
        ends.append(end)
        counts.append(len(history))
    np.testing.assert_allclose(ends[1], ends[0], atol=1e-9 * np.abs(ends[0]).max())
    # the line search's trials carry the sweep too (the hub re-minimised on each): no more iterations than without
    assert counts[1] <= counts[0], counts


def test_fitted_shift_brings_the_node_that_moves_most_to_the_radius():
    """A node that moves along one mode of the pencil (H, D) (a diagonal H: stiffness lambda along y) steps by
    c/(lambda + alpha): the fitted shift is the closed form c/radius - lambda, from the step taken with any shift."""
    lambdas = np.array([4.0, 1e-4, 2.0])
    for shift in (0.0, 1e-3, 0.5):
        moving = np.array([0.0, 0.3 / (1e-4 + shift), 0.0])
        alpha = fitted_shift(moving, lambdas * moving, moving, shift, 0.05)
        assert alpha == pytest.approx(0.3 / 0.05 - 1e-4, rel=1e-12)
        assert 0.3 / (1e-4 + alpha) == pytest.approx(0.05, rel=1e-12)
    assert fitted_shift(np.array([0.01, 0.0, 0.0]), np.zeros(3), np.full(3, 1.0), 0.2, 0.05) == 0.2  # never lower
    with pytest.raises(ValueError, match="fit_radius"):
        TrustRegionOptions(fit_radius=-1)


def _pendulum_block(force: float = 0.002):
    """A unit block (4x4x4 hexes) clamped at x = 0, its face x = 1 moved 0.3 along z, with a bob (a vertex of no
    cell) hung from that face's centre by one Ogden cable and pulled sideways by a dead force: the unstressed cable
    gives the bob no lateral stiffness, so Newton's step swings it far while the block needs a stiff correction."""
    block = skfem.MeshHex().refined(2)
    mesh = skfem.MeshHex(np.hstack([[[1.0], [0.5], [1.5]], block.p]), block.t + 1)  # the bob is vertex 0
    space = Space(mesh)
    X = mesh.p
    centre = int(np.flatnonzero(np.all(np.isclose(X.T, [1.0, 0.5, 1.0]), axis=1))[0])
    law = OgdenUniaxial((0.5,), (8.0,))
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 10.0)))])
    problem.add_term(Truss(space, [[centre, 0]], 0.01, law))
    problem.add_term(NodalForce(space, np.array([0]), np.array([force, 0.0, 0.0]), ramp=True))
    cells = np.arange(X.shape[1]) >= 1
    problem.add_dirichlet(nodes=np.flatnonzero(np.isclose(X[0], 0.0) & cells), value=0.0)
    problem.add_dirichlet(nodes=np.flatnonzero(np.isclose(X[0], 1.0) & cells), value=np.array([0.0, 0.0, 0.3]))
    return problem, centre, law


def test_a_radius_fitted_shift_solves_the_stiff_part_while_a_soft_mode_swings():
    """Scaled into the radius, Newton's step (dominated by the bob's swing) corrects the block by the same small
    fraction and the residual stalls while the bob travels. With the shift fitted to the radius it falls while the bob
    swings: slowly under Marquardt's diagonal shift, which damps the block's modes as much as the bob's, at once under a
    uniform one, which damps only what is softer than the shift. All runs end at the same equilibrium: the cable along
    the force, its tension the force (closed form)."""
    options = TrustRegionOptions(rtol=1e-10, radius=0.05, max_radius=0.1, max_steps=300)
    runs = {}
    for fit, scaling in ((0, "diagonal"), (3, "diagonal"), (3, "uniform")):
        problem, centre, law = _pendulum_block()
        runs[fit, scaling] = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs),
                                          replace(options, fit_radius=fit, shift_scaling=scaling), progress=False)
        assert runs[fit, scaling].converged
        x = problem.space.mesh.p.T + runs[fit, scaling].u[: problem.space.n_u].reshape(-1, 3)
        cable = x[0] - x[centre]
        np.testing.assert_allclose(cable / np.linalg.norm(cable), [1.0, 0.0, 0.0], atol=1e-8)
        assert 0.01 * law.nominal_stress(np.linalg.norm(cable) / 0.5)[0] == pytest.approx(0.002, rel=1e-8)
    plain, fitted, uniform = runs[0, "diagonal"], runs[3, "diagonal"], runs[3, "uniform"]
    assert plain.radius_fits == 0 and fitted.radius_fits >= 5 and uniform.radius_fits >= 5
    for run in (fitted, uniform):
        assert np.abs(run.u - plain.u).max() <= 1e-8 * np.abs(plain.u).max()
        assert len(run.residuals) < len(plain.residuals)
    assert max(plain.residuals[5:15]) >= 0.9 * plain.residuals[0]  # the plain run stalls while the bob swings
    assert fitted.residuals[12] <= 1e-2 * plain.residuals[12]  # while the fitted one has nearly converged
    assert fitted.residuals[3] >= 0.3 * fitted.residuals[0]  # the diagonal shift held the block back
    assert uniform.residuals[3] <= 0.1 * uniform.residuals[0]  # the uniform one did not
    with pytest.raises(ValueError, match="shift_scaling"):
        TrustRegionOptions(shift_scaling="marquardt")



def test_projecting_named_terms_only():
    """With the bob pushed towards the block (its cable compressed: negative lateral stiffness -N/l) and the block
    unstrained (its element blocks already semidefinite), projecting the cable's blocks alone gives the fully projected
    step matrix, and differs from the unprojected one by a positive semidefinite matrix of the cable's dofs."""
    problem, centre, _ = _pendulum_block()
    u = np.zeros(problem.space.n_dofs)
    u[problem.space.displacement_dofs(np.array([0])).ravel()] = [0.0, 0.0, -0.1]  # cable stretch 0.8
    _, tangent = problem.assemble(u, 1.0, tangent=True)
    truss = next(term for term in problem.terms if isinstance(term, Truss))
    named = step_matrix(problem, tangent, False, (truss.name,)).toarray()
    everything = step_matrix(problem, tangent, True).toarray()
    plain = step_matrix(problem, tangent, False).toarray()
    np.testing.assert_allclose(named, everything, atol=1e-12 * np.abs(everything).max())
    difference = named - plain
    assert np.linalg.eigvalsh(difference).min() >= -1e-12 and np.abs(difference).max() > 1e-6
    assert np.linalg.eigvalsh(plain).min() < 0.0 <= np.linalg.eigvalsh(named).min() + 1e-12


def test_a_stalled_stage_stops_where_its_energy_drop_falls_off_and_the_next_one_ends_at_the_same_equilibrium():
    """The pendulum block with scaled steps: its energy falls by about the same amount per step while the bob swings
    within the radius, then by less and less. With ``stall_fraction`` the region stops at the first step whose last
    ``stall_window`` drops average below that fraction of all its drops (found here from the full run's drops), on the
    full run's path; relaxed on from there, it ends at the full run's equilibrium."""
    options = TrustRegionOptions(rtol=1e-10, radius=0.05, max_radius=0.1, max_steps=300)
    problem, _, _ = _pendulum_block()
    full = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), options, progress=False)
    drops = -np.asarray(full.energy_changes)
    window, fraction = 5, 0.2
    stop = next(k for k in range(window, drops.size + 1) if drops[k - window:k].mean() < fraction * drops[:k].mean())
    assert window < stop < drops.size  # the test has a stop to find before the run converges
    problem, _, _ = _pendulum_block()
    staged = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs),
                          replace(options, stall_fraction=fraction, stall_window=window), progress=False)
    assert staged.stalled and not staged.converged and len(staged.residuals) == stop
    np.testing.assert_allclose(staged.energy_changes, full.energy_changes[:stop], rtol=1e-8, atol=1e-14)
    rest = trust_region(problem, 1.0, staged.u, options, progress=False)
    assert rest.converged and not rest.stalled
    assert np.abs(rest.u - full.u).max() <= 1e-8 * np.abs(full.u).max()
    for bad in ({"stall_fraction": 1.0}, {"stall_fraction": -0.1}, {"stall_window": 1}):
        with pytest.raises(ValueError, match="stall"):
            TrustRegionOptions(**bad)


def test_shifting_indefinite_blocks_adds_the_smallest_identity_that_makes_each_semidefinite():
    """``shift_psd``: a block with eigenvalues (-2, 1, 3) in a rotated basis gains 2 I (eigenvalues 0, 3, 5), a
    semidefinite one is unchanged; a sparse matrix of two such blocks on disjoint dofs gains each block's own shift.
    On the pendulum block with its cable compressed, shifting the cable's blocks (``shifted``) adds -lambda_min of the
    cable's element block on its six dofs alone, and the step matrix becomes semidefinite."""
    rotation = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))[0]
    indefinite = rotation @ np.diag([-2.0, 1.0, 3.0]) @ rotation.T
    definite = rotation @ np.diag([0.5, 1.0, 3.0]) @ rotation.T
    shifted = shift_psd(np.stack([indefinite, definite]))
    np.testing.assert_allclose(np.linalg.eigvalsh(shifted[0]), [0.0, 3.0, 5.0], atol=1e-12)
    np.testing.assert_allclose(shifted[1], definite, atol=1e-14)
    lower = rotation @ np.diag([-0.5, 2.0, 4.0]) @ rotation.T
    sparse = sp.block_diag([indefinite, lower, np.zeros((2, 2))], format="csr")
    expected = sp.block_diag([indefinite + 2.0 * np.eye(3), lower + 0.5 * np.eye(3), np.zeros((2, 2))]).toarray()
    np.testing.assert_allclose(project_sparse_psd(sparse, shift=True).toarray(), expected, atol=1e-12)
    problem, centre, _ = _pendulum_block()
    u = np.zeros(problem.space.n_dofs)
    u[problem.space.displacement_dofs(np.array([0])).ravel()] = [0.0, 0.0, -0.1]  # cable stretch 0.8
    _, tangent = problem.assemble(u, 1.0, tangent=True)
    truss = next(term for term in problem.terms if isinstance(term, Truss))
    block = next(b.matrices for b in tangent.contributions[problem.terms.index(truss)].blocks if b.matrices.size)[0]
    lowest = np.linalg.eigvalsh(0.5 * (block + block.T))[0]
    assert lowest < 0.0  # the compressed cable's lateral stiffness -N/l
    plain = step_matrix(problem, tangent, False).toarray()
    local = step_matrix(problem, tangent, False, shifted=(truss.name,)).toarray()
    free = problem.pattern.free
    cable = np.isin(free, problem.space.displacement_dofs(np.array([centre, 0])).ravel())
    np.testing.assert_allclose(np.diag(local - plain)[cable], -lowest, rtol=1e-12)
    off = local - plain - np.diag(np.diag(local - plain))
    assert np.abs(off).max() <= 1e-12 * np.abs(plain).max() and np.abs(np.diag(local - plain)[~cable]).max() == 0.0
    assert np.linalg.eigvalsh(plain).min() < 0.0 <= np.linalg.eigvalsh(local).min() + 1e-12


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="the inertia needs PARDISO")
def test_a_run_resumed_from_a_steps_control_repeats_the_uninterrupted_one():
    """The curled flap under its follower pressure (a work term beside the potentials, Newton tries, shifts that
    change from step to step): stopped after 7 accepted steps and resumed from that step's state and
    :class:`TrustRegionControl`, the run takes the same steps to the same state as one that never stopped."""
    options = TrustRegionOptions(rtol=1e-10, radius=0.2, max_radius=2.0, max_steps=150, newton_below=1e-2)
    whole_steps = []
    whole = trust_region(_flap(), 1.0, np.zeros(_flap().space.n_dofs), options, progress=False,
                         callbacks=[whole_steps.append])
    assert whole.converged and len(whole.residuals) > 10
    first_steps = []
    with pytest.raises(ConvergenceError, match="7 steps without converging"):
        trust_region(_flap(), 1.0, np.zeros(whole.u.size), replace(options, max_steps=7), progress=False,
                     callbacks=[first_steps.append])
    kept = first_steps[-1]
    assert kept.control.steps == 7 and kept.control.attempts >= 7
    rest = []
    resumed = trust_region(_flap(), 1.0, kept.u, options, progress=False, control=kept.control,
                           callbacks=[rest.append])
    assert [event.step for event in rest] == list(range(8, len(whole.residuals) + 1))
    assert np.abs(resumed.u - whole.u).max() <= 1e-10 * np.abs(whole.u).max()
    # the same steps to rounding (a linear solver reuses its analysis in one run, not across two)
    assert [event.residual_norm for event in rest] == pytest.approx(whole.residuals[7:], rel=1e-6)
    with pytest.raises(ValueError, match="local shifts"):
        trust_region(_flap(), 1.0, kept.u, options, progress=False,
                     control=replace(kept.control, local=np.zeros(3)))


class _RefuseFirst(Term):
    """A term with no forces that refuses the first ``count`` states it is shown (:class:`StateRefused`)."""

    name = "refuse first"

    def __init__(self, space, count: int) -> None:
        self.space, self.left, self.shown = space, count, 0

    def assemble(self, u, t, tangent=True, step=None):
        return Contribution()

    def energy(self, u, t):
        return 0.0

    def check_state(self, u, t):
        self.shown += 1
        if self.left > 0:
            self.left -= 1
            raise StateRefused("refused by the test")


def test_a_refused_trial_is_a_rejected_step_not_a_failure():
    """A term that refuses a trial state (as the IPC contact refuses a self-intersection among primitives it excludes)
    makes the trust region reject that step and shorten the radius; the run still ends at Newton's state."""
    newton = solve(sheared_block(), 10, progress=False, rtol=1e-11).u()
    block = sheared_block()
    guard = block.add_term(_RefuseFirst(block.space, 2))
    plain = trust_region(sheared_block(), 1.0, np.zeros(newton.size), TrustRegionOptions(rtol=1e-11, radius=0.1),
                         progress=False)
    result = trust_region(block, 1.0, np.zeros(newton.size), TrustRegionOptions(rtol=1e-11, radius=0.1),
                          progress=False)
    assert result.converged and guard.left == 0 and guard.shown > 2
    assert result.rejected == plain.rejected + 2
    assert np.abs(result.u - newton).max() <= 1e-9 * np.abs(newton).max()


def test_each_steps_energy_change_is_the_drop_of_the_total_potential():
    """Where every term has a potential (the sheared block), a resolved step's energy change is the potential's own
    difference between the accepted states (evaluated here by :meth:`Problem.energy`, not by the solver's
    quadrature), and the potential falls at every step."""
    block = sheared_block()
    states = []
    result = trust_region(block, 1.0, np.zeros(block.space.n_dofs), TrustRegionOptions(rtol=1e-11, radius=0.1),
                          progress=False, callbacks=[lambda event: states.append(event.u.copy())])
    start = np.zeros(block.space.n_dofs)
    start[block.pattern.fixed] = block.constrained(1.0)[1]
    energies = [block.energy(state, 1.0) for state in [start, *states]]
    drops = np.diff(energies)
    resolved = np.abs(drops) > 1e-8 * abs(energies[-1])
    assert resolved.sum() >= 5 and np.all(drops[resolved] < 0.0)
    # the last steps' changes are lost in the energy's rounding (the residual's fall accepts them): none rises past it
    assert np.all(drops <= 1e-12 * abs(energies[-1]))
    np.testing.assert_allclose(np.array(result.energy_changes)[resolved], drops[resolved], rtol=1e-9)


@pytest.mark.skipif("pardiso" not in available_solvers(), reason="the inertia needs PARDISO")
def test_newton_tries_are_not_held_to_a_shrunken_radius():
    """Near the curled flap's equilibrium, with a radius of 1e-7 (as energy steps that keep being rejected leave it),
    Newton's tries may still go as far as ``max_radius``: they are kept by the residual's fall, so the run converges
    in a few tries, quadratically, instead of crawling 1e-7 at a time."""
    newton = solve(_flap(), 10, progress=False, rtol=1e-10).u()
    rng = np.random.default_rng(7)
    flap = _flap()
    start = newton + 1e-6 * np.abs(newton).max() * rng.standard_normal(newton.size)
    start[flap.pattern.fixed] = newton[flap.pattern.fixed]
    options = TrustRegionOptions(rtol=1e-10, radius=1e-7, min_radius=1e-9, max_radius=2.0, newton_below=10.0,
                                 max_steps=8)
    result = trust_region(flap, 1.0, start, options, progress=False)
    assert result.converged and result.newton_steps == len(result.residuals) <= 6
    assert max(result.largest_increments) > 50 * options.radius  # held to the radius it could not move so far
    np.testing.assert_allclose(result.u, newton, atol=1e-8 * np.abs(newton).max())
