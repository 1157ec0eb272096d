"""`skvalve materials`: catalogue entries carry the papers' parameters; the CLI prints and plots."""

from __future__ import annotations

import pytest

from skvalve.cli import main as cli_main
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden
from skvalve.materials.catalogue import TEXAS, catalogue


def _entry(name_part: str):
    matches = [e for e in catalogue() if name_part in e.name]
    assert len(matches) == 1, name_part
    return matches[0]


def test_paper_values():
    assert _entry("neo-Hookean").law == IncompressibleNeoHookean(45.0)  # buchanan2014 Sect. 3.2
    fibrosa = _entry("fibrosa").law
    assert isinstance(fibrosa, BimodularNeoHookean)
    assert (fibrosa.mu_tension, fibrosa.mu_compression) == (139.5, 29.55)  # buchanan2014 Table 3
    ventricularis = _entry("ventricularis").law
    assert (ventricularis.mu_tension, ventricularis.mu_compression) == (65.0, 16.74)
    matrix = _entry("matrix").law
    assert isinstance(matrix, NeoHookean)
    assert matrix.mu == 2.1 and matrix.poisson_ratio == pytest.approx(0.49, rel=1e-14)  # thomas2019
    alpha2 = _entry("alpha = 2").law
    assert alpha2 == Ogden((45.0,), (2.0,))  # Fig. 3 family, mu = 45 kPa


def test_texas_trivalve_values_are_converted_to_kpa_and_credited():
    anterior = _entry("anterior leaflet")
    law = anterior.law
    assert isinstance(law, LeeSacks) and not law.published_equation
    # VUANISO_ISO (C0, D, C1, C2) = (1e-3, 20.0669, 1.188659e-4, 15.260081) MPa -> kPa
    assert (law.c0, law.c1, law.c2, law.D) == pytest.approx((1.0, 0.1188659, 15.260081, 20.0669e-3), rel=1e-14)
    assert anterior.law.bulk_modulus == pytest.approx(99.67, rel=1e-3)  # mathur2022 Sect. 2.6: 99.67 kPa
    chordae = _entry("anterior chordae")
    assert chordae.law.mu[0] == pytest.approx(4212.040401935249, rel=1e-14)
    for entry in catalogue():
        if entry.paper == "mathur2022":
            assert TEXAS in entry.source and "CC BY-NC-SA 4.0" in entry.source
    assert {e.paper for e in catalogue()} == {"buchanan2014", "thomas2019", "mathur2022"}
    assert sum("leaflet" in e.name and e.paper == "mathur2022" for e in catalogue()) == 3


def test_cli_prints_without_plotting(tmp_path, capsys):
    out = tmp_path / "figs"
    assert cli_main(["materials", "--no-plot", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Table 3" in text and "Texas TriValve 1.0" in text and "OGDEN" in text
    assert not out.exists()


def test_cli_writes_one_figure_per_group(tmp_path):
    assert cli_main(["materials", "--out", str(tmp_path)]) == 0
    groups = {e.group for e in catalogue()}
    written = {p.stem for p in tmp_path.glob("*.png")}
    assert written == groups
    assert all(p.stat().st_size < 100_000 for p in tmp_path.glob("*.png"))
