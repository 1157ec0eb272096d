"""Descent directions and line search of the incremental-potential steps (:mod:`skvalve.fem.solvers.incremental`).

The shifted Newton direction: Newton's step where the tangent is positive definite, the smallest Marquardt shift of
the sequence where it is not (checked against the eigenvalues), a quadratic rate near a stable minimum where the
per-element projection is linear; the Wolfe curvature refinement: a step far past the minimum along its direction is
moved onto the minimum of a quadratic (closed form); both directions reach the same equilibrium with IPC contact.
"""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from test_ipc_contact import _block_over_obstacle  # the pressed block of the IPC tests

from skvalve.fem import Solid, solve
from skvalve.fem.errors import ConvergenceError
from skvalve.fem.meshes import box
from skvalve.fem.solvers import linsolve
from skvalve.fem.solvers.incremental import (
    FIRST_SHIFT,
    SHIFT_GROWTH,
    IncrementalOptions,
    StepFailed,
    _past_the_minimum,
    incremental_potential,
    minimise_step,
    shifted_newton,
)
from skvalve.materials import NeoHookean

pytestmark = pytest.mark.skipif("pardiso" not in linsolve.available_solvers(), reason="needs PARDISO's inertia")


def _laplacian(n: int, shift: float) -> sp.csr_matrix:
    return sp.diags([-np.ones(n - 1), np.full(n, 2.0 + shift), -np.ones(n - 1)], [-1, 0, 1], format="csr")


def test_shifted_newton_is_newton_on_a_definite_matrix():
    H = _laplacian(30, 0.1)
    rhs = np.random.default_rng(0).standard_normal(30)
    direction, shift, _ = shifted_newton(H, rhs, 0.0, "pardiso")
    assert shift == 0.0
    np.testing.assert_allclose(direction, np.linalg.solve(H.toarray(), rhs), rtol=1e-10)


def test_shifted_newton_takes_the_smallest_definite_shift_of_its_sequence():
    """lambda_min(H) = -0.3 at a diagonal of ~2: the shift is the first mu of 1e-6 x 10^k with H + mu diag(H) > 0."""
    H = _laplacian(30, -0.3)
    rhs = np.random.default_rng(1).standard_normal(30)
    direction, shift, _ = shifted_newton(H, rhs, 0.0, "pardiso")
    D = np.abs(H.diagonal())
    lowest = lambda mu: np.linalg.eigvalsh(H.toarray() + mu * np.diag(D))[0]
    assert lowest(shift) > 0.0 and lowest(shift / SHIFT_GROWTH) <= 0.0
    assert np.log10(shift / FIRST_SHIFT) == pytest.approx(round(np.log10(shift / FIRST_SHIFT)))
    assert rhs @ direction > 0.0  # a descent direction for the gradient -rhs
    # warm start: from a larger last shift the sequence starts a hundredth below it and ends at a definite one
    _, again, _ = shifted_newton(H, rhs, 1e3 * shift, "pardiso")
    assert again == pytest.approx(10 * shift) and lowest(again) > 0.0


def test_a_negative_pivot_is_lifted_by_its_own_diagonal():
    """diag(1, -1, 2): definite once mu |diag| lifts the -1 past 0, so mu = 10 (mu = 1 makes it singular)."""
    H = sp.csr_matrix(np.diag([1.0, -1.0, 2.0]))
    direction, shift, _ = shifted_newton(H, np.ones(3), 0.0, "pardiso")
    assert shift == pytest.approx(10.0)
    np.testing.assert_allclose(direction, [1.0 / 11.0, 1.0 / 9.0, 1.0 / 22.0], rtol=1e-12)


