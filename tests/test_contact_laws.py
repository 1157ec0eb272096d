"""Contact pressure laws (skvalve.fem.contact.laws): energy, pressure and stiffness consistent by central differences,
the barrier's closed form, C^2 onset and unbounded growth, and two blocks pressed together hard: the penalty alone
lets them overlap past the clearance floor; with the barrier they stop short of it at the closed-form overlap."""

from functools import partial

import numpy as np
import pytest
from scipy.optimize import brentq
from test_contact import LAW, SMOOTHING, block_contact_problem, overlap
from test_contact_clearance import DEPTH, GAP, PUSH
from test_contact_clearance import _blocks as clearance_blocks
from test_contact_clearance import _overlap as clearance_overlap

from skvalve.analytic.homogeneous import uniaxial
from skvalve.fem import solve
from skvalve.fem.contact.blend import BARRIER_FLOOR
from skvalve.fem.contact.clearance import ALLOWED_DEPTH, clearance_fraction
from skvalve.fem.contact.laws import BARRIER_CUTOFF, depth_barrier, rounded_penalty
from skvalve.fem.errors import ConvergenceError
from skvalve.fem.solvers.trust_region import TrustRegionOptions, trust_region

PENALTY, START, FLOOR, SATURATE = 3.0, 0.1, 0.4, 0.45
CUTOFF = FLOOR - BARRIER_CUTOFF * (FLOOR - START)


def barrier(h):
    return depth_barrier(h, PENALTY, START, FLOOR, SATURATE)


def log_barrier_pressure(h: float, penalty: float = PENALTY, start: float = START, floor: float = FLOOR) -> float:
    """Written out here from the energy -eps (r - w)^2 ln(r / w), r = floor - h, w = floor - start: p = d psi / dh
    (the log branch, before the cutoff)."""
    r, w = floor - h, floor - start
    if r >= w:
        return 0.0
    return penalty * (2.0 * (r - w) * np.log(r / w) + (r - w) ** 2 / r)


def test_energy_pressure_and_stiffness_of_both_laws_are_consistent():
    h = np.concatenate([np.linspace(0.0, FLOOR - 1e-3, 4001), FLOOR - np.geomspace(9e-4, 1e-6, 200),
                        np.linspace(FLOOR, SATURATE + 0.1, 400)])
    delta = 1e-7
    h = h[np.abs(h - CUTOFF) > 10 * delta]  # the barrier's stiffness jumps at its cutoff (pressure continuous)
    for law in (lambda x: rounded_penalty(x, PENALTY, SMOOTHING), barrier):
        energy, pressure, stiffness = law(h)
        assert np.all(np.isfinite(energy)) and np.all(np.isfinite(stiffness))
        plus, minus = law(h + delta), law(h - delta)
        np.testing.assert_allclose((plus[0] - minus[0]) / (2 * delta), pressure, rtol=1e-6, atol=1e-8)
        np.testing.assert_allclose((plus[1] - minus[1]) / (2 * delta), stiffness, rtol=1e-5,
                                   atol=1e-6 * np.abs(stiffness).max())
        assert np.all(pressure >= 0.0) and np.all(np.diff(energy) >= -1e-12)  # energy never falls with depth
    energy, pressure, _ = barrier(h)
    rising = h < CUTOFF
    assert np.all(np.diff(pressure[rising]) >= 0.0) and np.all(np.diff(pressure[~rising]) <= 1e-12)
    assert np.all(pressure[h >= SATURATE] == 0.0)
    np.testing.assert_allclose(energy[h >= SATURATE], energy[-1], rtol=1e-12)  # bounded: constant past saturate
    below, above = barrier(np.array([CUTOFF - 1e-12, CUTOFF + 1e-12]))[1]
    assert above == pytest.approx(below, rel=1e-9)  # pressure continuous at the cutoff


def test_the_barrier_starts_smoothly_and_grows_without_bound_towards_the_floor():
    energy, pressure, stiffness = barrier(np.array([0.0, START, START + 1e-4]))
    np.testing.assert_array_equal(energy[:2], 0.0)
    np.testing.assert_array_equal(pressure[:2], 0.0)
    # C^2 at the start: value, slope and curvature vanish there; with s = h - start, psi ~ eps s^3 / w
    width = FLOOR - START
    s = 1e-4
    assert energy[2] == pytest.approx(PENALTY * s**3 / width, rel=1e-3)
    assert pressure[2] == pytest.approx(3 * PENALTY * s**2 / width, rel=1e-3)
    assert stiffness[2] == pytest.approx(6 * PENALTY * s / width, rel=1e-3)
    for r in (0.5 * width, 0.1 * width, 0.02 * width):
        assert barrier(np.array([FLOOR - r]))[1][0] == pytest.approx(log_barrier_pressure(FLOOR - r), rel=1e-12)
    assert barrier(np.array([CUTOFF]))[1][0] > 0.9 * PENALTY * width / BARRIER_CUTOFF  # ~ eps w^2 / r
    with pytest.raises(ValueError, match="start < floor"):
        depth_barrier(np.zeros(1), PENALTY, FLOOR, START, SATURATE)
    with pytest.raises(ValueError, match="floor < saturate"):
        depth_barrier(np.zeros(1), PENALTY, START, FLOOR, FLOOR)


