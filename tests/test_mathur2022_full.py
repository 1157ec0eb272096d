"""``skvalve reproduce mathur2022 --full`` with the closure replaced by stand-ins (no closure is run): each input is
closed in its own folder, resumed from the state kept there, summarised, drawn and measured; the clip input is handed
to the closure with its arms; a closure that stops is measured at its last accepted state, marked incomplete."""

import numpy as np
import pytest

from skvalve.io.abaqus import trivalve_inputs
from skvalve.papers.mathur2022 import reproduce as module
from skvalve.papers.mathur2022.data import TABLE2_AREAS
from skvalve.papers.table import Row, Stage, Written
from skvalve.valve.options import CloseOptions
from skvalve.valve.outputs import closure_measures
from skvalve.valve.run import CloseReport, ClosureFailed
from skvalve.valve.setup import valve_setup
from skvalve.valve.state import KeptState, write_state

INPUTS = trivalve_inputs()
pytestmark = pytest.mark.skipif("1.0-diseased" not in INPUTS, reason="Texas TriValve 1.0 input not found")
FIGURES = ["mathur2022_atrial_stress.png", "mathur2022_coaptation.png", "mathur2022_orifice.png"]


@pytest.fixture(scope="module")
def setup():
    return valve_setup(INPUTS["1.0-diseased"])


class StandIn:
    """``close_valve`` and ``valve_setup`` of the module, recording their calls; the closure returns (or, with
    ``fail``, stops at) the state ``u`` at step time ``t``."""

    def __init__(self, setup, u: np.ndarray, t: float = 1.5, fail: bool = False) -> None:
        self.setup, self.u, self.t, self.fail = setup, u, t, fail
        self.closed: list[dict] = []
        self.options: list = []

    def valve_setup(self, path, options=None):
        self.options.append(options)
        return self.setup if path == INPUTS["1.0-diseased"] else valve_setup(path, options)

    def close_valve(self, path, options=None, out=None, resume=False, progress=True, setup=None, callbacks=()):
        self.closed.append({"path": path, "options": options, "out": out, "resume": resume, "setup": setup})
        if self.fail:
            for callback in callbacks:
                callback(KeptState(self.t, self.u, path.name, CloseOptions(), "path"))
            raise ClosureFailed("load step 7 failed at every length (stand-in)")
        if out is not None:
            out.mkdir(parents=True, exist_ok=True)
            (out / "closure.pvd").write_text("<VTKFile/>")
        return CloseReport(path.name, True, self.t, self.u, 40, 3, 800, 5e-7, False, 1e-4, 0, 0.0, 12.5)


def _run(monkeypatch, stand_in: StandIn, inputs: dict, out):
    monkeypatch.setattr(module, "present_inputs", lambda: inputs)
    monkeypatch.setattr(module, "valve_setup", stand_in.valve_setup)
    monkeypatch.setattr(module, "close_valve", stand_in.close_valve)
    items = list(module.reproduce(out, full=True))
    return ([item.text for item in items if isinstance(item, Stage)],
            {item.quantity: item for item in items if isinstance(item, Row)},
            [item.path for item in items if isinstance(item, Written)])


def _widened(setup) -> np.ndarray:
    """A displacement that stretches the valve horizontally by up to ~10 % (so the rows are not the open ones)."""
    X = setup.model.mesh.p.T
    centre = X.mean(axis=0)
    x = X.copy()
    x[:, :2] = centre[:2] + (1.0 + 0.004 * (X[:, 2:] - X[:, 2].min())) * (X[:, :2] - centre[:2])
    u = np.zeros(setup.problem.space.n_dofs)
    u[: setup.problem.space.n_u] = (x - X).ravel()
    return u


def test_each_input_is_closed_in_its_folder_then_summarised_drawn_and_measured(setup, monkeypatch, tmp_path):
    u = _widened(setup)
    stand_in = StandIn(setup, u)
    inputs = {"1.0-diseased": INPUTS["1.0-diseased"]}
    stages, rows, written = _run(monkeypatch, stand_in, inputs, tmp_path)
    (call,) = stand_in.closed
    assert call["out"] == tmp_path / "1.0-diseased" and call["resume"] is False and call["setup"] is setup
    report = CloseReport("Diseased_QuasiStatic.inp", True, 1.5, u, 40, 3, 800, 5e-7, False, 1e-4, 0, 0.0, 12.5)
    assert f"1.0-diseased: {report.summary()}" in stages
    folder = tmp_path / "1.0-diseased"
    assert written == [folder / "closure.pvd", *(folder / name for name in FIGURES)]
    assert all(path.stat().st_size > 0 for path in written)
    expected = closure_measures(setup, u, 1.5)
    orifice = rows["Table 2 orifice area, diseased (mm²; closed valve)"]
    assert orifice.skvalve == pytest.approx(expected.orifice["mid"], rel=1e-12)
    assert orifice.skvalve > 1.05 * closure_measures(setup, 0 * u, 0.0).orifice["mid"]  # measured at u, not open
    assert rows["Table 2 leaflet area, diseased (mm²)"].paper == TABLE2_AREAS["leaflet"].diseased
    assert len(rows) == 6 and not any("INCOMPLETE" in row.note for row in rows.values())


