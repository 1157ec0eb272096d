"""The hex corner barrier: derivatives by finite differences, the energy in closed form, the fold-free step, and a
single F-bar hex that folds at a corner without it and does not with it."""

import numpy as np
import pytest
import skfem

from skvalve.fem.elements.constitutive import MaterialRegions
from skvalve.fem.elements.corner_barrier import CornerBarrier, _first_root, corner_barrier_phi, hex_corner_stencils
from skvalve.fem.elements.fbar import FBarTerm
from skvalve.fem.errors import NonPositiveJacobianError, TangledMeshError
from skvalve.fem.loads import NodalForce
from skvalve.fem.problem import Problem
from skvalve.fem.solvers.trust_region import TrustRegionOptions, trust_region
from skvalve.fem.space import Space
from skvalve.materials import NeoHookean


def _unit(n: int) -> np.ndarray:
    return np.eye(1, n, 0)[0]


def test_stencils_are_the_neighbours_along_the_three_axes():
    locs = np.asarray(skfem.ElementHex1().doflocs)
    for c, *neighbours in hex_corner_stencils():
        for axis, a in enumerate(neighbours):
            differs = np.flatnonzero(locs[c] != locs[a])
            assert differs.tolist() == [axis]


def test_reference_state_is_untouched():
    space = Space(skfem.MeshHex().refined(1))
    barrier = CornerBarrier(space, 2.0, threshold=0.9)
    u = np.zeros(space.n_dofs)
    assert np.allclose(barrier.ratios(u), 1.0)
    assert barrier.energy(u, 0.0) == 0.0
    contribution = barrier.assemble(u, 0.0, True, None)
    assert not np.any(contribution.internal) and contribution.matrix.nnz == 0


def test_forces_and_tangent_against_finite_differences():
    space = Space(skfem.MeshHex().refined(1))
    barrier = CornerBarrier(space, 2.0, threshold=0.9)
    u = 0.06 * np.random.default_rng(0).standard_normal(space.n_dofs)
    ratios = barrier.ratios(u)
    assert 20 < np.sum(ratios < 0.9) < ratios.size and ratios.min() > 0.0  # many active corners, none folded
    contribution = barrier.assemble(u, 0.0, True, None)
    h, n = 1e-6, space.n_dofs
    shifts = [h * np.roll(_unit(n), i) for i in range(n)]
    gradient = np.array([(barrier.energy(u + d, 0.0) - barrier.energy(u - d, 0.0)) / (2 * h) for d in shifts])
    assert np.abs(gradient - contribution.internal).max() <= 1e-8 * np.abs(contribution.internal).max()
    hessian = np.column_stack([(barrier.assemble(u + d, 0.0, False, None).internal
                                - barrier.assemble(u - d, 0.0, False, None).internal) / (2 * h) for d in shifts])
    K = contribution.matrix.toarray()
    assert np.abs(hessian - K).max() <= 1e-8 * np.abs(K).max()
    assert np.allclose(K, K.T, rtol=0.0, atol=1e-14 * np.abs(K).max())
    assert np.linalg.eigvalsh(contribution.projected_matrix.toarray()).min() > -1e-12 * np.abs(K).max()


def test_uniform_compression_energy_in_closed_form():
    """A unit cube squashed to 5 % of its height: every corner's ratio is 0.05, so the energy is mu V phi(0.5)."""
    mesh = skfem.MeshHex()
    space = Space(mesh)
    barrier = CornerBarrier(space, 3.0, threshold=0.1)
    u = np.zeros(space.n_dofs)
    u.reshape(-1, 3)[:, 2] = -0.95 * mesh.p[2]
    phi = -(1 - 0.5) ** 2 * np.log(0.5)
    assert barrier.energy(u, 0.0) == pytest.approx(3.0 * phi, rel=1e-12)
    assert corner_barrier_phi(np.array([0.5]))[0][0] == pytest.approx(phi, rel=1e-15)


def test_step_fraction_stops_before_the_corner_flattens():
    mesh = skfem.MeshHex()
    space = Space(mesh)
    barrier = CornerBarrier(space, 1.0)
    move = np.zeros(space.n_dofs)
    move.reshape(-1, 3)[:, 2] = -2.0 * mesh.p[2]  # the top face through the bottom: flat at half the move
    assert barrier.step_fraction(np.zeros(space.n_dofs), 0.0, move, 0.0) == pytest.approx(0.9 * 0.5, rel=1e-12)
    assert barrier.step_fraction(np.zeros(space.n_dofs), 0.0, 0.3 * move, 0.0) == 1.0


