"""``skvalve reproduce mathur2022 --state``: kept states of ``skvalve valve close`` (format 2) are matched to their
input by name and size, rebuilt with the options they record, measured beside the input's paper column, and refused
with the file named when they are not readable or fit no input."""

import numpy as np
import pytest

from skvalve.cli import main
from skvalve.io.abaqus import trivalve_inputs
from skvalve.papers.mathur2022.data import PRESSURE_HEALTHY_MMHG, TABLE2_AREAS, TABLE3_CENTRE_STRESS
from skvalve.papers.mathur2022.reproduce import present_inputs, reproduce, state_input
from skvalve.papers.table import InputError, Row, Stage, Status, Written
from skvalve.valve.options import CloseOptions, ContactOptions
from skvalve.valve.outputs import closure_measures
from skvalve.valve.setup import valve_setup
from skvalve.valve.state import KeptState, write_state

INPUTS = trivalve_inputs()
DISEASED = "Diseased_QuasiStatic.inp"
needs_10 = pytest.mark.skipif("1.0-diseased" not in INPUTS, reason="Texas TriValve 1.0 input not found")


def _state(path, n: int, name: str = DISEASED, phase: str = "done", options: CloseOptions | None = None,
           terms: dict | None = None):
    write_state(path, KeptState(1.5, np.zeros(n), name, options or CloseOptions(), phase, terms=terms or {}))
    return path


def _items(**kwargs) -> tuple[list[Stage], dict[str, Row], list[Written]]:
    items = list(reproduce(**kwargs))
    return ([item for item in items if isinstance(item, Stage)],
            {item.quantity: item for item in items if isinstance(item, Row)},
            [item for item in items if isinstance(item, Written)])


@pytest.fixture(scope="module")
def diseased():
    return valve_setup(INPUTS["1.0-diseased"]) if "1.0-diseased" in INPUTS else None


@needs_10
def test_a_converged_state_gives_the_diseased_column_measured_at_its_displacement(diseased, tmp_path):
    n = diseased.problem.space.n_dofs
    state = _state(tmp_path / "state.npz", n, options=CloseOptions(contact=ContactOptions(dhat=0.05)))
    stages, rows, written = _items(out=tmp_path / "out", state=state)
    expected = closure_measures(diseased, np.zeros(n), 1.5)  # zero displacement: the open leaflets at the end load
    assert len(rows) == 6
    orifice = rows["Table 2 orifice area, diseased (mm²; closed valve)"]
    assert orifice.paper == TABLE2_AREAS["orifice"].diseased
    assert orifice.skvalve == pytest.approx(expected.orifice["mid"], rel=1e-12)
    assert orifice.status is Status.AGREES  # the input holds the annulus: the open orifice is within 3 % of 870 mm²
    area = rows["Table 2 leaflet area, diseased (mm²)"]
    assert area.skvalve == pytest.approx(expected.leaflet_area["mid"], rel=1e-12)
    assert "1.00 here" in area.note and area.status is Status.DIFFERS
    coaptation = rows["Table 2 coaptation area, diseased (mm²)"]
    assert coaptation.skvalve == 0.0 and coaptation.paper == TABLE2_AREAS["coaptation"].diseased
    assert "dhat = 0.05 mm" in coaptation.note and "penalty" not in coaptation.note  # the state's own options
    for leaflet in ("anterior", "posterior", "septal"):
        row = rows[f"Table 3 centre max principal Cauchy stress, {leaflet}, diseased (kPa)"]
        assert row.paper == TABLE3_CENTRE_STRESS[leaflet].diseased and row.skvalve == 0.0
    assert not any("INCOMPLETE" in row.note for row in rows.values())
    text = " ".join(stage.text for stage in stages)
    assert "phase 'done'" in text and "1.0-diseased" in text and "CC BY-NC-SA 4.0" in text
    assert "recomputed" in text  # the static residual of the state, not only the recorded one
    names = sorted(item.path.name for item in written)
    assert names == ["mathur2022_atrial_stress.png", "mathur2022_coaptation.png", "mathur2022_kept_state.pvd",
                     "mathur2022_orifice.png"]
    assert (tmp_path / "out" / "mathur2022_kept_state_0000.vtu").stat().st_size > 100_000


@needs_10
def test_a_state_short_of_the_end_is_marked_incomplete_in_every_row(diseased, tmp_path):
    state = _state(tmp_path / "state.npz", diseased.problem.space.n_dofs, phase="hold")
    _, rows, written = _items(state=state)
    assert written == []  # no out: nothing written
    assert rows and all("INCOMPLETE" in row.note and "phase 'hold'" in row.note for row in rows.values())


