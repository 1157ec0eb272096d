"""Pseudo-transient continuation (:mod:`skvalve.fem.solvers.ptc`): it converges to the undamped equilibrium that
load-stepped
Newton or a closed form gives, its trust regions hold on every accepted step, and bad input fails clearly."""

from dataclasses import replace

import numpy as np
import pytest
from _truss_checks import sheared_block, two_nodes
from scipy.optimize import brentq

from skvalve.fem import NodalForce, Problem, solve
from skvalve.fem.elements.truss import Truss
from skvalve.fem.errors import ConvergenceError
from skvalve.fem.solvers.damping import lumped_volume
from skvalve.fem.solvers.ptc import PseudoTransientOptions, _carriers, pseudo_transient
from skvalve.fem.terms import Blocks, Contribution, Term
from skvalve.materials.uniaxial import OgdenUniaxial, TensionOnly


def test_relaxes_to_the_equilibrium_newton_reaches():
    """An elastic problem is path independent: Ψtc (one damped linear step per pseudo-step, no equilibrium on the
    way) must end where 10 converged Newton load steps end, and its last steps must converge like Newton's."""
    newton = solve(sheared_block(), 10, progress=False, rtol=1e-11)
    block = sheared_block()
    seen = []
    result = pseudo_transient(block, lumped_volume(block.space), 1.0,
                              PseudoTransientOptions(damping=1.0, first_step=0.05, max_load_step=0.1, rtol=1e-11,
                                                     max_increment=None, max_strain_increment=None),
                              progress=False, callbacks=[seen.append])
    assert result.converged and result.load_factor == 1.0
    assert np.abs(result.u - newton.u()).max() <= 1e-9 * np.abs(newton.u()).max()
    # the residual it reports is the undamped one, recomputed independently
    residual, _ = block.assemble(result.u, 1.0, tangent=False)
    free, fixed = block.pattern.free, block.pattern.fixed
    assert np.linalg.norm(residual[free]) == pytest.approx(result.residuals[-1], rel=1e-10)
    assert np.linalg.norm(residual[free]) <= 1e-11 * np.linalg.norm(residual[fixed])
    # the load follows pseudo-time, then is held while the damping fades (SER: growing steps, falling residual)
    assert result.load_factors == sorted(result.load_factors)
    held = np.flatnonzero(np.array(result.load_factors) == 1.0)
    assert result.step_lengths[held[-1]] > 10 * result.step_lengths[held[0]]
    assert result.residuals[-1] < 1e-6 * max(result.residuals)
    assert [event.step for event in seen] == list(range(1, len(result.pseudo_times) + 1))
    # a stiffness-proportional damping (here a function of the load factor) changes the path, not the end state
    block = sheared_block()
    damped = pseudo_transient(block, lumped_volume(block.space), 1.0,
                              PseudoTransientOptions(damping=1.0, first_step=0.05, max_load_step=0.1, rtol=1e-11,
                                                     max_increment=None, stiffness_damping=lambda t: 0.05 * t),
                              progress=False)
    assert damped.converged and np.abs(damped.u - newton.u()).max() <= 1e-9 * np.abs(newton.u()).max()
    assert damped.step_lengths != result.step_lengths