def test_crossed_moves_the_folding_hexes_rigidly_and_that_move_is_admissible():
    """Two hexes side by side; the move pushes the first one's outer top edge through its bottom. ``crossed`` names that
    hex's 8 nodes with its mean increment (a translation: every corner ratio unchanged, so the barrier allows the whole
    move), the second hex's own nodes not at all; a move that folds nothing gives None."""
    mesh = skfem.MeshHex.init_tensor(np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0]), np.array([0.0, 1.0]))
    space = Space(mesh)
    barrier = CornerBarrier(space, 1.0)
    u0 = np.zeros(space.n_dofs)
    first = mesh.t[:, 0]
    edge = first[(mesh.p[2, first] > 0.5) & (mesh.p[0, first] < 0.5)]  # not shared with the second hex
    move = np.zeros(space.n_dofs)
    move.reshape(-1, 3)[edge, 2] = -2.0  # 1 below the bottom
    move.reshape(-1, 3)[:, 0] += 0.25  # and everything slid along x
    assert barrier.step_fraction(u0, 0.0, move, 0.0) < 1.0
    dofs, increments = barrier.crossed(u0, 0.0, move, 0.0)
    nodes = np.unique(dofs // 3)
    assert sorted(nodes.tolist()) == sorted(first.tolist())
    mean = move.reshape(-1, 3)[first].mean(axis=0)
    assert np.allclose(increments.reshape(-1, 3), mean, rtol=0.0, atol=1e-15)
    assert np.allclose(mean, [0.25, 0.0, -0.5])
    rigid = move.copy()
    rigid[dofs] = increments
    assert np.allclose(barrier.ratios(rigid)[:8], 1.0, rtol=0.0, atol=1e-14)
    assert barrier.crossed(u0, 0.0, 0.3 * move, 0.0) is None


def test_first_root_of_a_cubic_that_dips_below_zero_and_comes_back():
    """J(a) = k (a - 0.3)(a - 0.6)(a - 2) is positive at 0 and at 1 but not between 0.3 and 0.6."""
    k = -1.0 / 0.36
    c = np.array([[k * -0.36], [k * (0.18 + 0.6 + 1.2)], [k * -2.9], [k]])
    assert _first_root(*c)[0] == pytest.approx(0.3, abs=1e-14)
    assert _first_root(np.array([1.0]), np.array([0.5]), np.array([0.0]), np.array([0.0]))[0] == 2.0  # no root


def test_folded_states_and_tangled_references_are_named():
    mesh = skfem.MeshHex()
    space = Space(mesh)
    barrier = CornerBarrier(space, 1.0)
    u = np.zeros(space.n_dofs)
    u.reshape(-1, 3)[:, 2] = -1.5 * mesh.p[2]
    with pytest.raises(NonPositiveJacobianError, match="corner barrier"):
        barrier.energy(u, 0.0)
    tangled = skfem.MeshHex(mesh.p.copy(), mesh.t[[1, 0, 2, 3, 4, 5, 6, 7]])
    with pytest.raises(TangledMeshError):
        CornerBarrier(_space_without_check(tangled), 1.0)
    with pytest.raises(ValueError, match="threshold"):
        CornerBarrier(space, 1.0, threshold=1.5)


def _space_without_check(mesh):
    """A space on a tangled mesh (the space's own reference check would refuse it first)."""
    space = Space(skfem.MeshHex())
    space.mesh = mesh
    return space


def _pushed_corner(force: float, guarded: bool) -> float:
    """The smallest corner ratio of a thin F-bar hex (1 x 1 x 0.25, bottom clamped) whose top corner is pushed in."""
    mesh = skfem.MeshHex().scaled([1.0, 1.0, 0.25])
    space = Space(mesh)
    problem = Problem(space, [FBarTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 100.0)))])
    problem.add_dirichlet(lambda X: X[2] == 0.0, 0.0)
    node = int(np.flatnonzero(np.all(np.isclose(mesh.p.T, [1.0, 1.0, 0.25]), axis=1))[0])
    problem.add_term(NodalForce(space, np.array([node]), np.full(3, -force), False))
    if guarded:
        problem.add_term(CornerBarrier(space, 1.0, threshold=0.1))
    result = trust_region(problem, 1.0, np.zeros(space.n_dofs), TrustRegionOptions(rtol=1e-10, max_steps=300),
                          progress=False)
    assert result.converged
    return float(CornerBarrier(space, 1.0).ratios(result.u).min())


def test_a_pushed_corner_folds_without_the_barrier_and_not_with_it():
    """The F-bar hex's Gauss points stay positive while its corner folds (ratio -0.28 under the larger push); the
    barrier holds the corner above zero there and changes nothing under the smaller push (every ratio above the
    threshold)."""
    assert _pushed_corner(0.2, guarded=False) < -0.2
    assert 0.0 < _pushed_corner(0.2, guarded=True) < 0.1
    small = _pushed_corner(0.05, guarded=False)
    assert small > 0.1 and _pushed_corner(0.05, guarded=True) == pytest.approx(small, rel=1e-9)
