"""Strain mapping of Appendix 1: exact recovery, polar decomposition, noisy Rivlin bending markers."""

from __future__ import annotations

import numpy as np
import pytest

from skvalve.analytic.rivlin import bend
from skvalve.analytic.strainmap import fit_strain_map, polar_2d
from skvalve.kinematics import polar_decomposition
from skvalve.materials import IncompressibleNeoHookean


def _markers(rng, n=150, length=0.3, thickness=0.318, x0=7.0):
    return np.column_stack([x0 + length * (rng.random(n) - 0.5), thickness * rng.random(n)])


def test_quadratic_field_is_recovered_exactly():
    rng = np.random.default_rng(0)
    X = _markers(rng, 40)
    a = np.array([0.01, 0.02, -0.03, 0.04, 0.005, -0.06])
    b = np.array([-0.02, 0.01, 0.015, -0.02, 0.003, 0.07])
    A = np.column_stack([np.ones(len(X)), X[:, 0], X[:, 1], X[:, 0] * X[:, 1], X[:, 0] ** 2, X[:, 1] ** 2])
    smap = fit_strain_map(X, X + np.column_stack([A @ a, A @ b]))
    np.testing.assert_allclose(smap.a, a, atol=1e-11)
    np.testing.assert_allclose(smap.b, b, atol=1e-11)
    assert smap.r2_u == pytest.approx(1.0) and smap.r2_v == pytest.approx(1.0)
    F = smap.deformation_gradient(7.0, 0.1)
    assert F[0, 0] == pytest.approx(1 + a[1] + a[3] * 0.1 + 2 * a[4] * 7.0)
    assert F[1, 1] == pytest.approx(1 + b[2] + b[3] * 7.0 + 2 * b[5] * 0.1)


def test_polar_2d_matches_3d_polar_decomposition():
    rng = np.random.default_rng(1)
    F2 = np.eye(2)[:, :, None] + 0.3 * rng.standard_normal((2, 2, 50))
    F2 = F2[:, :, (F2[0, 0] * F2[1, 1] - F2[0, 1] * F2[1, 0]) > 0.05]
    R, U, alpha = polar_2d(F2)
    F3 = np.zeros((3, 3, F2.shape[2]))
    F3[:2, :2], F3[2, 2] = F2, 1.0
    R3, U3 = polar_decomposition(F3)
    np.testing.assert_allclose(U, U3[:2, :2], atol=1e-12)
    np.testing.assert_allclose(R, R3[:2, :2], atol=1e-12)
    np.testing.assert_allclose(alpha, np.arctan2(R3[1, 0], R3[0, 0]), atol=1e-12)


def _rivlin_edge_markers(sol, X, rotation=0.3, shift=(0.5, -0.2)):
    """Deformed positions of an edge of the bent block (exact Rivlin map) plus a rigid motion."""
    a, x0 = sol.a, 7.0
    lam = sol.profile(X[:, 1])[0]
    r, theta = lam / a, a * (X[:, 0] - x0)
    x = np.column_stack([x0 + r * np.sin(theta), sol.neutral_axis + r * np.cos(theta) - 1.0 / a])
    c, s = np.cos(rotation), np.sin(rotation)
    return x @ np.array([[c, s], [-s, c]]) + np.asarray(shift)


def test_rivlin_bending_markers_recover_stretch_rotation_and_neutral_axis():
    """Noise-free: only the truncation error of Eq. 5 remains.

    Eq. 5 makes F linear in X2, while λ(Y) = √(2aY + c) has λ'' = −a²/λ³; the best linear fit of
    λ over [0, H] is off by at most about a²H²/8 ≈ 5e-4 at a = 0.2/mm, H = 0.318 mm.
    """
    H = 0.318
    sol = bend([(0.4 * H, IncompressibleNeoHookean(20.0)), (0.6 * H, IncompressibleNeoHookean(45.0))], 0.2)
    rng = np.random.default_rng(2)
    X = _markers(rng, 200, thickness=H)
    smap = fit_strain_map(X, _rivlin_edge_markers(sol, X, rotation=0.3))
    Y = np.linspace(0.0, H, 11)
    np.testing.assert_allclose(smap.axial_stretch(7.0, Y), sol.profile(Y)[0], atol=0.2**2 * H**2 / 8)
    _, alpha = smap.stretch(7.0, 0.5 * H)
    assert float(alpha) == pytest.approx(0.3, abs=1e-4)
    assert smap.neutral_axis(7.0) == pytest.approx(sol.neutral_axis, abs=0.005 * H)