def test_held_growth_lengthens_every_step_whose_residual_does_not_grow():
    """``held_growth``: at the held load the pseudo-time step grows at least by that factor (at most by ``growth``)
    after each accepted step whose residual fell, and the end state is still Newton's."""
    newton = solve(sheared_block(), 10, progress=False, rtol=1e-11)
    block = sheared_block()
    options = PseudoTransientOptions(damping=1.0, first_step=0.05, max_load_step=0.1, rtol=1e-11, max_increment=None,
                                     max_strain_increment=None, stiffness_damping=0.5, held_growth=1.5, growth=3.0)
    result = pseudo_transient(block, lumped_volume(block.space), 1.0, options, progress=False)
    assert result.converged and np.abs(result.u - newton.u()).max() <= 1e-9 * np.abs(newton.u()).max()
    held = np.flatnonzero(np.array(result.load_factors) == 1.0)
    ratios = [(result.step_lengths[k + 1] / result.step_lengths[k], result.residuals[k] / result.residuals[k - 1])
              for k in held[1:-1]]
    assert ratios and all(1.5 - 1e-12 <= ratio <= 3.0 + 1e-12 for ratio, fell in ratios if fell <= 1.0)
    # with pure SER (held_growth 1) the same problem takes more held steps
    block = sheared_block()
    plain = pseudo_transient(block, lumped_volume(block.space), 1.0, replace(options, held_growth=1.0), progress=False)
    assert plain.converged and len(plain.pseudo_times) > len(result.pseudo_times)
    with pytest.raises(ValueError, match="held_growth"):
        PseudoTransientOptions(held_growth=3.0, growth=2.0)


def test_held_stiffness_damping_replaces_the_stiffness_damping_once_the_load_is_held():
    """``held_stiffness_damping = 0``: the stiffness-proportional damping of the load path stops at the held load; the
    end state is still Newton's, reached in fewer held steps than with the damping kept."""
    newton = solve(sheared_block(), 10, progress=False, rtol=1e-11)
    options = PseudoTransientOptions(damping=1.0, first_step=0.05, max_load_step=0.1, rtol=1e-11, max_increment=None,
                                     max_strain_increment=None, stiffness_damping=2.0)
    results = []
    for held in (None, 0.0):
        block = sheared_block()
        results.append(pseudo_transient(block, lumped_volume(block.space), 1.0,
                                        replace(options, held_stiffness_damping=held), progress=False))
    kept, dropped = results
    for result in results:
        assert result.converged and np.abs(result.u - newton.u()).max() <= 1e-9 * np.abs(newton.u()).max()
    # the load path is the same (same damping while the load moves), the held relaxation shorter
    path = [k for k, t in enumerate(kept.load_factors) if t < 1.0]
    assert [dropped.load_factors[k] for k in path] == [kept.load_factors[k] for k in path]
    assert kept.load_factors.count(1.0) > dropped.load_factors.count(1.0)
    with pytest.raises(ValueError, match="held_stiffness_damping"):
        PseudoTransientOptions(held_stiffness_damping=-1.0)


class _Memory(Term):
    """No forces; counts its assemblies as a state (like a contact search's memory of the last active set)."""

    def __init__(self) -> None:
        self.assemblies = 0

    def connectivity(self):
        return []

    def assemble(self, u, t, tangent, step):
        self.assemblies += 1
        return Contribution()

    def state(self):
        return {"assemblies": np.array([self.assemblies])}

    def restore(self, arrays):
        if "assemblies" in arrays:
            self.assemblies = int(arrays["assemblies"][0])


