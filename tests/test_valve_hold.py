"""The held phase of :func:`skvalve.valve.run.close_valve` on a stand-in setup (a block under a follower pressure with
IPC contact on its boundary): the descend and settle stages hand on in turn to proximal steps, which reach the static
equilibrium that load-stepped Newton finds, with the pseudo-step growing after easy steps (by the residual's fall
after hard ones) and halved after a failed one, and a run stopped inside the held phase (in any stage) and resumed
from its kept state repeats the uninterrupted one.
"""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from skvalve.fem import Solid
from skvalve.fem.contact import IPCContact
from skvalve.fem.meshes import box
from skvalve.fem.solvers.newton import solve
from skvalve.materials import NeoHookean
from skvalve.valve import run as run_module
from skvalve.valve.history import StepWindow
from skvalve.valve.options import CloseOptions, HoldOptions, StepOptions
from skvalve.valve.setup import ValveSetup, end_load_norm
from skvalve.valve.state import read_state

PRESSURE = 0.05


def _block() -> ValveSetup:
    """A unit block fixed on x = 0 under a follower pressure on x = 1 (ramped over step time 0-1), with the
    ValveSetup fields the run reads."""
    mesh = box((2, 2, 2))
    solid = Solid(mesh, NeoHookean.from_shear_poisson(1.0, 0.3))
    solid.add_dirichlet("left", 0.0)
    solid.add_pressure("right", PRESSURE)
    contact = solid.add_term(IPCContact(solid.space, dhat=1e-3, stiffness=1.0))
    model = SimpleNamespace(mesh=mesh, end_time=1.0, pressures=[SimpleNamespace(at=lambda t: np.array([PRESSURE * t]))])
    n = mesh.p.shape[1]
    volumes = np.full(3 * n, 1.0 / n)
    return ValveSetup(None, model, solid, contact, np.zeros(n, dtype=np.int64), volumes, "block",
                      end_load_norm(solid, 1.0))


def _newton_end_state() -> np.ndarray:
    """The block's end state by load-stepped Newton (a second, independent solver)."""
    return solve(_block().problem, steps=4, rtol=1e-10, progress=False).u()


# short path steps with a heavy pseudo-mass: the path ends at a relative residual of 0.12, 4.5e-3 from the static state;
# energy steps of at most 2e-4 hand on to the proximal steps below 0.08
OPTIONS = CloseOptions(steps=StepOptions(first=0.25, largest=0.25, damping=1.0),
                       hold=HoldOptions(max_radius=2e-4, proximal_below=0.08, max_steps=40, growth=2.0))


@pytest.fixture
def short_descend(monkeypatch):
    """A descend stage of three steps, so that the settle stage has steps to take before the hand-on."""
    stages = run_module.energy_stages

    def three_steps(options, load_norm, solver=None):
        descend, settle = stages(options, load_norm, solver)
        return [replace(descend, max_steps=3), settle]

    monkeypatch.setattr(run_module, "energy_stages", three_steps)


def test_the_held_stages_hand_on_in_turn_and_reach_the_static_equilibrium(short_descend):
    report = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    assert report.converged and report.relative_residual <= 1e-6
    phases = [record.phase for record in report.records]
    settle, proximal = phases.count("settle"), phases.count("proximal")
    assert settle >= 1 and proximal >= 2
    assert phases == ["path"] * 4 + ["descend"] * 3 + ["settle"] * settle + ["proximal"] * proximal
    energy = [record for record in report.records if record.phase in ("descend", "settle")]
    assert all(record.moved <= 2e-4 * (1 + 1e-12) for record in energy)  # no node moved more than max_radius
    assert energy[-1].relative_residual < 0.08 < energy[-2].relative_residual  # handed on below proximal_below
    # the pseudo-step starts at the path's last step length and doubles after each easy step; after a hard exact one
    # it grows by the static residual's fall (between 1/2 and 2), after an inexact one it stays
    first = phases.index("proximal")
    assert report.records[first].increment == pytest.approx(0.25)
    easy = OPTIONS.steps.easy_iterations
    for k in range(first, len(phases) - 1):
        start, before, after = report.records[k - 1: k + 2]
        fall = start.relative_residual / before.relative_residual
        factor = 2.0 if before.iterations <= easy else min(2.0, max(fall, 1.0 if fall >= 1.0 else 0.5))
        assert after.increment == pytest.approx(before.increment * (factor if before.exact else 1.0))
    newton = _newton_end_state()
    np.testing.assert_allclose(report.u, newton, atol=1e-5 * np.abs(newton).max())


