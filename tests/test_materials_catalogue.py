"""`skvalve materials`: the catalogue's laws behave as the papers state; the CLI prints and plots readable figures."""

from __future__ import annotations

import functools

import matplotlib.image
import numpy as np
import pytest

from skvalve.analytic.homogeneous import uniaxial
from skvalve.cli import main as cli_main
from skvalve.io.abaqus import trivalve_input
from skvalve.papers.catalogue import catalogue
from skvalve.papers.mathur2022.data import BULK_MODULUS_KPA, CREDIT, POISSON_RATIO
from skvalve.papers.plotting import DPI, MIN_WIDTH_IN

TRIVALVE = trivalve_input()
needs_trivalve = pytest.mark.skipif(TRIVALVE is None, reason="Texas TriValve input (../shared/data) not present")


@functools.cache
def _catalogue():
    return catalogue()  # reads the TriValve input when present: once per test session


def _entry(name_part: str):
    matches = [e for e in _catalogue() if name_part in e.name]
    assert len(matches) == 1, name_part
    return matches[0]


def test_ogden_alpha_two_is_the_neo_hookean_layer():
    """buchanan2014 Sect. 2.2: Eq. 1 with α = 2, N = 1 is the neo-Hookean law (Eq. 3) of the same μ."""
    lam = np.linspace(0.8, 1.4, 7)
    ogden = uniaxial(_entry("alpha = 2").law, lam).cauchy[0]
    neo_hookean = uniaxial(_entry("neo-Hookean").law, lam).cauchy[0]
    np.testing.assert_allclose(ogden, neo_hookean, rtol=1e-12)


def test_bimodular_layers_are_stiffer_in_tension():
    """buchanan2014 Sect. 3.4: both outer layers are stiffer in tension than in compression (Table 3)."""
    for layer in ("fibrosa", "ventricularis"):
        law = _entry(layer).law
        assert law.mu_tension > law.mu_compression


def test_thomas2019_matrix_has_the_small_strain_youngs_modulus():
    """thomas2019 Eq. 10 with G, ν: free uniaxial stress has slope E = 2G(1 + ν) at λ = 1 (linear elasticity)."""
    law = _entry("matrix").law
    h = 1e-6
    sigma = uniaxial(law, np.array([1 - h, 1 + h]), incompressible=False).cauchy[0]
    assert (sigma[1] - sigma[0]) / (2 * h) == pytest.approx(2 * 2.1e3 * (1 + 0.49), rel=1e-6)


@needs_trivalve
def test_texas_trivalve_leaflets_match_the_papers_bulk_modulus_and_are_credited():
    """mathur2022 Sect. 2.8: the file's D gives the bulk modulus 99.67 kPa and, with the small-strain shear
    modulus μ = c0 of Eq. 1 (the exponential term has zero slope at Ī1 = 3), Poisson's ratio 0.495."""
    for entry in _catalogue():
        if entry.paper == "mathur2022":
            assert CREDIT in entry.source and "CC BY-NC-SA 4.0" in entry.source
    leaflets = [e for e in _catalogue() if e.paper == "mathur2022" and "leaflet" in e.name]
    assert len(leaflets) == 3
    for entry in leaflets:
        assert entry.law.bulk_modulus == pytest.approx(BULK_MODULUS_KPA, rel=1e-3)
        K, mu = entry.law.bulk_modulus, entry.law.c0
        assert (3 * K - 2 * mu) / (2 * (3 * K + mu)) == pytest.approx(POISSON_RATIO, abs=5e-6)


def test_cli_prints_without_plotting(tmp_path, capsys):
    out = tmp_path / "figs"
    assert cli_main(["materials", "--no-plot", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Table 3" in text and "BimodularNeoHookean(" in text
    assert ("Texas TriValve 1.0" in text and "OGDEN" in text) if TRIVALVE else "SKVALVE_TRIVALVE" in text
    assert not out.exists()


def test_cli_writes_one_readable_figure_per_group(tmp_path):
    assert cli_main(["materials", "--out", str(tmp_path)]) == 0
    groups = {e.group for e in _catalogue()}
    written = {p.stem for p in tmp_path.glob("*.png")}
    assert written == groups
    for path in tmp_path.glob("*.png"):
        width_px = matplotlib.image.imread(path).shape[1]
        assert width_px >= MIN_WIDTH_IN * DPI, path.name
    assert not list(tmp_path.glob(".*"))  # no temporary files left
