"""Continuation aids of the Newton driver: cables that stiffen from a soft start (``Truss.stiffness_scale`` with a
``GeometricRamp``), the line search's true baseline when prescribed values move (a slack cable turning taut)."""

import numpy as np
import pytest
import skfem
from _truss_checks import two_blocks_with_chord, two_nodes

from skvalve.fem import NodalForce, Problem, Solid, solve
from skvalve.fem.amplitudes import GeometricRamp, smooth_step_polynomial
from skvalve.fem.elements.truss import Truss
from skvalve.materials import NeoHookean
from skvalve.materials.uniaxial import LinearUniaxial, TensionOnly


def test_geometric_ramp_endpoints_midpoint_and_monotone():
    ramp = GeometricRamp(1e-4, 0.2, 0.6)
    assert ramp(0.0) == ramp(0.2) == pytest.approx(1e-4, rel=1e-14)
    assert ramp(0.6) == ramp(2.0) == 1.0
    # S(1/2) = 1/2: the geometric mean of the two ends
    assert ramp(0.4) == pytest.approx(1e-2, rel=1e-12)
    t = np.linspace(0.2, 0.6, 41)
    values = np.array([ramp(x) for x in t])
    assert np.all(np.diff(values) > 0)
    # ln s is the smooth step between ln s0 and 0
    xi = (t - 0.2) / 0.4
    assert np.allclose(np.log(values), np.log(1e-4) * (1 - smooth_step_polynomial(xi)), rtol=1e-12, atol=1e-13)
    for bad in ((0.0, 0.2, 0.6), (1e-3, 0.6, 0.2), (np.nan, 0, 1)):
        with pytest.raises(ValueError, match="GeometricRamp"):
            GeometricRamp(*bad)


def test_stiffness_scale_multiplies_forces_and_tangent():
    space, a, b = two_nodes()
    scale = 0.037
    scaled = Truss(space, [[a, b]], 0.3, LinearUniaxial(5.0), stiffness_scale=lambda t: scale * (1 + t))
    plain = Truss(space, [[a, b]], 0.3, LinearUniaxial(5.0))
    u = np.random.default_rng(3).normal(scale=0.2, size=space.n_dofs)
    one, two = scaled.assemble(u, 0.5, True, 1), plain.assemble(u, 0.5, True, 1)
    assert np.allclose(one.internal, 1.5 * scale * two.internal, rtol=1e-14, atol=0)
    assert np.allclose(one.blocks[0].matrices, 1.5 * scale * two.blocks[0].matrices, rtol=1e-14, atol=0)
    bad = Truss(space, [[a, b]], 0.3, LinearUniaxial(5.0), stiffness_scale=lambda t: 0.0)
    with pytest.raises(ValueError, match="stiffness_scale.*load step 4"):
        bad.assemble(u, 0.5, False, 4)


def test_scaled_chord_against_closed_form():
    """A linear chord with scale s pulled by F: s A E (lambda - 1) = F."""
    space, a, b = two_nodes()
    area, modulus, force, scale = 0.2, 10.0, 0.05, 1e-2
    problem = Problem(space, [Truss(space, [[a, b]], area, LinearUniaxial(modulus), stiffness_scale=lambda t: scale)])
    problem.add_dirichlet(nodes=np.setdiff1d(np.arange(space.n_scalar), [b]), value=0.0)
    problem.add_dirichlet(nodes=[b], value=0.0, components=[1, 2])
    problem.add_term(NodalForce(space, np.array([b]), [force, 0.0, 0.0], ramp=True))
    u = solve(problem, steps=1, progress=False, rtol=1e-12).u()
    assert 1.0 + u[3 * b] / 2.0 == pytest.approx(1.0 + force / (scale * area * modulus), rel=1e-12)


def _block_and_slack_cable():
    """A soft block fixed at x = 0; a stiff tension-only cable from the centre of its face x = 1 to a second,
    fully prescribed block 2 apart, whose cable is slack (rest length 2.5) until that block moves away."""
    cable = TensionOnly(LinearUniaxial(1e4), slack_fraction=1e-6, transition=0.01)
    solid, chord, _, _ = two_blocks_with_chord(cable, 0.05, 2.5, slack_stretch=2.0 / 2.5)
    solid.add_dirichlet(lambda X: X[0] < 1e-9, 0.0)
    solid.add_dirichlet(lambda X: X[0] > 2.5, lambda X, t: 0.8 * t, components=[0])
    solid.add_dirichlet(lambda X: X[0] > 2.5, 0.0, components=[1, 2])
    return solid, chord