def test_a_held_phase_out_of_steps_stops_with_its_last_state():
    with pytest.raises(run_module.ClosureFailed, match="not converged in 12 held steps"):
        run_module.close_valve(None, replace(OPTIONS, hold=replace(OPTIONS.hold, max_steps=12)), setup=_block(),
                               progress=False)


def test_a_failed_held_step_is_retried_with_half_the_pseudo_step(monkeypatch):
    """The first proximal step fails once (as a step whose Newton iterations run out would): it is retried from the same
    state with half the pseudo-step, and the run still converges to Newton's state."""
    real = run_module._Run.step
    failures = []

    def fail_once(self, t_new, inertia_scale, rtol, max_iter):
        if self.state.phase == "hold" and self.state.held_stage == 2 and not failures:
            failures.append(inertia_scale)
            raise run_module.StepFailed("made to fail")
        return real(self, t_new, inertia_scale, rtol, max_iter)

    monkeypatch.setattr(run_module._Run, "step", fail_once)
    report = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    held = [record for record in report.records if record.phase == "proximal"]
    assert failures and report.failed_steps == 1 and held[0].increment == pytest.approx(0.125)
    assert failures[0] == pytest.approx(OPTIONS.steps.damping / 0.25)  # the failed try had the path's last length
    assert report.converged
    np.testing.assert_allclose(report.u, _newton_end_state(), atol=1e-5 * np.abs(report.u).max())


@pytest.mark.parametrize("stage", ["descend", "settle", "proximal"])
def test_a_run_stopped_in_the_held_phase_resumes_to_the_uninterrupted_result(tmp_path, monkeypatch, short_descend,
                                                                              stage):
    monkeypatch.setattr(run_module, "_write_final", lambda *args: None)  # the stand-in has no chordae to draw
    whole = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    phases = [record.phase for record in whole.records if record.phase != "path"]
    stop_at = phases.index(stage) + 2 if stage != "descend" else 2  # the held steps taken when the run is stopped
    assert phases[stop_at - 1] == stage

    def stop_in_the_hold(state) -> None:
        if state.held_steps >= stop_at:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_module.close_valve(None, OPTIONS, setup=_block(), out=tmp_path, progress=False,
                               callbacks=[stop_in_the_hold])
    kept = read_state(tmp_path / "state.npz")
    assert kept.phase == "hold" and kept.held_steps == stop_at
    assert kept.held_stage == ("descend", "settle", "proximal").index(stage)
    assert (kept.control is not None) == (stage != "proximal")  # an energy stage resumes with its controller
    resumed = run_module.close_valve(None, out=tmp_path, resume=True, setup=_block(), progress=False)
    assert resumed.converged and resumed.held_steps == whole.held_steps and resumed.iterations == whole.iterations
    np.testing.assert_allclose(resumed.u, whole.u, rtol=0.0, atol=1e-10 * np.abs(whole.u).max())


def test_path_steps_land_on_the_inputs_step_boundaries():
    """A model with steps breaking at total time 0.37: a path step lands there exactly (amplitudes and obstacle
    contact change at step boundaries), and the step after it keeps the planned length the break cut short."""
    setup = _block()
    setup.model.steps = [StepWindow("first", 0.0, 0.37, False), StepWindow("second", 0.37, 0.63, False)]
    options = CloseOptions(steps=StepOptions(first=0.25, largest=0.25, damping=1.0))
    report = run_module.close_valve(None, options, setup=setup, progress=False)
    path = [record for record in report.records if record.phase == "path"]
    times = [record.t for record in path]
    assert 0.37 in times and report.converged
    k = times.index(0.37)
    assert path[k].increment == pytest.approx(0.37 - times[k - 1]) and path[k].increment < 0.25
    assert path[k + 1].increment == pytest.approx(min(1.0 - 0.37, 0.25))


def test_end_load_norm_is_the_pressure_nodal_forces_norm():
    """The closure's force scale on the block: the x = 1 face (2 x 2 bilinear facets of 1/4) under p carries nodal
    forces p/16 at its 4 corners, p/8 at its 4 edge midpoints and p/4 at its centre: norm 0.375 p."""
    setup = _block()
    assert setup.load_norm == pytest.approx(0.375 * PRESSURE, rel=1e-12)
    assert end_load_norm(setup.problem, 0.5) == pytest.approx(0.5 * 0.375 * PRESSURE, rel=1e-12)  # ramped
    with pytest.raises(ValueError, match="no pressure"):
        end_load_norm(setup.problem, 0.0)