def test_giving_up_at_the_held_load_keeps_the_held_state_with_the_smallest_residual():
    """A linear chord (k = 1) pulled by 0.4 and pushed back by 0.3 once past u = 0.2: no equilibrium (0.4 below
    0.2, 0.1 above), so the held residual rises and falls around the jump. When the run gives up, its state is the
    held one whose residual was smallest (found here from the callbacks), not the last."""
    from skvalve.materials.uniaxial import LinearUniaxial

    space, a, b = two_nodes()
    chord = Truss(space, [[a, b]], 0.5, LinearUniaxial(4.0))
    memory = _Memory()
    problem = Problem(space, [chord, NodalForce(space, np.array([b]), [0.4, 0.0, 0.0], ramp=True),
                              _JumpForce(space.n_dofs, 3 * b, 0.2, -0.3), memory])
    problem.add_dirichlet(nodes=np.setdiff1d(np.arange(space.n_scalar), [b]), value=0.0)
    problem.add_dirichlet(nodes=[b], value=0.0, components=[1, 2])
    weights = np.zeros(space.n_dofs)
    weights[3 * b] = 1.0
    seen, memories = [], {}
    options = PseudoTransientOptions(damping=1.0, first_step=0.5, max_load_step=0.5, max_increment=None,
                                     blow_up=1e6, max_steps=40, stall_steps=0)
    with pytest.raises(ConvergenceError, match="40 pseudo-steps") as info:
        pseudo_transient(problem, weights, 1.0, options, progress=False,
                         callbacks=[lambda event: seen.append((event.step, event.load_factor, event.residual_norm,
                                                               event.u.copy())),
                                    lambda event: memories.update({event.step: memory.assemblies})])
    held = [event for event in seen if event[1] == 1.0]
    best = min(held, key=lambda event: event[2])
    kept = info.value.last_state
    assert held[-1][2] > 1.5 * best[2]  # the last held state is not the best one: the test can tell them apart
    assert kept.kept_step == best[0] and kept.load_factor == 1.0
    assert np.array_equal(kept.u, best[3])
    # the terms' state is given back as it was at that step (what a re-evaluation of the kept state depends on)
    assert memory.assemblies == memories[best[0]] < max(memories.values())
    # the jump is where the residual is smallest: the kept state sits next to it
    assert abs(kept.u[3 * b] - 0.2) < 0.1


def test_the_carriers_of_a_blown_up_residual_are_the_fewest_nodes_with_most_of_it():
    """``_carriers`` picks, by hand: nodal residual norms 3, 1, 10, 0.5 (squares 9, 1, 100, 0.25; sum 110.25): 90 %
    (99.2) needs node 2 alone, 95 % (104.7) nodes 2 and 0; without node 2's dof (a reaction, not a residual) the
    squares 9, 1, 0.25 need nodes 0 and 1 for 90 % (9.2)."""
    space = type("Space", (), {"n_u": 12, "dim": 3})()
    residual = np.zeros(12)
    residual[[0, 4, 6, 9]] = [3.0, 1.0, 10.0, 0.5]  # nodes 0, 1, 2, 3
    free = np.arange(12)
    assert _carriers(residual, free, space).tolist() == [2]
    assert _carriers(residual, free, space, share=0.95).tolist() == [2, 0]
    assert _carriers(residual, np.setdiff1d(free, [6]), space).tolist() == [0, 1]


def _slack_chord(force: float):
    """An Ogden chord (alpha = 50, as the tricuspid chordae) from a fixed node to a node 2 away that a force pulls
    along the chord; rest length 2.2: slack at the start, held only by its slack spring (1e-6 of the modulus)."""
    space, a, b = two_nodes()
    law = OgdenUniaxial((4.0, 15.0), (50.0, 50.0))
    chord = Truss(space, [[a, b]], 0.33, TensionOnly(law, slack_fraction=1e-6), rest_length=[2.2],
                  slack_stretch=[2.0 / 2.2])
    problem = Problem(space, [chord])
    problem.add_dirichlet(nodes=np.setdiff1d(np.arange(space.n_scalar), [b]), value=0.0)
    problem.add_dirichlet(nodes=[b], value=0.0, components=[1, 2])
    problem.add_term(NodalForce(space, np.array([b]), [force, 0.0, 0.0], ramp=True))
    return problem, law, b


