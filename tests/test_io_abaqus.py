"""Abaqus material reader, on a small hand-written deck and (if present) on the Texas TriValve file."""

import pytest

from skvalve.io.abaqus import read_materials, trivalve_input
from skvalve.papers.catalogue import catalogue

DECK = """** comment
*Material, name=Chord
*Density
1e-9
*Hyperelastic, OGDEN, N=2
1.5, 2.0, 0.25, -4.0,
1e-3, 0
*Material, name=Leaf
*anisotropic hyperelastic, user,formulation=invariant, properties=4
1.0e-03, 20.0, 1.0e-4, 15.0
*Step, name=Load
*Static
0.1, 1.0
"""


def test_reads_options_and_data_across_lines(tmp_path):
    path = tmp_path / "deck.inp"
    path.write_text(DECK)
    mats = read_materials(path)
    assert set(mats) == {"Chord", "Leaf"}
    ogden = mats["Chord"].option("hyperelastic")
    assert ogden.parameters == {"n": "2"} and "ogden" in ogden.keyword
    assert ogden.data == [1.5, 2.0, 0.25, -4.0, 1e-3, 0.0]
    assert mats["Leaf"].option("anisotropic").data == [1e-3, 20.0, 1e-4, 15.0]
    assert mats["Chord"].option("density").data == [1e-9]
    with pytest.raises(KeyError, match="Leaf"):
        mats["Leaf"].option("density")


def test_bad_number_names_file_and_line(tmp_path):
    path = tmp_path / "bad.inp"
    path.write_text("*Material, name=M\n*Density\n1e-9x\n")
    with pytest.raises(ValueError, match=r"bad.inp:3"):
        read_materials(path)


TRIVALVE = trivalve_input()


@pytest.mark.skipif(TRIVALVE is None, reason="Texas TriValve input (../shared/data/texas_trivalve) not present")
def test_catalogue_equals_the_texas_trivalve_file():
    """Mathur et al. 2022, Texas TriValve 1.0 (CC BY-NC-SA 4.0): catalogue kPa values = file MPa values x 1000."""
    mats = read_materials(TRIVALVE)
    entries = {e.name: e.law for e in catalogue() if e.paper == "mathur2022"}
    for leaflet in ("Anterior", "Posterior", "Septal"):
        c0, D, c1, c2 = mats[f"VUANISO_ISO_{leaflet}"].option("anisotropic").data
        law = entries[f"mathur2022 {leaflet.lower()} leaflet, Lee-Sacks"]
        assert (law.c0, law.c1, law.c2, law.D) == pytest.approx((1e3 * c0, 1e3 * c1, c2, D / 1e3), rel=1e-12)
    for chord in ("Anterior", "Posterior", "Septal"):
        data = mats[f"{chord}_Chordae"].option("hyperelastic").data
        law = entries[f"mathur2022 {chord.lower()} chordae, Ogden N = 3"]
        assert law.mu == pytest.approx([1e3 * m for m in data[0:6:2]], rel=1e-12)
        assert law.alpha == pytest.approx(data[1:6:2], rel=1e-12)
        assert law.D[0] == pytest.approx(data[6] / 1e3, rel=1e-12)
