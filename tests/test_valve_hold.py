"""The held phase of :func:`skvalve.valve.run.close_valve` on a stand-in setup (a block under a follower pressure with
IPC contact on its boundary): the trust-region stages reach the static equilibrium that load-stepped Newton finds, a
descend stage that runs out of steps hands on to the settle stage, and a run stopped inside the held phase and resumed
from its kept state (with the trust region's controller) repeats the uninterrupted one."""

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


# short steps and Newton's tries only near the end, so that the trust region's own steps (and a stage hand-on) occur
OPTIONS = CloseOptions(steps=StepOptions(first=0.25, largest=0.25, damping=1.0),
                       hold=HoldOptions(max_radius=0.05, newton_below=1e-4))


def test_the_held_stages_reach_the_static_equilibrium():
    report = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    assert report.converged and report.relative_residual <= 1e-6
    held = [record for record in report.records if record.phase == "hold"]
    assert held and report.held_steps == len(held) and all(record.iterations >= 1 for record in held)
    assert all(record.increment <= 0.05 * (1 + 1e-12) for record in held)  # no node moved more than max_radius
    newton = _newton_end_state()
    np.testing.assert_allclose(report.u, newton, atol=1e-5 * np.abs(newton).max())


def test_a_descend_stage_out_of_steps_hands_on_to_the_settle_stage(monkeypatch):
    stages = run_module.held_stages
    used = []

    def short_descend(options, load_norm, solver=None):
        descend, settle = stages(options, load_norm, solver)
        return [replace(descend, max_steps=2), settle]

    def seen(state):
        used.append((state.phase, state.held_stage, state.held_steps))

    monkeypatch.setattr(run_module, "held_stages", short_descend)
    report = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False, callbacks=[seen])
    assert report.converged and report.relative_residual <= 1e-6
    held = [entry for entry in used if entry[0] != "path"]  # the path's last step, each held step, the hand-on, the end
    assert held[:4] == [("hold", 0, 0), ("hold", 0, 1), ("hold", 0, 2), ("hold", 1, 2)]
    assert held[-1] == ("done", 1, report.held_steps) and report.held_steps > 2
    np.testing.assert_allclose(report.u, _newton_end_state(), atol=1e-5 * np.abs(report.u).max())


def test_a_run_stopped_in_the_held_phase_resumes_to_the_uninterrupted_result(tmp_path, monkeypatch):
    monkeypatch.setattr(run_module, "_write_final", lambda *args: None)  # the stand-in has no chordae to draw
    whole = run_module.close_valve(None, OPTIONS, setup=_block(), progress=False)
    assert whole.held_steps >= 3

    def stop_in_the_hold(state) -> None:
        if state.held_steps >= 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_module.close_valve(None, OPTIONS, setup=_block(), out=tmp_path, progress=False,
                               callbacks=[stop_in_the_hold])
    kept = read_state(tmp_path / "state.npz")
    assert kept.phase == "hold" and kept.held_steps == 2 and kept.control is not None and kept.control.steps == 2
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