def test_slack_exponential_chord_against_the_closed_form_with_the_strain_trust_region():
    """From slack, the tangent is the slack spring's: a linearised step would throw the end metres away, into
    lambda^50. The strain trust region (5 % per step) walks it taut; the end state solves A P(lambda) = F."""
    force = 2.0
    problem, law, b = _slack_chord(force)
    weights = np.zeros(problem.space.n_dofs)
    weights[3 * b] = 1.0
    options = PseudoTransientOptions(damping=1e-3, first_step=0.1, max_load_step=0.1, rtol=1e-12, atol=1e-13,
                                     max_strain_increment=0.05, max_increment=None)
    lengths = [2.0]
    result = pseudo_transient(problem, weights, 1.0, options, edges=np.array([[0, b]]), rest_lengths=[2.2],
                              progress=False,
                              callbacks=[lambda event: lengths.append(2.0 + event.u[3 * b])])
    assert result.converged
    k_slack = 1e-6 * law.young_modulus  # the parallel slack spring, from the slack stretch 2/2.2 on

    def balance(lam):
        return 0.33 * (law.nominal_stress(np.array([lam]))[0][0] + k_slack * (lam - 2.0 / 2.2)) - force

    stretch = brentq(balance, 1.0, 1.5, xtol=1e-15)
    assert (2.0 + result.u[3 * b]) / 2.2 == pytest.approx(stretch, rel=1e-10)
    taut_stretch = np.maximum(np.array(lengths) / 2.2, 1.0)
    assert np.abs(np.diff(taut_stretch)).max() <= 0.05 * (1 + 1e-12)  # the trust region held on every accepted step
    assert result.rejected > 0  # and had work to do
    # local damping (the nodes that break the trust region are damped more, the step barely cut): same end state
    problem, _, _ = _slack_chord(force)
    local = pseudo_transient(problem, weights, 1.0, replace(options, local_damping=10.0), edges=np.array([[0, b]]),
                             rest_lengths=[2.2], progress=False)
    assert local.converged and (2.0 + local.u[3 * b]) / 2.2 == pytest.approx(stretch, rel=1e-10)
    assert local.rejected > 0
    # without it, the first linearised step leaves the chord far beyond the root (what Newton's first iterate does)
    assert 0.1 * force / (0.33 * k_slack / 2.2) > 1e3


def test_filling_the_trust_region_ends_where_newton_does_with_fewer_rejected_steps():
    """The sheared block followed under a nodal trust region that binds (the prescribed face moves 0.5 at most
    0.02 a step): growing the step by load_growth alone keeps breaking the region (each rejection a wasted
    factorisation); aiming each next step at 0.8 of the region from the last one's use (fill) rejects fewer, holds
    the region on every accepted step and ends where load-stepped Newton does."""
    newton = solve(sheared_block(), 10, progress=False, rtol=1e-11)
    runs = {}
    for fill in (None, 0.8):
        block = sheared_block()
        moves = []
        options = PseudoTransientOptions(damping=1.0, first_step=0.01, max_load_step=1.0, rtol=1e-11,
                                         max_increment=0.02, max_strain_increment=None, fill=fill)
        runs[fill] = pseudo_transient(block, lumped_volume(block.space), 1.0, options, progress=False,
                                      callbacks=[lambda event, seen=moves: seen.append(event.u.copy())])
        assert runs[fill].converged
        assert np.abs(runs[fill].u - newton.u()).max() <= 1e-9 * np.abs(newton.u()).max()
        assert max(runs[fill].largest_increments) <= 0.02
    assert runs[None].rejected >= 5 and runs[0.8].rejected <= runs[None].rejected // 3
    with pytest.raises(ValueError, match="fill"):
        PseudoTransientOptions(fill=1.5)


class _JumpForce(Term):
    """A dead force ``jump`` on one dof once it passes ``at`` (zero tangent): a discontinuity like a contact pair that
    switches on at a finite overlap."""

    load_dependent = False

    def __init__(self, n_dofs: int, dof: int, at: float, jump: float) -> None:
        self.n_dofs, self.dof, self.at, self.jump = n_dofs, dof, at, jump

    def connectivity(self):
        return [np.array([[self.dof]])]

    def assemble(self, u, t, tangent, step):
        external = np.zeros(self.n_dofs)
        external[self.dof] = self.jump if u[self.dof] > self.at else 0.0
        return Contribution(external=external, blocks=[Blocks(np.array([[self.dof]]),
                                                               np.zeros((1, 1, 1)) if tangent else None)])