def _nominal(lam: float) -> float:
    return abs(float(uniaxial(LAW, lam, incompressible=False).nominal[0]))


def closed_form_overlap(shortening: float, penalty: float, start: float, depth: float) -> tuple[float, float]:
    """Overlap h and nominal pressure of two unit blocks in series pressed by ``shortening`` past touching, with the
    rounded penalty and the barrier from ``start`` x ``depth`` to the floor: d = 2(1 - lam) + h, |P(lam)| = 2 p(h)
    (two passes), the laws written out here."""
    floor = BARRIER_FLOOR * depth

    def law_pressure(h):
        rounded = penalty * h**2 / (2 * SMOOTHING) if h < SMOOTHING else penalty * (h - 0.5 * SMOOTHING)
        return rounded + log_barrier_pressure(h, penalty, start * depth, floor)

    def overlap_of(P):
        return brentq(lambda h: 2.0 * law_pressure(h) - P, 0.0, floor * (1 - 1e-12), xtol=1e-14)

    lam = brentq(lambda lam: 2 * (1 - lam) + overlap_of(_nominal(lam)) - shortening, 0.5, 1.0, xtol=1e-14)
    return overlap_of(_nominal(lam)), _nominal(lam)


def test_blocks_pressed_hard_stop_short_of_the_floor_at_the_closed_form_overlap():
    """Unit blocks (2x2 faces, search depth 0.5 = the mean edge) shortened by 0.6 with a penalty of 0.3:
    the penalty alone needs an overlap past the barrier's floor (0.38); with the barrier from 0.1 of the depth
    load-stepped Newton ends at the closed-form overlap, below it."""
    penalty, shortening, start, depth = 0.3, 0.6, 0.1, 0.5
    floor = BARRIER_FLOOR * depth
    lam_alone = brentq(lambda lam: 2 * (1 - lam) + overlap(_nominal(lam), penalty) - shortening, 0.5, 1.0)
    assert overlap(_nominal(lam_alone), penalty) > floor  # the penalty alone would pass the floor
    expected, pressure = closed_form_overlap(shortening, penalty, start, depth)
    assert 0.5 * floor < expected < floor - BARRIER_CUTOFF * (floor - start * depth)  # before the cutoff

    problem, contact = block_contact_problem(2, 2, penalty, barrier=start)
    assert contact.max_penetration == pytest.approx(depth)
    problem.add_dirichlet(lambda X: X[2] == 2.0, -shortening, components=[2])
    result = solve(problem, steps=12, progress=False, rtol=1e-10, solver="scipy")
    u = result.u()
    z = problem.space.dof_coordinates[2] + u[2::3]
    assert z[:27].max() - z[27:].min() == pytest.approx(expected, rel=1e-6)
    assert -result.reaction(lambda X: X[2] == 2.0)[2] == pytest.approx(pressure, rel=1e-6)


def test_the_barrier_lets_the_trust_region_pass_a_node_held_at_its_floor():
    """The clearance-limit blocks (GAP 0.2 apart, pushed 0.45, search depth 0.1) with a soft penalty of 0.5: the
    penalty alone would need 0.15 of overlap, so the limited trust region drives the faces to its floor (0.075) and
    stalls there, its steps cut to nothing (the 1.0 valve's failure); with the barrier from a quarter of the depth it
    converges to the closed-form overlap, short of the floor."""
    penalty, start = 0.5, 0.25
    options = TrustRegionOptions(rtol=1e-10, radius=1.0, max_radius=2.0, solver="scipy", max_steps=300)
    problem, contact = clearance_blocks(penalty=penalty)
    with pytest.raises(ConvergenceError, match="trust region shrank"):
        trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), options, progress=False,
                     limit=partial(clearance_fraction, contact))
    problem, contact = clearance_blocks(penalty=penalty, barrier=start)
    result = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), options, progress=False,
                          limit=partial(clearance_fraction, contact))
    expected, _ = closed_form_overlap(PUSH - GAP, penalty, start, DEPTH)
    assert expected < ALLOWED_DEPTH * DEPTH
    assert result.converged
    assert clearance_overlap(problem, result.u) == pytest.approx(expected, rel=1e-6)


def test_a_barrier_outside_its_range_is_refused():
    with pytest.raises(ValueError, match="barrier must lie in"):
        block_contact_problem(2, 2, 1.0, barrier=BARRIER_FLOOR)
