"""``skvalve reproduce mathur2022 --state``: kept closure states are read with clear errors for bad files, rebuilt
with the options they record, and measured (a state short of the end is marked incomplete)."""

import json
from dataclasses import asdict

import numpy as np
import pytest

from skvalve.io.abaqus import read_model, trivalve_input
from skvalve.papers.mathur2022.reproduce import KEPT_STATE_OPTIONS, read_kept_state, reproduce
from skvalve.papers.table import InputError, Row, Stage, Status
from skvalve.valve.closure import ClosureOptions, closure_setup
from skvalve.valve.model import valve_model
from skvalve.valve.outputs import closure_measures


def test_a_state_without_options_is_measured_with_the_converged_contact(tmp_path):
    path = tmp_path / "kept.npz"
    np.savez(path, t=1.5, u=np.zeros(6))
    kept = read_kept_state(path)
    assert kept.t == 1.5 and kept.options is None
    model = type("Model", (), {"pressures": [], "end_time": 1.5})()
    options = kept.closure_options(model)
    assert {key: getattr(options, key) for key in KEPT_STATE_OPTIONS} == KEPT_STATE_OPTIONS


def test_recorded_options_come_back_equal(tmp_path):
    recorded = ClosureOptions(contact_depth=0.3, contact_barrier=0.2, cable_stiffening=(0.1, 0.2))
    path = tmp_path / "kept.npz"
    np.savez(path, t=1.0, u=np.ones(3), options=json.dumps(asdict(recorded)))
    assert read_kept_state(path).closure_options(None) == recorded


@pytest.mark.parametrize(("content", "message"), [
    ({"t": 1.5}, "no u"),
    ({"t": 1.5, "u": np.array([0.0, np.nan])}, "finite"),
    ({"t": 1.5, "u": np.zeros((2, 3))}, "one-dimensional"),
    ({"t": 1.5, "u": np.zeros(3), "options": "[1, 2]"}, "JSON object"),
    ({"t": 1.5, "u": np.zeros(3), "options": "{not json"}, "not a readable"),
])
def test_bad_kept_states_are_refused_naming_the_file(tmp_path, content, message):
    path = tmp_path / "bad.npz"
    np.savez(path, **content)
    with pytest.raises(InputError, match=message) as info:
        read_kept_state(path)
    assert str(path) in str(info.value)


def test_a_missing_or_foreign_file_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="last_state.npz"):
        read_kept_state(tmp_path / "absent.npz")
    text = tmp_path / "notes.npz"
    text.write_text("not a zip")
    with pytest.raises(InputError, match="notes.npz"):
        read_kept_state(text)


@pytest.mark.skipif(trivalve_input() is None, reason="Texas TriValve input not found (../shared/data)")
def test_kept_states_of_the_valve_are_checked_and_measured(tmp_path):
    wrong = tmp_path / "wrong.npz"
    np.savez(wrong, t=1.5, u=np.zeros(12))
    with pytest.raises(InputError, match="dofs"):
        list(reproduce(state=wrong))
    model = valve_model(read_model(trivalve_input()))
    setup = closure_setup(options=ClosureOptions.for_relaxation(model, **KEPT_STATE_OPTIONS), model=model)
    zero = tmp_path / "zero.npz"
    np.savez(zero, t=0.0, u=np.zeros(setup.problem.space.n_dofs))
    items = list(reproduce(state=zero))
    stages = " ".join(item.text for item in items if isinstance(item, Stage))
    assert "not converged" in stages and "step time 0" in stages and "input not recorded" in stages
    rows = {row.quantity: row for row in items if isinstance(row, Row)}
    area = rows["Table 2 leaflet area, diseased (mm²)"]
    opened = closure_measures(setup, np.zeros(setup.problem.space.n_dofs), 0.0).leaflet_area["mid"]
    assert area.skvalve == pytest.approx(opened, rel=1e-12)  # zero displacement: the open leaflets
    assert "areal stretch from the open configuration" in area.note and "1.00 here" in area.note
    assert "kept state zero.npz" in area.note and area.status is Status.DIFFERS
    assert rows["Table 2 coaptation area, diseased (mm²)"].skvalve == 0.0  # nothing touches when open
    assert rows["Table 2 orifice area, diseased (mm²; closed valve)"].skvalve == pytest.approx(
        closure_measures(setup, np.zeros(setup.problem.space.n_dofs), 0.0).orifice["mid"], rel=1e-12)


@pytest.mark.skipif(trivalve_input() is None, reason="Texas TriValve input not found (../shared/data)")
def test_a_state_of_another_input_is_refused_by_name(tmp_path):
    """The annuloplasty valve shares the diseased valve's mesh, so only the recorded input name tells them apart."""
    path = tmp_path / "annuloplasty.npz"
    np.savez(path, t=1.5, u=np.zeros(3), input="Annuloplasty_QuasiStatic.inp")
    assert read_kept_state(path).input == "Annuloplasty_QuasiStatic.inp"
    with pytest.raises(InputError, match="computed from Annuloplasty_QuasiStatic.inp, not Diseased_QuasiStatic.inp"):
        next(reproduce(state=path))
