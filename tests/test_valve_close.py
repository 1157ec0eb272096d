"""``close_valve`` on the posterior leaflet of the 1.0 diseased valve with its chordae trees.

The single leaflet (3704 hexes, 123 cables) is loaded as in the input (papillary motion, then the transvalvular
pressure with its amplitude), with IPC contact on its whole hex boundary from the start. Checked: an interrupted run
resumed from its kept state repeats the uninterrupted one (1e-10), with its log. Skipped without the shipped input
(Mathur et al. 2022, Texas TriValve 1.0, CC BY-NC-SA 4.0).
"""

from pathlib import Path

import numpy as np
import pytest

from skvalve.io.abaqus import read_model
from skvalve.valve.model import valve_model
from skvalve.valve.options import CloseOptions, HoldOptions
from skvalve.valve.run import close_valve
from skvalve.valve.setup import valve_setup
from skvalve.valve.state import read_state

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "texas_trivalve" / "Diseased_QuasiStatic.inp"
POSTERIOR = 0
pytestmark = pytest.mark.skipif(not DATA.is_file(), reason="Texas TriValve 1.0 input not present (../shared/data)")


@pytest.fixture(scope="module")
def leaflet():
    abaqus = read_model(DATA)
    return abaqus, valve_model(abaqus).submodel([POSTERIOR], chordae=True)


def _setup(leaflet, options):
    abaqus, model = leaflet
    return valve_setup(abaqus, options, model=model)


class _StopAfter:
    """A callback that interrupts the run after ``steps`` accepted steps (as Ctrl-C would)."""

    def __init__(self, steps: int) -> None:
        self.steps = steps

    def __call__(self, state) -> None:
        if state.steps + state.held_steps >= self.steps:
            raise KeyboardInterrupt


def test_interrupted_run_resumes_to_the_uninterrupted_result(leaflet, tmp_path):
    options = CloseOptions(end=0.12, hold=HoldOptions(max_steps=0))  # part of the load path only
    whole = close_valve(leaflet[0], options, out=tmp_path / "whole", setup=_setup(leaflet, options), progress=False)
    with pytest.raises(KeyboardInterrupt):
        close_valve(leaflet[0], options, out=tmp_path / "cut", setup=_setup(leaflet, options), progress=False,
                    callbacks=[_StopAfter(3)])
    kept = read_state(tmp_path / "cut" / "state.npz")
    assert kept.steps == 3 and kept.t < 0.12
    resumed = close_valve(leaflet[0], out=tmp_path / "cut", resume=True, setup=_setup(leaflet, options),
                          progress=False)
    assert resumed.steps == whole.steps and resumed.iterations == whole.iterations
    assert resumed.t == whole.t
    np.testing.assert_allclose(resumed.u, whole.u, rtol=0.0, atol=1e-10 * np.abs(whole.u).max())
    lines = (tmp_path / "cut" / "closure.log").read_text().splitlines()
    assert len(lines) == whole.steps + whole.held_steps


def test_an_end_before_the_pressure_runs_the_path_only(leaflet, tmp_path, caplog):
    """Before the pressure (step time < 0.5) the hanging leaflet has no unique static state: the run keeps the path,
    says so and reports itself not converged, instead of doubling a held pseudo-step that has nothing to do."""
    options = CloseOptions(end=0.05)
    with caplog.at_level("WARNING", logger="skvalve.valve"):
        report = close_valve(leaflet[0], options, out=tmp_path, setup=_setup(leaflet, options), progress=False)
    assert not report.converged and report.held_steps == 0 and report.t == 0.05
    assert "no pressure" in caplog.text
    assert read_state(tmp_path / "state.npz").phase == "hold"