def test_a_residual_jump_no_shorter_step_removes_is_crossed():
    """A linear chord (k = A E / L) pulled by F, plus a force J switched on past u = 0.1: the residual jumps by J there
    however short the step. Rejected at first, the crossing step is accepted once shorter than accept_jumps_below, and
    the end state is the closed form u = (F + J) / k; with the option off, the run gives up with an error."""
    from skvalve.materials.uniaxial import LinearUniaxial

    def build():
        space, a, b = two_nodes()
        chord = Truss(space, [[a, b]], 0.5, LinearUniaxial(4.0))
        problem = Problem(space, [chord, NodalForce(space, np.array([b]), [0.4, 0.0, 0.0], ramp=True),
                                  _JumpForce(space.n_dofs, 3 * b, 0.1, 0.3)])
        problem.add_dirichlet(nodes=np.setdiff1d(np.arange(space.n_scalar), [b]), value=0.0)
        problem.add_dirichlet(nodes=[b], value=0.0, components=[1, 2])
        weights = np.zeros(space.n_dofs)
        weights[3 * b] = 1.0
        return problem, weights, b

    problem, weights, b = build()
    options = PseudoTransientOptions(damping=1.0, first_step=0.1, max_load_step=0.1, rtol=1e-12, atol=1e-14,
                                     max_increment=None, accept_jumps_below=1e-4, min_step=1e-7, blow_up=2.0)
    result = pseudo_transient(problem, weights, 1.0, options, progress=False)
    k = 0.5 * 4.0 / 2.0
    assert result.converged and result.rejected > 0
    assert result.u[3 * b] == pytest.approx((0.4 + 0.3) / k, rel=1e-10)
    problem, weights, b = build()
    with pytest.raises(ConvergenceError, match="pseudo-time step fell"):
        pseudo_transient(problem, weights, 1.0, PseudoTransientOptions(
            damping=1.0, first_step=0.1, max_load_step=0.1, max_increment=None, accept_jumps_below=0.0,
            min_step=1e-7, blow_up=2.0), progress=False)


def test_a_stalled_relaxation_gives_up_with_a_held_state():
    """A pseudo-step so short that the held residual cannot halve in 5 steps: the run stops, naming the stall."""
    problem, _, b = _slack_chord(2.0)
    weights = np.zeros(problem.space.n_dofs)
    weights[3 * b] = 1.0
    options = PseudoTransientOptions(damping=1e3, first_step=0.5, max_load_step=0.5, growth=1.0, stall_steps=5,
                                     max_increment=None)
    with pytest.raises(ConvergenceError, match="stalled") as info:
        pseudo_transient(problem, weights, 1.0, options, progress=False)
    assert info.value.last_state.load_factor == 1.0 and not info.value.last_state.converged


def test_bad_input_and_giving_up():
    problem, _, b = _slack_chord(2.0)
    with pytest.raises(ValueError, match="weights must be"):
        pseudo_transient(problem, np.ones(3), 1.0, progress=False)
    with pytest.raises(ValueError, match="edges must be node pairs"):
        pseudo_transient(problem, np.ones(problem.space.n_dofs), 1.0, edges=np.array([[0, 99]]), progress=False)
    with pytest.raises(ValueError, match="t0 <= end"):
        pseudo_transient(problem, np.ones(problem.space.n_dofs), 0.5, t0=1.0, progress=False)
    for bad in ({"damping": 0.0}, {"growth": 0.5}, {"max_strain_increment": -1.0}, {"atol": np.nan}):
        with pytest.raises(ValueError, match="PseudoTransientOptions"):
            PseudoTransientOptions(**bad)
    # a trust region too tight to ever pass: the step shrinks below min_step and the error names where
    options = PseudoTransientOptions(max_strain_increment=1e-9, min_step=1e-6, first_step=0.1, max_increment=None)
    with pytest.raises(ConvergenceError, match=r"pseudo-step 1, load factor .*last accepted load factor 0") as info:
        pseudo_transient(problem, np.ones(problem.space.n_dofs), 1.0, options, edges=np.array([[0, b]]),
                         progress=False)
    assert info.value.last_state.load_factor == 0.0 and info.value.last_state.rejected > 0
