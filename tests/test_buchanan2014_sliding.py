"""buchanan2014 pin-ended end loading (Sect. 2.2, Figs. 4/9): equilibrium, bonded strip vs Rivlin, sliding measure."""

from __future__ import annotations

import numpy as np
import pytest

from skvalve.analytic.rivlin import bend
from skvalve.papers.buchanan2014 import data
from skvalve.papers.buchanan2014 import models as b14
from skvalve.papers.buchanan2014 import sliding as sl

COARSE = {"ny_per_layer": 1, "steps": 16, "shortening": 1.6}  # reaches Δκ ≈ 0.2 in a few seconds


@pytest.fixture(scope="module")
def bonded():
    return sl.fe_end_loading(b14.trilayer(data.MU_OUTER), "WC", **COARSE)


@pytest.fixture(scope="module")
def unbonded():
    return sl.fe_end_loading(b14.trilayer(0.001), "WC", **COARSE)


def test_centre_moment_three_ways(bonded):
    """M = P·y (pin force × deflection) against the symmetry-plane reactions (global moment balance, exact
    up to the Newton tolerance) and against ∫σ11 (y − y_c) dy over the deformed section (independent
    stress integration; its error is that of the Q2/Q1 stress field)."""
    q = sl.at_curvature(bonded, 0.15)
    assert q["M_Py"] > 0 and q["y"] < 0  # WC: the centre moves down
    assert q["M_reaction"] == pytest.approx(q["M_Py"], rel=1e-5)
    assert q["M_stress"] == pytest.approx(q["M_Py"], rel=2e-3)
    assert q["N_reaction"] == pytest.approx(q["P"], rel=1e-5)  # horizontal balance of the half strip


def test_pin_force_is_near_the_euler_load(bonded):
    """Small deflections: P → π²E'I/L_e² with E' = 4μ (plane strain), L_e between the sleeve edges
    (13 mm, rigid sleeves) and the pins (14 mm), within 3 % (elastica at Δκ = 0.05, axial shortening)."""
    EI = 4 * data.MU_OUTER * 0.4**3 / 12
    P = sl.at_curvature(bonded, 0.05)["P"]
    assert 0.97 * np.pi**2 * EI / 14.0**2 < P < 1.03 * np.pi**2 * EI / 13.0**2


def test_homogeneous_centre_profile_is_rivlins(bonded):
    """Uniform μ: Λ1 at the centre matches Rivlin at the FE's bending angle a; the difference left is the
    axial compression P/(E'H) (≈ 7e-4) that pure bending leaves out, plus discretisation."""
    for kappa in (0.1, 0.2):
        q = sl.at_curvature(bonded, kappa)
        rivlin = bend(bonded["layers"], -q["a"]).profile(bonded["Y"])[0]
        assert np.max(np.abs(q["stretch"] - rivlin)) < 2e-3
        assert abs(sl.interface_jump(bonded["layers"], bonded["Y"], q["stretch"])) < 2e-3


def test_sliding_measure_vanishes_bonded_and_is_large_for_one_pascal(bonded, unbonded):
    Y = bonded["Y"]
    for kappa in (0.1, 0.2):
        jb = sl.interface_jump(bonded["layers"], Y, sl.at_curvature(bonded, kappa)["stretch"])
        ju = sl.interface_jump(unbonded["layers"], Y, sl.at_curvature(unbonded, kappa)["stretch"])
        assert abs(jb) < 2e-3
        assert abs(ju - jb) > 2 * data.LAMBDA_EXPERIMENT_ERROR * kappa / 0.2  # FE: 0.025 at 0.1, 0.05 at 0.2


def test_interface_jump_of_synthetic_profiles():
    layers = b14.trilayer(1.0)
    Y = np.linspace(0, 0.4, 41)
    assert sl.interface_jump(layers, Y, 1 + 0.3 * (Y - 0.2)) == pytest.approx(0.0, abs=1e-12)
    stepped = np.where(Y > 0.16, 1.01, 1.0)
    assert sl.interface_jump(layers, Y, stepped) == pytest.approx(0.01, abs=1e-12)


def test_threshold_interpolates_in_log_modulus_and_rejects_unbracketed():
    study = {"moduli": (0.001, 0.1, 45.0), "sliding": {(0.001, 0.2): 0.1, (0.1, 0.2): 0.001, (45.0, 0.2): 0.0}}
    # |S| falls from 0.1 to 0.001 over two decades: 0.0505 is halfway, at 10 Pa
    assert sl.sliding_threshold(study, 0.2, 0.0505) == pytest.approx(0.01, rel=1e-9)
    with pytest.raises(ValueError, match="bracket"):
        sl.sliding_threshold(study, 0.2, 0.5)


def test_bad_input():
    with pytest.raises(ValueError, match="direction"):
        sl.fe_end_loading(b14.trilayer(1.0), "sideways")
    with pytest.raises(ValueError, match="perturbation"):
        sl.fe_end_loading(b14.trilayer(1.0), "WC", perturbation=0.0)
    with pytest.raises(ValueError, match="Δκ"):
        sl.at_curvature({"kappa": np.array([0.1, 0.2])}, 0.5)


def test_reported_state_does_not_depend_on_the_branch_selecting_force(bonded):
    """The transverse force is zero for every reported step, so a 4× larger one ends on the same equilibrium."""
    other = sl.fe_end_loading(b14.trilayer(data.MU_OUTER), "WC", **COARSE, perturbation=4 * sl.PERTURBATION)
    a, b = sl.at_curvature(bonded, 0.15), sl.at_curvature(other, 0.15)
    np.testing.assert_allclose(b["stretch"], a["stretch"], atol=1e-8)
    assert b["P"] == pytest.approx(a["P"], rel=1e-8)
