"""valve_model refuses inputs it cannot represent (skvalve.valve.support), naming keyword and file line: a small deck
with a free rigid clip arm (its reference node held in no step), a connector that would act, bonded contact with the
rigid surface and a prescribed rotation of that free arm in a second step; the shipped 1.0 clip repair is accepted,
its bonded contact noted as approximated (skipped when absent: Texas TriValve, Mathur et al. 2022, CC BY-NC-SA 4.0).
The clip arms that are modelled are checked in tests/test_valve_clip.py."""

import logging

import pytest

from skvalve.io.abaqus import read_model, trivalve_inputs
from skvalve.valve.model import valve_model
from skvalve.valve.support import UnsupportedInputError, check_supported, unsupported_features

BASE = [
    "*Node", "1, 0., 0., 0.", "2, 1., 0., 0.", "3, 1., 1., 0.", "4, 0., 1., 0.",
    "5, 0., 0., 1.", "6, 1., 0., 1.", "7, 1., 1., 1.", "8, 0., 1., 1.",
    "*Element, type=C3D8R, elset=Leaf", "1, 1, 2, 3, 4, 5, 6, 7, 8",
    "*Solid Section, elset=Leaf, material=M",
    "*Surface, type=ELEMENT, name=Top", "Leaf, S2",
    "*Material, name=M", "*Anisotropic Hyperelastic, user, formulation=invariant, type=compressible, properties=4",
    "0.001, 20., 0.0001, 15.",
    "*Boundary", "1, 1, 3", "2, 1, 3", "3, 1, 3", "4, 1, 3",
    "*Step, name=Close", "*Static", "0.5, 1.", "*Dsload", "Top, P, 0.001", "*End Step",
]
CLIP = [
    "*Node", "11, 0., 0., 2.", "12, 1., 0., 2.", "13, 1., 1., 2.", "14, 0., 1., 2.",
    "20, 0.5, 0.5, 2.5", "21, 3., 3., 3.",
    "*Element, type=R3D4, elset=Arm", "11, 11, 12, 13, 14",
    "*Nset, nset=RP", "20", "*Rigid Body, ref node=RP, elset=Arm",
    "*Surface, type=ELEMENT, name=Jaw", "Arm, SNEG",
    "*Element, type=CONN3D2, elset=Wire", "12, 20, 21", "*Connector Section, elset=Wire", "Slot,",
    "*Surface Interaction, name=Rough", "*Friction, rough", "*Surface Behavior, no separation",
    "*Step, name=Capture", "*Static", "0.5, 1.",
    "*Boundary", "RP, 6, 6, 0.5",
    "*Contact Pair, interaction=Rough", "Jaw, Top",
    "*End Step",
]


def _lines(text: str, *starts: str) -> list[int]:
    """1-based line numbers of the first line starting with each of ``starts`` (counted here, by hand)."""
    lines = text.splitlines()
    return [next(k + 1 for k, line in enumerate(lines) if line.startswith(start)) for start in starts]


def test_a_clip_deck_is_refused_with_every_keyword_and_line(tmp_path):
    text = "\n".join(BASE + CLIP) + "\n"
    path = tmp_path / "clip.inp"
    path.write_text(text)
    abaqus = read_model(path)
    found = [(f.keyword, f.location.line) for f in unsupported_features(abaqus)]
    expected = list(zip(["*Element, type=R3D4", "*Rigid Body", "*Element, type=CONN3D2", "*Connector Section",
                         "*Surface Interaction", "*Boundary", "*Contact Pair"],
                        _lines(text, "*Element, type=R3D4", "*Rigid Body", "*Element, type=CONN3D2",
                               "*Connector Section", "*Surface Interaction", "RP, 6, 6", "Jaw, Top"), strict=True))
    assert found == expected
    with pytest.raises(UnsupportedInputError) as info:
        valve_model(abaqus)
    message = str(info.value)
    assert "7 keyword(s)" in message and f"clip.inp:{expected[1][1]}: *Rigid Body" in message
    assert "dof(s) 1, 2, 3, 4, 5, 6 not prescribed in every step" in message and "free rigid body" in message
    assert "node(s) 20, 21 not held at zero in dofs 1-3" in message
    assert "rough and *Surface Behavior, no separation" in message
    # step 1 alone does not touch the clip: built, with the clip listed in the notes; step 2 alone is refused
    model = valve_model(abaqus, partial=True)
    assert model.counts()["hexes"] == 1 and model.counts()["pressure_facets"] == 1 and model.obstacles == []
    assert sum(note.startswith("not modelled (partial build of step 0)") for note in model.notes) == 4
    with pytest.raises(UnsupportedInputError, match=r"3 keyword\(s\)") as info:
        valve_model(abaqus, step=1, partial=True)
    assert {f.keyword for f in info.value.features} == {"*Boundary", "*Contact Pair", "*Surface Interaction"}


def test_a_supported_deck_builds_and_reports_nothing(tmp_path):
    path = tmp_path / "plain.inp"
    path.write_text("\n".join(BASE) + "\n")
    abaqus = read_model(path)
    assert unsupported_features(abaqus) == []
    assert valve_model(abaqus).counts()["hexes"] == 1


@pytest.mark.skipif("1.0-clipping" not in trivalve_inputs(), reason="Texas TriValve 1.0 clipping input not found")
def test_the_shipped_clip_repair_is_accepted_with_its_bonded_contact_noted():
    """Four rigid arms, two inert Slot connectors, two further steps and four arm rotations (65 and 35 degrees) are
    modelled; the bonded Rough_Interaction (line 75482, found with grep) is noted as the barrier with a tie after
    capture, and so are the arms' contact starting in step 2 (the first Contact Pair with an arm, line 76531)."""
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    abaqus = read_model(trivalve_inputs()["1.0-clipping"])
    assert unsupported_features(abaqus) == []
    notes = check_supported(abaqus)
    assert [note.split(": ")[0].rsplit(":", 1)[1] for note in notes] == ["75482", "76531"]
    assert "*Friction, rough and *Surface Behavior, no separation" in notes[0] and "tie after capture" in notes[0]
    # step 1 alone (the earlier partial build) still builds: the arms are parked there
    model = valve_model(abaqus, partial=True)
    assert model.end_time == 1.0 and len(model.obstacles) == 4
    assert {arm.angle.at(1.0) for arm in model.arms} == {0.0}
