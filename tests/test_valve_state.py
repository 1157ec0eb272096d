"""The closure's options and kept state (skvalve.valve.options, skvalve.valve.state): round trips and bad input."""

import json

import numpy as np
import pytest

from skvalve.cli import main
from skvalve.fem.contact.ipc import Friction
from skvalve.fem.solvers.trust_region import TrustRegionControl
from skvalve.valve.options import CloseOptions, ContactOptions, HoldOptions, ModelOptions, StepOptions
from skvalve.valve.state import FORMAT, KeptState, StateError, read_state, write_state


def _options() -> CloseOptions:
    return CloseOptions(ModelOptions(insertion="node", cable_compression=False, corner_threshold=0.2),
                        ContactOptions(dhat=0.05, friction=Friction(0.2, 1e-3), tie_within=0.03),
                        StepOptions(first=0.02, largest=0.1), HoldOptions(rtol=1e-7), end=0.5, solver="scipy")


def test_options_round_trip_through_json():
    options = _options()
    assert CloseOptions.from_dict(json.loads(json.dumps(options.as_dict()))) == options
    assert CloseOptions.from_dict(CloseOptions().as_dict()) == CloseOptions()


@pytest.mark.parametrize("make, name", [
    (lambda: ContactOptions(dhat=0.0), "dhat"),
    (lambda: ContactOptions(pressure_factor=float("nan")), "pressure_factor"),
    (lambda: StepOptions(first=0.5, largest=0.1), "first"),
    (lambda: StepOptions(max_iter=0), "max_iter"),
    (lambda: StepOptions(growth=0.5), "growth"),
    (lambda: HoldOptions(max_steps=-1), "max_steps"),
    (lambda: HoldOptions(growth=0.5), "growth"),
    (lambda: ModelOptions(insertion="glue"), "insertion"),
    (lambda: ModelOptions(corner_threshold=1.0), "corner_threshold"),
    (lambda: ModelOptions(corner_threshold=-0.1), "corner_threshold"),
    (lambda: ContactOptions(tie_within=-1.0), "tie_within"),
    (lambda: CloseOptions(end=-1.0), "end"),
])
def test_bad_option_names_its_field(make, name):
    with pytest.raises(ValueError, match=name):
        make()


def _state(n: int = 12) -> KeptState:
    rng = np.random.default_rng(3)
    control = TrustRegionControl(0.3, 1e-4, 2e-4, rng.standard_normal(n), steps=3, attempts=5, retry_after=9,
                                 energy_changes=[-0.5, -0.25, -1e-3])
    return KeptState(0.375, rng.standard_normal(n), "Valve.inp", _options(), "hold", 0.125, 17, 3, 211, 2.5e-5,
                     {"contact/stiffness": np.array(1.25), "contact/lag": rng.standard_normal((4, 3))}, 1, control)


def test_state_round_trip_is_exact(tmp_path):
    state = _state()
    write_state(tmp_path / "state.npz", state)
    back = read_state(tmp_path / "state.npz", input_name="Valve.inp", n_dofs=12)
    assert back.u.tobytes() == state.u.tobytes()  # bit for bit: a resumed run repeats the uninterrupted one
    assert (back.t, back.phase, back.increment, back.steps, back.held_steps, back.iterations) == \
        (state.t, state.phase, state.increment, state.steps, state.held_steps, state.iterations)
    assert back.relative_residual == state.relative_residual and back.options == state.options
    assert set(back.terms) == set(state.terms)
    for key, value in state.terms.items():
        np.testing.assert_array_equal(back.terms[key], value)
    assert back.held_stage == 1  # the held load's trust region resumes with its own controller
    c, d = back.control, state.control
    assert d.local.tobytes() == c.local.tobytes() and c.energy_changes == d.energy_changes
    assert (c.radius, c.shift, c.fallback, c.steps, c.attempts, c.retry_below, c.retry_after) == \
        (d.radius, d.shift, d.fallback, d.steps, d.attempts, d.retry_below, d.retry_after)
    assert [p.name for p in tmp_path.iterdir()] == ["state.npz"]  # no temporary left behind


def test_state_errors_name_the_file_and_the_fault(tmp_path):
    path = tmp_path / "state.npz"
    with pytest.raises(StateError, match="no such file"):
        read_state(path)
    path.write_bytes(b"not a zip archive")
    with pytest.raises(StateError, match="not a readable .npz"):
        read_state(path)
    np.savez(path, t=0.5, u=np.zeros(3))  # a kept state of the old benchmark: no format, input or options
    with pytest.raises(StateError, match="missing format, input, options"):
        read_state(path)
    write_state(path, _state())
    with pytest.raises(StateError, match="computed from 'Valve.inp', not from 'Other.inp'"):
        read_state(path, input_name="Other.inp")
    with pytest.raises(StateError, match="12 displacement values for a model of 30 dofs"):
        read_state(path, n_dofs=30)
    with np.load(path) as data:
        content = {key: data[key] for key in data.files}
    np.savez(path, **{**content, "format": 3})  # keyed by term position: still read (Problem.restore maps it)
    assert read_state(path).t == 0.375
    np.savez(path, **{**content, "format": FORMAT + 1})
    with pytest.raises(StateError, match=f"format {FORMAT + 1}, this version reads 3 and 4"):
        read_state(path)


def test_state_phase_is_checked():
    with pytest.raises(StateError, match="phase"):
        KeptState(0.0, np.zeros(3), "x", CloseOptions(), phase="closing")


def test_cli_close_refuses_missing_file_and_bad_state(tmp_path, capsys):
    assert main(["valve", "close", str(tmp_path / "nope.inp"), "--out", str(tmp_path / "out")]) == 2
    assert "is not a file" in capsys.readouterr().err
    deck = tmp_path / "bad.inp"
    deck.write_text("*Node\n1, 0., 0., 0.\n2, 1., x, 0.\n")
    assert main(["valve", "close", str(deck), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "bad.inp" in err and "3" in err
    out = tmp_path / "resume"
    out.mkdir()
    (out / "state.npz").write_bytes(b"garbage")
    assert main(["valve", "close", str(deck), "--out", str(out), "--resume", "--quiet"]) == 2
    assert "not a readable .npz" in capsys.readouterr().err