def test_an_indefinite_tangent_falls_back_to_its_projection_unshifted():
    """With a ``fallback`` (the element-projected matrix): Newton's step where H is definite; where it is not, the
    fallback's own step with no shift when the fallback is definite, and its smallest definite shift otherwise."""
    rhs = np.random.default_rng(2).standard_normal(30)
    definite, indefinite = _laplacian(30, 0.1), _laplacian(30, -0.3)
    projection = _laplacian(30, 0.5)
    calls = []

    def fallback():
        calls.append(1)
        return projection

    direction, shift, projected = shifted_newton(definite, rhs, 0.0, "pardiso", fallback=fallback)
    assert (shift, projected, calls) == (0.0, False, [])
    np.testing.assert_allclose(direction, np.linalg.solve(definite.toarray(), rhs), rtol=1e-10)
    direction, shift, projected = shifted_newton(indefinite, rhs, 0.0, "pardiso", fallback=fallback)
    assert (shift, projected, len(calls)) == (0.0, True, 1)
    np.testing.assert_allclose(direction, np.linalg.solve(projection.toarray(), rhs), rtol=1e-10)
    # an indefinite fallback takes its own smallest definite shift, as the plain sequence does on it
    _, alone, _ = shifted_newton(indefinite, rhs, 0.0, "pardiso")
    _, shift, projected = shifted_newton(_laplacian(30, -0.5), rhs, 0.0, "pardiso", fallback=lambda: indefinite)
    assert projected and shift == pytest.approx(alone)


class _Quadratic:
    """E(u) = k/2 |u - u*|^2 on free dofs: a stand-in problem for the line search."""

    def __init__(self, k: float, target: np.ndarray) -> None:
        self.k, self.target = k, target
        self.pattern = SimpleNamespace(free=np.arange(target.size))

    def assemble(self, u, t, tangent=True, step=None):
        return self.k * (u - self.target), SimpleNamespace(contributions=[])

    def energy(self, u):
        return 0.5 * self.k * float((u - self.target) @ (u - self.target))


def test_a_step_far_past_the_minimum_is_moved_onto_it():
    """Along p = 1.95 (u* - u) the full step decreases E (Armijo holds) but ends with a slope of 0.95 |slope(0)|:
    the curvature condition moves it to the secant's zero, the exact minimiser of a quadratic (alpha = 1/1.95)."""
    target = np.array([1.0, -2.0, 0.5])
    problem = _Quadratic(3.0, target)
    u = np.zeros(3)
    p = 1.95 * (target - u)
    gradient = problem.assemble(u, 0.0)[0]
    slope, value = float(gradient @ p), problem.energy(u)
    full = u + p
    accepted = (full, problem.assemble(full, 0.0)[0], None, problem.assemble(full, 0.0)[0], problem.energy(full))
    assert accepted[4] <= value + 1e-4 * slope  # Armijo accepts the overshoot
    merit = lambda alpha, state, contributions: problem.energy(state)
    alpha, refined = _past_the_minimum(problem, lambda a: u + a * p, p, 1.0, slope, value, accepted, 0.0, 1,
                                       np.zeros(3), u, merit, IncrementalOptions())
    assert alpha == pytest.approx(1.0 / 1.95, rel=1e-12)
    np.testing.assert_allclose(refined[0], target, atol=1e-12)
    # a step that stops short of the minimum is left as it is
    short = u + 0.5 * (target - u)
    kept = (short, problem.assemble(short, 0.0)[0], None, problem.assemble(short, 0.0)[0], problem.energy(short))
    towards = target - u
    assert _past_the_minimum(problem, lambda a: u + a * towards, towards, 0.5, float(gradient @ towards), value, kept,
                             0.0, 1, np.zeros(3), u, merit, IncrementalOptions())[0] == 0.5


def _pressed_block(direction: str):
    solid, contact, _ = _block_over_obstacle(drop=0.1, gap=0.05, dhat=0.02, rollers=True)
    result = incremental_potential(solid, steps=2, options=IncrementalOptions(rtol=1e-10, atol=1e-12,
                                                                              direction=direction), progress=False)
    return result, contact


