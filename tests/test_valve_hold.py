"""The held phase of :func:`skvalve.valve.run.close_valve` on a stand-in setup (a block under a follower pressure with
IPC contact on its boundary): damped held steps alone, with the static solve refused, must reach the static
equilibrium, and the refused static problem is tried again only after the residual fell tenfold. Each held step
converges to a tenth of the static residual it starts from (a forcing term); at the path's own tolerance a state the
path left just inside it would be accepted as it is, and the held steps would not move (the 1.0 diseased valve's
first held steps did that: 0 iterations each, the residual unchanged)."""

from types import SimpleNamespace

import numpy as np
import pytest

from skvalve.fem import Solid
from skvalve.fem.contact import IPCContact
from skvalve.fem.errors import SolverError
from skvalve.fem.meshes import box
from skvalve.fem.newton import solve
from skvalve.materials import NeoHookean
from skvalve.valve import run as run_module
from skvalve.valve.history import StepWindow
from skvalve.valve.options import CloseOptions, HoldOptions, StepOptions
from skvalve.valve.setup import ValveSetup, end_load_norm

PRESSURE = 0.05
CAP = 1  # iterations of a damped held step in the test of unconverged held steps


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


def test_damped_held_steps_alone_reach_the_static_equilibrium(monkeypatch):
    attempt = run_module._Run.attempt
    static_tries = []

    def no_static(self, t_new, inertia_scale, rtol, max_iter, **kwargs):
        if inertia_scale == 0.0:
            static_tries.append(self.state.relative_residual)
            self.last_error = SolverError("static solve refused by the test")
            return None
        return attempt(self, t_new, inertia_scale, rtol, max_iter, **kwargs)

    monkeypatch.setattr(run_module._Run, "attempt", no_static)
    options = CloseOptions(steps=StepOptions(first=0.25, largest=0.25, damping=1.0), hold=HoldOptions(max_steps=60))
    report = run_module.close_valve(None, options, setup=_block(), progress=False)
    assert report.converged and report.relative_residual <= 1e-6
    held = [record for record in report.records if record.phase == "hold"]
    assert held and all(record.iterations > 0 for record in held)  # every held step moved
    assert all(record.converged for record in held) and report.failed_steps == 0
    for before, after in zip(held, held[1:], strict=False):  # each converged held step doubles the pseudo-step
        assert after.increment == pytest.approx(options.hold.growth * before.increment)
    residuals = [record.relative_residual for record in held]
    assert all(b < a for a, b in zip(residuals, residuals[1:], strict=False))
    # a failed static problem is tried again only once the residual fell tenfold, not from every held state
    assert static_tries and len(static_tries) < len(held)
    assert all(b <= 0.1 * a for a, b in zip(static_tries, static_tries[1:], strict=False))
    # the same block by load-stepped Newton: the held state is its equilibrium
    reference = _block().problem
    newton = solve(reference, steps=4, rtol=1e-10, progress=False)
    np.testing.assert_allclose(report.u, newton.u(), atol=1e-5 * np.abs(newton.u()).max())


def test_held_steps_out_of_iterations_are_kept_for_their_progress(monkeypatch):
    """A held step that runs out of iterations is kept (marked unconverged) when its last iterate lowered the static
    residual, and keeps its pseudo-step: with the damped held steps held to one iteration on the block, every one ends
    unconverged, and the held steps still reach the equilibrium, the static residual falling at every held step."""
    step = run_module._Run.step

    def capped(self, t_new, inertia_scale, rtol, max_iter):
        damped_hold = self.state.phase == "hold" and inertia_scale > 0.0
        return step(self, t_new, inertia_scale, rtol, CAP if damped_hold else max_iter)

    monkeypatch.setattr(run_module._Run, "step", capped)
    options = CloseOptions(steps=StepOptions(first=0.25, largest=0.25, damping=1.0), hold=HoldOptions(max_steps=200))
    report = run_module.close_valve(None, options, setup=_block(), progress=False)
    assert report.converged and report.relative_residual <= 1e-6
    held = [record for record in report.records if record.phase == "hold" and np.isfinite(record.increment)]
    assert len(held) > 1 and not any(record.converged for record in held)
    assert all(record.iterations == CAP and "unconverged" in record.line() for record in held)
    assert len({record.increment for record in held}) == 1  # an unconverged step does not let the pseudo-mass fade
    residuals = [record.relative_residual for record in report.records if record.phase == "hold"]
    assert all(b < a for a, b in zip(residuals, residuals[1:], strict=False))


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