@pytest.mark.skipif("1.0-clipping" not in INPUTS, reason="Texas TriValve 1.0 clip input not found")
def test_the_clip_input_is_closed_with_its_arms_through_its_three_steps(monkeypatch, tmp_path):
    """The clip repair is no longer refused: its closure gets the setup with the four arms as obstacles, to the end of
    its third step (total time 2.5), in its own folder."""
    clip = valve_setup(INPUTS["1.0-clipping"])
    assert len(clip.model.obstacles) == 4 and clip.model.end_time == pytest.approx(2.5)
    stand_in = StandIn(clip, np.zeros(clip.problem.space.n_dofs), t=2.5)
    monkeypatch.setattr(stand_in, "valve_setup", lambda path, options=None: clip)
    stages, rows, _ = _run(monkeypatch, stand_in, {"1.0-clipping": INPUTS["1.0-clipping"]}, tmp_path)
    (call,) = stand_in.closed
    assert call["out"] == tmp_path / "1.0-clipping" and call["setup"] is clip
    assert any(text.startswith("1.0-clipping: closing Clipping_QuasiStatic.inp") for text in stages)
    assert rows["Table 2 leaflet area, clip (mm²)"].paper == TABLE2_AREAS["leaflet"].clip


def test_a_kept_state_is_resumed_with_its_own_options(setup, monkeypatch, tmp_path):
    folder = tmp_path / "1.0-diseased"
    folder.mkdir()
    kept = CloseOptions(end=0.7)
    write_state(folder / "state.npz", KeptState(0.3, np.zeros(setup.problem.space.n_dofs), INPUTS["1.0-diseased"].name,
                                                kept, "path", 0.01, 5))
    stand_in = StandIn(setup, np.zeros(setup.problem.space.n_dofs), t=0.7)
    stages, _, _ = _run(monkeypatch, stand_in, {"1.0-diseased": INPUTS["1.0-diseased"]}, tmp_path)
    (call,) = stand_in.closed
    assert call["resume"] is True and call["options"] == kept and stand_in.options == [kept]
    assert any(text.startswith("1.0-diseased: resuming") for text in stages)


@pytest.mark.parametrize(("name", "message"), [("Other.inp", "computed from 'Other.inp'.*choose another --out"),
                                               ("Diseased_QuasiStatic.inp", "6 displacement values for the .* dofs")])
def test_a_kept_state_of_another_input_in_the_folder_is_refused(setup, monkeypatch, tmp_path, name, message):
    folder = tmp_path / "1.0-diseased"
    folder.mkdir()
    write_state(folder / "state.npz", KeptState(0.3, np.zeros(6), name, CloseOptions()))
    stand_in = StandIn(setup, np.zeros(6))
    with pytest.raises(module.InputError, match=message):
        _run(monkeypatch, stand_in, {"1.0-diseased": INPUTS["1.0-diseased"]}, tmp_path)
    assert stand_in.closed == []


def test_a_closure_that_stops_is_measured_at_its_last_state_and_marked(setup, monkeypatch, tmp_path):
    u = _widened(setup)
    stand_in = StandIn(setup, u, t=0.9, fail=True)
    stages, rows, written = _run(monkeypatch, stand_in, {"1.0-diseased": INPUTS["1.0-diseased"]}, tmp_path)
    assert any("the closure stopped: load step 7" in text for text in stages)
    assert [path.name for path in written] == FIGURES  # no closure.pvd: the run wrote none
    assert rows and all("INCOMPLETE" in row.note and "step time 0.9" in row.note for row in rows.values())
    area = rows["Table 2 leaflet area, diseased (mm²)"]
    assert area.skvalve == pytest.approx(closure_measures(setup, u, 0.9).leaflet_area["mid"], rel=1e-12)


def test_without_out_nothing_is_written_or_resumed(setup, monkeypatch):
    stand_in = StandIn(setup, np.zeros(setup.problem.space.n_dofs))
    _, rows, written = _run(monkeypatch, stand_in, {"1.0-diseased": INPUTS["1.0-diseased"]}, None)
    (call,) = stand_in.closed
    assert call["out"] is None and call["resume"] is False
    assert written == [] and len(rows) == 6