def test_noisy_markers_stretch_accuracy():
    """Marker noise 0.5 µm, 150 markers on a 0.3 × 0.318 mm field, Δκ = 0.2/mm, 60 seeds.

    The RMS error of Λ1 at mid-thickness must match the least-squares standard error
    σ² gᵀ(AᵀA)⁻¹g of F11 (≈ 5e-4, i.e. the 0.05 % quoted in buchanan2014 Sect. 2.4) within the
    sampling scatter (±25 % for 60 seeds) plus the Eq. 5 truncation bias (< a²H²/8); the neutral
    axis RMS error must stay below 1.5 % of the thickness.
    """
    H, noise, x0 = 0.318, 0.0005, 7.0
    sol = bend([(H, IncompressibleNeoHookean(45.0))], 0.2)
    errors, na_errors, predicted = [], [], []
    for seed in range(60):
        rng = np.random.default_rng(100 + seed)
        X = _markers(rng, 150, thickness=H, x0=x0)
        x = _rivlin_edge_markers(sol, X) + noise * rng.standard_normal(X.shape)
        smap = fit_strain_map(X, x)
        errors.append(float(smap.axial_stretch(x0, 0.5 * H)) - float(sol.profile(0.5 * H)[0]))
        na_errors.append((smap.neutral_axis(x0) - sol.neutral_axis) / H)
        A = np.column_stack([np.ones(len(X)), X[:, 0], X[:, 1], X[:, 0] * X[:, 1], X[:, 0] ** 2, X[:, 1] ** 2])
        g = np.array([0.0, 1.0, 0.0, 0.5 * H, 2 * x0, 0.0])  # dF11/dcoefficients at (x0, H/2)
        predicted.append(noise**2 * g @ np.linalg.solve(A.T @ A, g))
    rms, sigma = np.sqrt(np.mean(np.square(errors))), np.sqrt(np.mean(predicted))
    assert 0.75 * sigma < rms < 1.25 * sigma + 0.2**2 * H**2 / 8
    assert sigma < 7e-4
    assert np.sqrt(np.mean(np.square(na_errors))) < 0.015


@pytest.mark.parametrize(
    "reference, deformed, match",
    [
        (np.zeros((5, 2)), np.zeros((5, 2)), "6 coefficients"),
        (np.zeros((8, 3)), np.zeros((8, 3)), "shape"),
        (np.ones((8, 2)), np.ones((7, 2)), "shape of reference"),
        (np.column_stack([np.arange(8.0), np.zeros(8)]), np.zeros((8, 2)), "spread"),
        (np.full((8, 2), np.nan), np.zeros((8, 2)), "finite"),
    ],
)
def test_bad_markers_raise(reference, deformed, match):
    with pytest.raises(ValueError, match=match):
        fit_strain_map(reference, deformed)


def test_degenerate_layout_folded_map_and_no_neutral_axis_raise():
    t = np.linspace(0, 1, 10)
    with pytest.raises(ValueError, match="rank"):
        fit_strain_map(np.column_stack([t, t]), np.column_stack([t, t]))
    with pytest.raises(ValueError, match="det F"):
        polar_2d(np.array([[-1.0, 0.0], [0.0, 1.0]]))
    X = _markers(np.random.default_rng(3), 20)
    stretched = fit_strain_map(X, X * np.array([1.1, 1.0 / 1.1]))
    with pytest.raises(ValueError, match="does not change sign"):
        stretched.neutral_axis(7.0)
