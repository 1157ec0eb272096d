"""mathur2022 data: the TriValve material parameters as read from an Abaqus deck, bad decks named clearly; the
reproduction without the shipped input exits with a message."""

from __future__ import annotations

import pytest

from skvalve.papers.mathur2022 import reproduce as reproduce_module
from skvalve.papers.mathur2022.data import LEAFLETS, read_trivalve_materials
from skvalve.papers.mathur2022.models import chordae_law, leaflet_law


def _deck(skip: str = "", leaflet_values: str = "1.0e-03, 20.0, 1.5e-04, 12.5") -> str:
    text = []
    for leaflet in (name.capitalize() for name in LEAFLETS):
        if leaflet != skip:
            text += [f"*Material, name=VUANISO_ISO_{leaflet}",
                     "*Anisotropic Hyperelastic, user, formulation=invariant, properties=4", leaflet_values]
        text += [f"*Material, name={leaflet}_Chordae", "*Hyperelastic, OGDEN, N=3",
                 "4.0, 50.0, 7.5, 0.02, 15.0,", "50.1, 7.0e-04, 0.0, 0.0"]
    return "\n".join(text) + "\n"


def test_parameters_come_from_the_deck_in_its_units(tmp_path):
    path = tmp_path / "deck.inp"
    path.write_text(_deck())
    materials = read_trivalve_materials(path)
    assert materials.source == path and set(materials.leaflets) == set(LEAFLETS) == set(materials.chordae)
    leaflet = materials.leaflets["septal"]
    assert (leaflet.c0, leaflet.D, leaflet.c1, leaflet.c2) == (1.0e-3, 20.0, 1.5e-4, 12.5)
    chordae = materials.chordae["anterior"]
    assert chordae.mu == (4.0, 7.5, 15.0) and chordae.alpha == (50.0, 0.02, 50.1) and chordae.D1 == 7.0e-4
    law = leaflet_law(leaflet)  # MPa -> kPa, 1/MPa -> 1/kPa
    assert (law.c0, law.c1, law.c2, law.D) == pytest.approx((1.0, 0.15, 12.5, 0.02), rel=1e-14)
    assert chordae_law(chordae).mu == pytest.approx((4000.0, 7500.0, 15000.0), rel=1e-14)


def test_bad_decks_are_named(tmp_path, monkeypatch):
    path = tmp_path / "deck.inp"
    path.write_text(_deck(skip="Posterior"))
    with pytest.raises(KeyError, match="VUANISO_ISO_Posterior"):
        read_trivalve_materials(path)
    path.write_text(_deck(leaflet_values="1.0e-03, 20.0, 1.5e-04"))
    with pytest.raises(ValueError, match=r"deck.inp:\d+"):  # the reader names the line of the short data
        read_trivalve_materials(path)
    with pytest.raises(FileNotFoundError, match="SKVALVE_TRIVALVE"):
        read_trivalve_materials(tmp_path / "missing.inp")


def test_reproduce_without_the_shipped_input_exits_with_a_message(monkeypatch, capsys):
    module = reproduce_module
    monkeypatch.setattr(module, "trivalve_input", lambda: None)
    with pytest.raises(SystemExit) as exit_info:
        next(module.reproduce(None))
    assert exit_info.value.code == module.EXIT_NO_INPUT == 2
    assert "SKVALVE_TRIVALVE" in capsys.readouterr().err