def test_both_directions_reach_the_same_contact_equilibrium_and_shifted_newton_ends_quadratically():
    """The block pressed onto an obstacle on rollers (one equilibrium, as the IPC tests show against Newton)."""
    projected, _ = _pressed_block("projected")
    shifted, contact = _pressed_block("shifted")
    u = shifted.solutions[-1]
    assert np.abs(u - projected.solutions[-1]).max() <= 1e-7 * np.abs(u).max()
    assert not contact.intersects(u, 1.0)
    last = [record["relative_residual"] for record in shifted.histories[-1]]
    # the residual falls at a rate of order 2 once it is small: log r_{k+1} / log r_k > 1.6
    rates = [np.log(c) / np.log(b) for b, c in zip(last[:-1], last[1:], strict=True) if b < 1e-2]
    assert rates and max(rates) > 1.6, last
    assert shifted.histories[-1][-1]["shift"] == 0.0
    assert sum(map(len, shifted.histories)) <= sum(map(len, projected.histories))


def test_unknown_direction_is_named():
    with pytest.raises(ValueError, match="direction"):
        IncrementalOptions(direction="steepest")
    with pytest.raises(ValueError, match="reference"):
        IncrementalOptions(reference=0.0)


def test_a_fixed_reference_force_sets_the_tolerance():
    """``reference`` replaces Newton's scale (the reactions' norm) in the convergence test: a block stretched by a
    prescribed end motion, converged to rtol x reference, leaves a residual below it, and a reference 1e4 times larger
    stops after fewer iterations."""
    def stretched(reference):
        solid = Solid(box((2, 2, 2)), NeoHookean.from_shear_poisson(1.0, 0.3))
        solid.add_dirichlet("left", 0.0)
        solid.add_dirichlet("right", [0.2, 0.0, 0.0])
        options = IncrementalOptions(rtol=1e-6, reference=reference)
        return solid, incremental_potential(solid, steps=1, options=options, progress=False)

    solid, tight = stretched(1e-3)
    _, loose = stretched(10.0)
    assert np.linalg.norm(tight.residuals[-1][solid.pattern.free]) <= 1e-6 * 1e-3
    assert len(loose.histories[-1]) < len(tight.histories[-1])


def _bent_strip(solver):
    """A strip clamped at x = 0 and bent by a follower pressure on its underside: the pressure turns with the
    strip, a load without a potential (its tangent is not symmetric)."""
    solid = Solid(box((6, 1, 1), (1.0, 0.2, 0.05)), NeoHookean(1.0, 20.0))
    solid.add_dirichlet(lambda X: X[0] < 1e-9, 0.0)
    solid.add_pressure(lambda x: x[2] < 1e-9, 2e-3)
    return solver(solid)


def test_a_follower_pressure_step_is_minimised_along_each_ray_to_newtons_equilibrium():
    """With a term that has no potential the line search follows phi(alpha) = potential + the term's work along the
    ray (trapezoidal): it reaches the equilibrium Newton's method finds, and its last iterations take full Newton
    steps (quadratic rate)."""
    newton = _bent_strip(lambda s: solve(s, steps=4, rtol=1e-11, progress=False))
    minimised = _bent_strip(lambda s: incremental_potential(s, steps=4, options=IncrementalOptions(rtol=1e-11),
                                                            progress=False))
    u = minimised.solutions[-1]
    assert np.abs(u).max() > 0.05  # a large deflection: the pressure has turned
    assert np.abs(u - newton.solutions[-1]).max() <= 1e-8 * np.abs(u).max()
    records = [record for step in minimised.histories for record in step]
    assert not any(record["energy_merit"] for record in records)
    assert records[-1]["newton"] and records[-1]["alpha"] == 1.0