def _proximal_steps_out_of_iterations(monkeypatch, first_bar: float | None = None) -> list[float]:
    """Hold every proximal step to one Newton iteration (two while contracting) against a tolerance it cannot reach,
    so that each runs out of iterations; ``first_bar``: the residual the first try's last iterate must get below.
    Returns the pseudo-mass scale of each try."""
    real_step, real_attempt = run_module._Run.step, run_module._Run.attempt
    tries = []

    def out_of_iterations(self, t_new, inertia_scale, rtol, max_iter):
        proximal = self.state.phase == "hold" and self.state.held_stage == 2
        return real_step(self, t_new, inertia_scale, 1e-14 if proximal else rtol, 1 if proximal else max_iter)

    def bar(self, t_new, inertia_scale, rtol, max_iter, inexact_below=None):
        if inexact_below is not None:
            tries.append(inertia_scale)
            if len(tries) == 1 and first_bar is not None:
                inexact_below = first_bar
        return real_attempt(self, t_new, inertia_scale, rtol, max_iter, inexact_below)

    monkeypatch.setattr(run_module._Run, "step", out_of_iterations)
    monkeypatch.setattr(run_module._Run, "attempt", bar)
    return tries


def test_a_proximal_step_out_of_iterations_is_taken_at_its_last_iterate_when_that_lowers_the_residual(monkeypatch):
    """Proximal steps that run out of iterations are each taken at their last iterate: the static residual falls from
    step to step, the pseudo-step stays as it was, none is cut back, and the run ends at Newton's state."""
    _proximal_steps_out_of_iterations(monkeypatch)
    report = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    held = [record for record in report.records if record.phase == "proximal"]
    assert len(held) >= 3 and report.failed_steps == 0
    assert all(record.iterations <= 2 for record in held)
    inexact = [record for record in held if not record.exact]
    assert len(inexact) >= 3
    for before, after in zip(held, held[1:], strict=False):  # an inexact step leaves the pseudo-step as it was
        assert after.increment == pytest.approx(before.increment * (1.0 if not before.exact else 2.0))
    assert "proximal (inexact) t=1 h=0.25 iterations=2" in inexact[0].line()
    residuals = [record.relative_residual for record in held]
    assert all(after < before for before, after in zip(residuals, residuals[1:], strict=False))
    assert report.converged
    np.testing.assert_allclose(report.u, _newton_end_state(), atol=1e-5 * np.abs(report.u).max())


def test_an_inexact_step_that_does_not_lower_the_residual_enough_is_refused(monkeypatch):
    """The first proximal step's last iterate must get below a residual it cannot reach: it is refused, the terms are
    rewound and the step is retried from the same state at half the pseudo-step; the run still converges."""
    tries = _proximal_steps_out_of_iterations(monkeypatch, first_bar=1e-12)
    report = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    assert report.failed_steps == 1 and tries[1] == pytest.approx(2.0 * tries[0])  # pseudo-mass c/h: h halved
    held = [record for record in report.records if record.phase == "proximal"]
    assert held[0].increment == pytest.approx(0.125)
    assert report.converged
    np.testing.assert_allclose(report.u, _newton_end_state(), atol=1e-5 * np.abs(report.u).max())


def test_the_proximal_pseudo_step_grows_by_the_residuals_fall_after_a_hard_step():
    """The rule on the 1.0 diseased valve's held steps (hard: 26 iterations, 7.305e-3 -> 2.874e-3): SER's ratio 2.54,
    capped by ``growth``; a residual that rises halves at most; an easy step grows by ``growth``; an inexact step
    keeps the pseudo-step."""
    assert run_module.proximal_growth(True, False, 7.305e-3, 2.874e-3, 3.0) == pytest.approx(7.305 / 2.874, rel=1e-15)
    assert run_module.proximal_growth(True, False, 1e-2, 1e-4, 3.0) == 3.0
    assert run_module.proximal_growth(True, False, 1e-3, 1.25e-3, 3.0) == pytest.approx(0.8, rel=1e-15)
    assert run_module.proximal_growth(True, False, 1e-3, 1e-1, 3.0) == 0.5
    assert run_module.proximal_growth(True, True, 1e-3, 1e-1, 3.0) == 3.0
    assert run_module.proximal_growth(False, True, 1e-2, 1e-4, 3.0) == 1.0