@needs_10
def test_the_recorded_terms_state_is_restored(diseased, tmp_path):
    n = diseased.problem.space.n_dofs
    k = diseased.problem.terms.index(diseased.contact)
    terms = {f"{k}/stiffness": np.array(0.123), f"{k}/u": np.zeros(n), f"{k}/t": np.array(1.5)}
    key, kept, setup = state_input(_state(tmp_path / "state.npz", n, terms=terms), present_inputs())
    assert key == "1.0-diseased" and kept.t == 1.5
    assert setup.contact.stiffness == 0.123 and diseased.contact.stiffness != 0.123


@needs_10
def test_the_annuloplasty_state_is_compared_with_its_own_column(diseased, tmp_path):
    """The annuloplasty valve shares the diseased valve's mesh: the recorded name picks the column."""
    if "1.0-annuloplasty" not in INPUTS:
        pytest.skip("annuloplasty input not present")
    state = _state(tmp_path / "state.npz", diseased.problem.space.n_dofs, name="Annuloplasty_QuasiStatic.inp")
    _, rows, _ = _items(state=state)
    orifice = rows["Table 2 orifice area, annuloplasty (mm²; closed valve)"]
    assert orifice.paper == TABLE2_AREAS["orifice"].annuloplasty
    assert orifice.status is Status.DIFFERS and "LINK MPCs" in orifice.note  # the ring has not pulled the annulus in
    assert rows["Table 3 centre max principal Cauchy stress, septal, annuloplasty (kPa)"].paper == \
        TABLE3_CENTRE_STRESS["septal"].annuloplasty


@pytest.mark.parametrize(("key", "column", "label", "reason"), [
    ("1.1-healthy", "healthy", "healthy, TTV 1.1", f"{PRESSURE_HEALTHY_MMHG} mmHg"),
    ("1.1-diseased", "diseased", "diseased, TTV 1.1", "another donor valve"),
])
def test_a_state_of_a_ttv_1_1_input_is_beside_the_paper_column_with_the_donor_named(tmp_path, key, column, label,
                                                                                    reason):
    if key not in INPUTS:
        pytest.skip(f"{key} input not present")
    n = valve_setup(INPUTS[key]).problem.space.n_dofs
    _, rows, _ = _items(state=_state(tmp_path / "state.npz", n, name=INPUTS[key].name))
    area = rows[f"Table 2 leaflet area, {label} (mm²)"]
    assert area.paper == getattr(TABLE2_AREAS["leaflet"], column)
    assert all("another donor valve" in row.note and reason in row.note and row.expected_difference is not None
               for row in rows.values())


@needs_10
def test_states_that_fit_no_input_are_refused_naming_the_file_and_the_sizes(diseased, tmp_path):
    n = diseased.problem.space.n_dofs
    wrong = _state(tmp_path / "wrong.npz", 12)
    with pytest.raises(InputError, match=rf"wrong.npz: 12 displacement values fits none .*1.0-diseased: {n}"):
        list(reproduce(state=wrong))
    if "1.1-healthy" in INPUTS:  # the right size for the 1.0 valves, the name of the 1.1 healthy one
        other = _state(tmp_path / "other.npz", n, name="Healthy_QuasiStatic.inp")
        with pytest.raises(InputError, match=r"other.npz: .* fits none .*1.1-healthy"):
            list(reproduce(state=other))
    if "1.0-clipping" in INPUTS:  # the clip input is modelled: a state of the wrong size is refused as any other
        clip = _state(tmp_path / "clip.npz", 12, name="Clipping_QuasiStatic.inp")
        with pytest.raises(InputError, match=r"clip.npz: 12 displacement values fits none .*1.0-clipping"):
            list(reproduce(state=clip))


def test_a_state_of_an_unknown_input_is_refused_naming_both(tmp_path):
    state = _state(tmp_path / "mitral.npz", 6, name="Mitral_QuasiStatic.inp")
    with pytest.raises(InputError, match=r"mitral.npz: computed from 'Mitral_QuasiStatic.inp', which is none of"):
        list(reproduce(state=state))


@pytest.mark.parametrize("damage", ["garbage", "truncated", "version 1", "missing"])
def test_unreadable_states_are_refused_naming_the_file(tmp_path, damage):
    path = tmp_path / "kept.npz"
    if damage == "garbage":
        path.write_bytes(b"not a zip archive at all")
    elif damage == "truncated":
        _state(path, 300)
        path.write_bytes(path.read_bytes()[:200])
    elif damage == "version 1":  # benchmarks/trivalve_closure.py before skvalve.valve.run: t and u only
        np.savez(path, t=1.5, u=np.zeros(6))
    with pytest.raises(InputError, match=str(path)):
        list(reproduce(state=path))


def test_the_command_line_exits_2_with_the_file_named(tmp_path, capsys):
    path = tmp_path / "kept.npz"
    path.write_bytes(b"garbage")
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path / "out"), "--state", str(path)]) == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("skvalve: reproduce mathur2022: kept state") and str(path) in last
