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
from skvalve.valve.options import CloseOptions, HoldOptions, StepOptions
from skvalve.valve.setup import ValveSetup, end_load_norm

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
    residuals = [record.relative_residual for record in held]
    assert all(b < a for a, b in zip(residuals, residuals[1:], strict=False))
    # a failed static problem is tried again only once the residual fell tenfold, not from every held state
    assert static_tries and len(static_tries) < len(held)
    assert all(b <= 0.1 * a for a, b in zip(static_tries, static_tries[1:], strict=False))
    # the same block by load-stepped Newton: the held state is its equilibrium
    reference = _block().problem
    newton = solve(reference, steps=4, rtol=1e-10, progress=False)
    np.testing.assert_allclose(report.u, newton.u(), atol=1e-5 * np.abs(newton.u()).max())


def test_held_steps_out_of_iterations_are_kept_for_their_progress():
    """A held step that runs out of iterations is kept (marked unconverged) when its last iterate lowered the static
    residual, and only a converged held step lets the pseudo-step grow: with max_iter 2 the held steps on the block
    end unconverged and still reach the equilibrium, the static residual falling at every held step."""
    options = CloseOptions(steps=StepOptions(first=0.25, largest=0.25, damping=1.0, max_iter=2),
                           hold=HoldOptions(max_steps=200))
    report = run_module.close_valve(None, options, setup=_block(), progress=False)
    assert report.converged and report.relative_residual <= 1e-6
    held = [record for record in report.records if record.phase == "hold" and np.isfinite(record.increment)]
    assert any(not record.converged for record in held) and any(record.converged for record in held)
    residuals = [record.relative_residual for record in report.records if record.phase == "hold"]
    assert all(b < a for a, b in zip(residuals, residuals[1:], strict=False))
    for before, after in zip(held, held[1:], strict=False):  # grows by HoldOptions.growth after a converged step
        expected = before.increment * (options.hold.growth if before.converged else 1.0)
        assert after.increment == pytest.approx(expected)
    assert all(record.iterations == 2 for record in held if not record.converged)
    assert "unconverged" in held[[record.converged for record in held].index(False)].line()


def test_end_load_norm_is_the_pressure_nodal_forces_norm():
    """The closure's force scale on the block: the x = 1 face (2 x 2 bilinear facets of 1/4) under p carries nodal
    forces p/16 at its 4 corners, p/8 at its 4 edge midpoints and p/4 at its centre: norm 0.375 p."""
    setup = _block()
    assert setup.load_norm == pytest.approx(0.375 * PRESSURE, rel=1e-12)
    assert end_load_norm(setup.problem, 0.5) == pytest.approx(0.5 * 0.375 * PRESSURE, rel=1e-12)  # ramped
    with pytest.raises(ValueError, match="no pressure"):
        end_load_norm(setup.problem, 0.0)
