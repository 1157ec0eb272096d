"""buchanan2014 reproduction: models against independent solutions, analytic rows, figures, CLI."""

from __future__ import annotations

import matplotlib.image
import numpy as np
import pytest

from skvalve.analytic.rivlin import bend
from skvalve.cli import main
from skvalve.papers.buchanan2014 import data, figures
from skvalve.papers.buchanan2014 import fe as b14_fe
from skvalve.papers.buchanan2014 import models as b14
from skvalve.papers.buchanan2014 import reproduce as b14_reproduce
from skvalve.papers.buchanan2014.rows import analytic_rows, closed_form_rows
from skvalve.papers.plotting import DPI, MIN_WIDTH_IN
from skvalve.papers.table import Status


def test_bilayer_layers_are_ordered_ventricularis_first():
    layers = b14.bimodular_bilayer(1.0)
    assert [t for t, _ in layers] == pytest.approx([0.4, 0.6])
    assert layers[0][1].mu_tension == 65.0 and layers[1][1].mu_compression == 29.55


def test_neutral_axis_moves_toward_the_stiff_tension_side():
    """AC stretches the fibrosa (stiff in tension): NA above mid-thickness; WC below it."""
    layers = b14.bimodular_bilayer()
    assert b14.neutral_axis(layers, "AC", 0.2) > 0.5 > b14.neutral_axis(layers, "WC", 0.2)
    with pytest.raises(ValueError, match="AC"):
        b14.neutral_axis(layers, "sideways", 0.2)


def test_neutral_axis_small_curvature_matches_linear_bimodular_beam():
    """Independent linear balance Σ E ∫ (y − y_n) dy = 0 with E = E± by side, solved in closed form per case."""
    (mv_t, mv_c), (mf_t, mf_c) = data.TABLE3["ventricularis"], data.TABLE3["fibrosa"]
    # AC: NA in the fibrosa (y_n > 0.4): mv_c·∫0^.4 + mf_c·∫.4^yn + mf_t·∫yn^1 of (y − y_n) = 0, quadratic in y_n
    from scipy.optimize import brentq

    def ac(yn):
        return (mv_c * ((0.4 - yn) ** 2 - yn**2) / 2 - mf_c * (0.4 - yn) ** 2 / 2 + mf_t * (1 - yn) ** 2 / 2)

    def wc(yn):  # WC: stretched below y_n; the linear NA lies just inside the fibrosa (y_n > 0.4)
        return (mv_t * ((0.4 - yn) ** 2 - yn**2) / 2 - mf_t * (0.4 - yn) ** 2 / 2 + mf_c * (1 - yn) ** 2 / 2)

    layers = b14.bimodular_bilayer(1.0)
    assert b14.neutral_axis(layers, "AC", 1e-4) == pytest.approx(brentq(ac, 0.4, 1.0), abs=1e-4)
    assert b14.neutral_axis(layers, "WC", 1e-4) == pytest.approx(brentq(wc, 0.4, 1.0), abs=1e-4)


def test_inverse_tension_modulus_reproduces_its_target():
    mu = b14.tension_modulus_for_neutral_axis("AC", 0.79)
    assert mu > data.TABLE3["fibrosa"][0]
    layers = [(0.4 * 0.318, b14.bimodular_bilayer()[0][1]),
              (0.6 * 0.318, type(b14.bimodular_bilayer()[1][1])(mu, 29.55, (1.0, 0.0, 0.0)))]
    assert b14.neutral_axis(layers, "AC", 0.2) == pytest.approx(0.79, abs=1e-5)


def test_unbonded_limit_has_one_neutral_axis_per_layer():
    layers = b14.trilayer(1e-3, 0.4)
    Y = np.linspace(0, 0.4, 401)
    lam = b14.unbonded_stretch(layers, 0.2, Y)
    # every homogeneous layer bent alone: λ_top·λ_bottom = 1 and λ = 1 inside each layer
    for y0, y1 in ((0.0, 0.1), (0.1, 0.22), (0.22, 0.4)):
        inside = (Y > y0 + 1e-9) & (Y < y1 - 1e-9)
        assert lam[inside].min() < 1.0 < lam[inside].max()
    bonded = bend(layers, 0.2).profile(Y)[0]
    assert np.ptp(bonded) > np.ptp(lam)  # bonded: one gradient across the whole thickness


def test_ogden_family_normalisation_and_alpha_two_curve():
    kappa = np.linspace(0, data.FIG3_MAX_CURVATURE, 8)
    m = b14.ogden_normalised_moment(2.0, kappa)
    assert m[0] == 0.0 and m[-1] == pytest.approx(1.0)
    # α = 2 is neo-Hookean: nearly linear at these strains (≤ 6 %), stiffer α curve lies below it
    assert np.max(np.abs(m - kappa / kappa[-1])) < 0.01
    assert np.all(b14.ogden_normalised_moment(20.0, kappa)[1:-1] < m[1:-1])