def test_line_search_trials_are_assembled_without_their_tangent_and_the_accepted_state_last():
    """A trial's tangent is assembled only once it is accepted (a rejected trial costs a residual), and the state a
    term saw last before each commit is the accepted one (the barrier's commit takes the state it saw last)."""
    solid, contact, _ = _block_over_obstacle(drop=0.1, gap=0.05, dhat=0.02, rollers=True)
    calls, commits = [], []
    assemble, commit = contact.assemble, contact.commit

    def counted_assemble(u, t, tangent, step):
        calls.append((np.array(u, copy=True), tangent))
        return assemble(u, t, tangent, step)

    def checked_commit():
        commits.append(calls[-1][0])
        commit()

    contact.assemble, contact.commit = counted_assemble, checked_commit
    result = incremental_potential(solid, steps=2, options=IncrementalOptions(rtol=1e-10, atol=1e-12),
                                   progress=False)
    iterations = sum(map(len, result.histories))
    with_tangent = sum(tangent for _, tangent in calls)
    # per step: the predictor's tangent at the old state and the first iterate's; then one per accepted iteration
    assert with_tangent == 2 * (len(result.histories) - 1) + iterations
    assert len(calls) - with_tangent > len(result.histories)  # rejected trials and residual-only evaluations happened
    for state, solution in zip(commits[1:], result.solutions[1:], strict=True):
        np.testing.assert_array_equal(state, solution)


def test_the_iteration_limit_tests_the_last_iterate_and_spares_a_contracting_iteration():
    """A block stretched in one load step takes ``n`` Newton iterations. With ``max_iter = n`` the step converges
    (the iterate after the last allowed iteration is tested); with ``max_iter = n - 2`` too, since its last
    iterations each more than halve |grad E| (``CONTRACTING``); with ``max_iter = 1`` it fails after at most two
    iterations (the hard cap: twice ``max_iter``)."""
    def stretched(max_iter):
        solid = Solid(box((2, 2, 2)), NeoHookean.from_shear_poisson(1.0, 0.3))
        solid.add_dirichlet("left", 0.0)
        solid.add_dirichlet("right", [0.8, 0.0, 0.0])
        options = IncrementalOptions(rtol=1e-10, max_iter=max_iter, max_cutbacks=0, predictor=False)
        return incremental_potential(solid, steps=1, options=options, progress=False)

    free = stretched(60)
    residuals = [record["residual"] for record in free.histories[-1]]
    n = len(residuals)
    assert n >= 5 and residuals[-1] <= 0.5 * residuals[-2] and residuals[-2] <= 0.5 * residuals[-3], residuals
    for max_iter in (n, n - 2):
        capped = stretched(max_iter)
        assert len(capped.histories[-1]) == n
        np.testing.assert_array_equal(capped.solutions[-1], free.solutions[-1])
    with pytest.raises(ConvergenceError, match="2 iterations"):
        stretched(1)


def test_a_step_out_of_iterations_carries_its_last_iterate_where_the_terms_were_last_assembled():
    """The block pressed onto an obstacle, its step held to one iteration (two while contracting) against a tolerance
    it cannot reach, fails and carries its last iterate: the static residual there is the problem's own, its history
    has the iterations taken, and the barrier term saw that state last with a tangent, so that committing takes it."""
    solid, contact, _ = _block_over_obstacle(drop=0.1, gap=0.05, dhat=0.02, rollers=True)
    seen = []
    assemble = contact.assemble

    def recorded(u, t, tangent, step):
        if tangent:
            seen.append(np.array(u, copy=True))
        return assemble(u, t, tangent, step)

    contact.assemble = recorded
    u_old = np.zeros(solid.space.n_dofs)
    options = IncrementalOptions(rtol=1e-14, max_iter=1, predictor=False)
    with pytest.raises(StepFailed, match="no convergence") as failed:
        minimise_step(solid, u_old, 0.0, 1.0, u_old, np.zeros_like(u_old), 1, options, "pardiso")
    u, residual, history = failed.value.last
    assert 1 <= len(history) <= 2 and np.abs(u).max() > 0.0
    np.testing.assert_array_equal(seen[-1], u)
    np.testing.assert_allclose(residual, solid.assemble(u, 1.0, tangent=False)[0], rtol=0.0,
                               atol=1e-12 * np.abs(residual).max())