def test_slack_cable_turning_taut_in_one_step_needs_no_cut_back():
    """The anchor moves 0.8: the cable (slack for the first 0.5) turns taut within the step. The consistent
    predictor, linearised at the slack state, barely moves the block, so its linearised |R| is tiny while the
    true residual with the new prescribed values is large; measured against the linearised |R| every line-search
    trial failed and the step was cut back. With the true baseline the step converges as one step, to the state
    that 40 small steps reach (an elastic problem: path independent)."""
    solid, chord = _block_and_slack_cable()
    one = solid.solve(steps=1, progress=False, rtol=1e-10, max_iter=40)
    assert one.load_factors == [0.0, 1.0]
    reference, _ = _block_and_slack_cable()
    many = reference.solve(steps=40, progress=False, rtol=1e-10, max_iter=40)
    assert np.allclose(one.u(), many.u(), rtol=0, atol=1e-8 * np.abs(many.u()).max())
    assert chord.response(one.u()).axial_force[0] > 0.0  # taut at the end


def test_stiffness_scale_softens_the_taut_law_and_keeps_the_slack_spring():
    """A softened cable must keep its slack spring: scaling it too leaves the ends of slack cables (chordae
    branch points) without support, and Newton's steps there blow up."""
    cable = TensionOnly(LinearUniaxial(100.0), slack_fraction=1e-3, transition=0.0)
    stretch = np.array([0.9, 0.97, 1.05, 1.2])
    slack = np.full(4, 0.95)
    P1, dP1 = cable.nominal_stress(stretch, slack)
    Ps, dPs = cable.nominal_stress(stretch, slack, 0.01)
    k = 1e-3 * 100.0
    expected = k * (stretch - 0.95) + 0.01 * np.where(stretch >= 1.0, 100.0 * (stretch - 1.0), 0.0)
    assert np.allclose(Ps, expected, rtol=1e-14, atol=1e-16)
    assert np.allclose(Ps[:2], P1[:2], rtol=1e-14) and np.allclose(dPs[:2], k, rtol=1e-14)
    assert np.allclose(dPs[2:], k + 0.01 * 100.0, rtol=1e-14)
    space, a, b = two_nodes()
    truss = Truss(space, [[a, b]], 0.5, cable, rest_length=[2.2], slack_stretch=[2.0 / 2.2],
                  stiffness_scale=lambda t: 0.01)
    u = np.zeros(space.n_dofs)
    u[3 * b] = -0.1  # slack: only the spring, unscaled
    force = truss.assemble(u, 0.0, False, 1).internal[3 * b]
    assert force == pytest.approx(0.5 * k * (1.9 / 2.2 - 2.0 / 2.2), rel=1e-12)


def _cantilever(tip_force: float) -> Solid:
    """A unit block (2x2x2 hexes) clamped at x = 0 with a ramped transverse load on its face x = 1."""
    solid = Solid(skfem.MeshHex().refined(1), NeoHookean(1.0, 10.0))
    X = solid.space.dof_coordinates
    solid.add_dirichlet(lambda X: X[0] < 1e-9, 0.0)
    solid.add_term(NodalForce(solid.space, np.flatnonzero(np.isclose(X[0], 1.0)), [0.0, 0.0, tip_force], ramp=True))
    return solid


def test_max_increment_caps_the_step_and_reaches_the_same_state():
    """A cantilever block under a large tip load: uncapped Newton moves some node more than 0.1 in one
    iteration; with max_increment = 0.05 every accepted iterate moves no node further than that, more iterations are
    needed, and the converged state is the same."""
    free = _cantilever(0.05).solve(steps=1, progress=False, rtol=1e-10)
    capped = solve(_cantilever(0.05), steps=1, progress=False, rtol=1e-10, max_iter=60, max_increment=0.05)
    assert np.allclose(capped.u(), free.u(), rtol=0, atol=1e-9)
    assert capped.iterations > free.iterations
    assert np.linalg.norm(free.u().reshape(-1, 3), axis=1).max() > 0.3  # the cap had work to do
    alphas = [record["alpha"] for record in capped.histories[1]]
    assert min(alphas) < 1.0
    assert max(record["largest_increment"] for record in capped.histories[1]) <= 0.05 * (1 + 1e-12)
    assert max(record["largest_increment"] for record in free.histories[1]) > 0.1
    with pytest.raises(ValueError, match="max_increment"):
        solve(_cantilever(0.05), steps=1, progress=False, max_increment=-1.0)


def test_levenberg_marquardt_shift_keeps_the_equilibrium():
    """The shift changes the iterates (more, shorter steps at first), not the state converged to."""
    plain = _cantilever(0.2).solve(steps=2, progress=False, rtol=1e-11)
    shifted = solve(_cantilever(0.2), steps=2, progress=False, rtol=1e-11, max_iter=60, regularization=1.0)
    for k in (1, 2):
        assert np.allclose(shifted.u(k), plain.u(k), rtol=0, atol=1e-10)
    assert shifted.iterations > plain.iterations
    with pytest.raises(ValueError, match="regularization"):
        solve(_cantilever(0.2), steps=1, progress=False, regularization=-0.5)