def test_analytic_rows_and_figures(tmp_path):
    rows = analytic_rows() + closed_form_rows()
    names = [r.quantity for r in rows]
    assert len(names) == len(set(names))
    assert all(r.ok for r in rows if r.quantity.startswith("[exact]") or r.quantity.startswith("Table 3"))
    for r in rows:
        if not r.ok:
            assert len(r.note) > 20, f"failing row without explanation: {r.quantity}"
        assert r.status in (Status.AGREES, Status.DIFFERS), r.quantity
    paths = [figures.write_figure(tmp_path, name, draw) for name, draw in figures.ANALYTIC_FIGURES]
    assert len(paths) == 3 and all(p.stat().st_size > 10_000 for p in paths)
    assert all(matplotlib.image.imread(p).shape[1] >= MIN_WIDTH_IN * DPI for p in paths)  # readable on a laptop
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths)  # no temporary files left


def test_fe_pure_bending_converges_to_rivlin_at_second_order():
    """Homogeneous strip (no interface): Q2/Q1 error in NA and M at the FE centre curvature falls ~4× per h/2."""
    layers = b14.trilayer(data.MU_OUTER, 0.4)
    errors = []
    for nx, ny in ((6, 1), (12, 2)):
        fe = b14_fe.fe_pure_bending(layers, 0.2, 1.2, nx, ny)
        ref = bend(layers, fe["centre_curvature"])
        assert abs(fe["axial_force"]) < 1e-5 * 4 * 45 * 0.2 * 0.4**2
        assert fe["centre_curvature"] == pytest.approx(0.2, rel=0.03)  # end effect only
        errors.append((abs(fe["neutral_axis"] / ref.neutral_axis - 1), abs(fe["moment"] / ref.moment - 1)))
    assert errors[1][0] < 1e-3 and errors[1][1] < 1e-3
    assert errors[0][0] / errors[1][0] > 3.0


def test_cli_streams_the_analytic_rows_and_stops_cleanly_on_interrupt(tmp_path, capsys, monkeypatch):
    """The CLI wiring; Ctrl-C arrives when the FE stage starts (the FE rows are checked above and take a minute)."""

    def interrupt(full=False):
        raise KeyboardInterrupt

    monkeypatch.setattr(b14_reproduce, "fe_convergence_rows", interrupt)
    code = main(["reproduce", "buchanan2014", "--out", str(tmp_path)])
    captured = capsys.readouterr()
    assert "Fig. 8 NA AC" in captured.out and "Table 3 fibrosa" in captured.out
    assert code == 130 and "interrupted" in captured.err and "fig8_bimodular_neutral_axis" in captured.err
    assert len(list(tmp_path.glob("*.png"))) == 3 and not list(tmp_path.glob(".*"))


def test_smoothed_bimodular_bilayer_bends_like_the_sharp_one():
    for direction in ("AC", "WC"):
        sharp = b14.neutral_axis(b14.bimodular_bilayer(), direction, 0.2)
        smooth = b14.neutral_axis(b14.bimodular_bilayer(smoothed=True), direction, 0.2)
        assert smooth == pytest.approx(sharp, abs=1e-4)


def test_smoothed_bilayer_uses_the_library_law_with_the_tanh_switch():
    """The FE bilayer is the library's BimodularNeoHookean with smoothing δ = 0.01 (FD-tested in
    tests/test_materials_bimodular.py); inside the band the modulus is between μ− and μ+."""
    law = b14.bimodular_bilayer(smoothed=True)[1][1]
    assert type(law).__name__ == "BimodularNeoHookean" and law.smoothing == b14.BIMODULAR_SMOOTHING
    F = np.diag([1.0 + 1e-4, 1 / (1.0 + 1e-4), 1.0])[:, :, None]
    sharp = b14.bimodular_bilayer()[1][1]
    assert law.psi(F)[0] < sharp.psi(F)[0]  # just above λ = 1: the smoothed modulus is below μ+


def test_figure_8_legend_sits_outside_the_data():
    """Issue 12 item 7: the Fig. 8 legend covered the data; now it is a figure legend clear of both panels."""
    import matplotlib.pyplot as plt

    axes = figures.figure_8()
    fig = axes[0].figure
    fig.canvas.draw()
    legend = fig.legends[0].get_window_extent()
    assert not any(legend.overlaps(ax.get_window_extent()) for ax in axes)
    plt.close(fig)


def test_sliding_figure_defines_its_symbols():
    """Issue 12 item 7: the sliding measure S (legend) and Λ1 (axis) are defined on the figure itself."""
    import matplotlib.pyplot as plt

    Y = np.linspace(0.0, 0.4, 5)
    flat = {(1.0, 0.2): 1 + 0 * Y, (45.0, 0.2): 1 + 0 * Y}
    study = {"Y": Y, "H": 0.4, "curvatures": (0.2,), "moduli": (1.0, 45.0), "direction": "WC", "profiles": flat,
             "sliding": {(1.0, 0.2): 0.0, (45.0, 0.2): 0.0}}
    axes = figures.figure_4_9_end_loading(study)
    fig = axes[0].figure
    assert "S = J(μS) − J(45 kPa)" in fig._suptitle.get_text() and "J = jump of Λ1" in fig._suptitle.get_text()
    assert "Λ1 = √(U11² + U12²)" in axes[0].get_ylabel()
    plt.close(fig)
