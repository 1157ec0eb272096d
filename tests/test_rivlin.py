"""Rivlin bending: closed forms, Euler–Bernoulli limits, equilibrium checks, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from skvalve.analytic.rivlin import bend, moment_curvature, plane_strain_energy
from skvalve.materials import IncompressibleNeoHookean, NeoHookean


class PrincipalOgden:
    """Test-only incompressible one-term Ogden law on diagonal F: W = 2μ/α² Σ(λᵢ^α − 1)."""

    incompressible = True

    def __init__(self, mu: float, alpha: float, mu_compression: float | None = None):
        self.mu, self.alpha = mu, alpha
        self.mu_c = mu if mu_compression is None else mu_compression  # bimodular along e1

    def _modulus(self, F):
        return np.where(F[0, 0] >= 1.0, self.mu, self.mu_c)

    def psi(self, F):
        lam = np.stack([F[0, 0], F[1, 1], F[2, 2]])
        return 2 * self._modulus(F) / self.alpha**2 * np.sum(lam**self.alpha - 1.0, axis=0)

    def pk1(self, F):
        P = np.zeros_like(F)
        for i in range(3):
            P[i, i] = 2 * self._modulus(F) / self.alpha * F[i, i] ** (self.alpha - 1.0)
        return P


def ogden_moment_closed_form(mu: float, alpha: float, H: float, a: float) -> tuple[float, float]:
    """(c, M) for one homogeneous one-term Ogden layer, derived by hand (alpha != ±2).

    Ŵ(λ) = 2μ/α² (λ^α + λ^-α − 2) is symmetric under λ → 1/λ, so λ_top·λ_bottom = 1 and
    c(c + 2aH) = 1. M = (1/a) ∫ (Ŵ(λ_b) − Ŵ(λ)) dY with s = λ² = 2aY + c, dY = ds/2a.
    """
    c = -a * H + np.sqrt((a * H) ** 2 + 1.0)
    st = c + 2 * a * H
    k = 2 * mu / alpha**2

    def prim(p):  # ∫ s^p ds / (2a)
        return (st ** (p + 1) - c ** (p + 1)) / (p + 1) / (2 * a)

    W_b = k * (c ** (alpha / 2) + c ** (-alpha / 2) - 2)
    integral_W = k * (prim(alpha / 2) + prim(-alpha / 2) - 2 * H)
    return c, (H * W_b - integral_W) / a


def neo_hookean_moment_closed_form(mu: float, H: float, a: float) -> float:
    """M = μ/(4a²) [ (c⁻² − c²)/2 + 2 ln c ], c = −aH + √(a²H² + 1) (derived by hand)."""
    c = -a * H + np.sqrt((a * H) ** 2 + 1.0)
    return mu / (4 * a**2) * (0.5 * (c**-2 - c**2) + 2 * np.log(c))


@pytest.mark.parametrize("a", [0.05, 0.3, 1.0, 3.0])
def test_neo_hookean_matches_closed_form(a):
    mu, H = 45.0, 0.4
    sol = bend([(H, IncompressibleNeoHookean(mu))], a)
    c = -a * H + np.sqrt((a * H) ** 2 + 1.0)
    assert sol.lambda_bottom * sol.lambda_top == pytest.approx(1.0, abs=1e-12)
    assert sol.neutral_axis == pytest.approx((1.0 - c) / (2 * a), rel=1e-10)
    assert sol.moment == pytest.approx(neo_hookean_moment_closed_form(mu, H, a), rel=1e-9)
    assert abs(sol.axial_force) < 1e-10 * mu * H


@pytest.mark.parametrize("alpha", [4.0, 7.5, -3.0])
def test_ogden_matches_closed_form(alpha):
    mu, H, a = 45.0, 0.4, 0.8
    sol = bend([(H, PrincipalOgden(mu, alpha))], a)
    c, M = ogden_moment_closed_form(mu, alpha, H, a)
    assert sol.c == pytest.approx(c, rel=1e-12)
    assert sol.moment == pytest.approx(M, rel=1e-9)


def test_ogden_alpha_two_is_neo_hookean():
    """With the package's Ogden law (Abaqus convention) when it exists, else the test-local one."""
    from skvalve.materials import Ogden

    ogden = Ogden(mu=(45.0,), alpha=(2.0,))
    for a in (0.1, 1.5):
        ref = bend([(0.4, IncompressibleNeoHookean(45.0))], a)
        sol = bend([(0.4, ogden)], a)
        assert sol.moment == pytest.approx(ref.moment, rel=1e-10)
        assert sol.neutral_axis == pytest.approx(ref.neutral_axis, rel=1e-10)


def test_small_curvature_is_euler_bernoulli_layered():
    """Transformed section with plane-strain modulus E' = E/(1-ν²) = 4μ (ν = 1/2)."""
    h = np.array([0.1, 0.12, 0.18])  # ventricularis, spongiosa, fibrosa
    mu = np.array([20.0, 3.0, 45.0])
    layers = [(t, IncompressibleNeoHookean(m)) for t, m in zip(h, mu, strict=True)]
    y = np.concatenate([[0.0], np.cumsum(h)])
    E = 4 * mu
    y_na = np.sum(E * (y[1:] ** 2 - y[:-1] ** 2) / 2) / np.sum(E * h)
    EI = np.sum(E * ((y[1:] - y_na) ** 3 - (y[:-1] - y_na) ** 3) / 3)
    for a in (1e-4, -1e-4):
        sol = bend(layers, a)
        assert sol.neutral_axis == pytest.approx(y_na, rel=1e-4)
        assert sol.moment == pytest.approx(EI * a, rel=1e-4)
    # and the error shrinks like the curvature (first-order nonlinear correction)
    err = [abs(bend(layers, a).moment / (EI * a) - 1) for a in (1e-2, 1e-3)]
    assert 5 < err[0] / err[1] < 20


def test_small_curvature_bimodular_neutral_axis():
    """Homogeneous bimodular beam: E₋ h_c² = E₊ (H − h_c)² ⇒ h_c/H = √E₊/(√E₊ + √E₋)."""
    mu_t, mu_c, H = 139.5, 29.55, 0.3
    a = 1e-4
    sol = bend([(H, PrincipalOgden(mu_t, 2.0, mu_compression=mu_c))], a)
    expected = np.sqrt(mu_t) / (np.sqrt(mu_t) + np.sqrt(mu_c)) * H
    assert sol.neutral_axis == pytest.approx(expected, rel=1e-4)
    # N vanishes against the fibre-stress scale 4μ·aH·H (c carries round-off ~1e-16/(aH))
    assert abs(sol.axial_force) < 1e-8 * 4 * mu_t * a * H**2


@pytest.mark.parametrize("alpha", [4.0, -3.0])
def test_package_ogden_matches_closed_form(alpha):
    from skvalve.materials import Ogden

    sol = bend([(0.4, Ogden(mu=(45.0,), alpha=(alpha,)))], 0.8)
    assert sol.moment == pytest.approx(ogden_moment_closed_form(45.0, alpha, 0.4, 0.8)[1], rel=1e-9)


def test_package_bimodular_equals_test_local_bimodular():
    from skvalve.materials import BimodularNeoHookean

    layers = [(0.16, BimodularNeoHookean(65.0, 16.74, [1, 0, 0])), (0.24, BimodularNeoHookean(139.5, 29.55, [1, 0, 0]))]
    local = [(0.16, PrincipalOgden(65.0, 2.0, 16.74)), (0.24, PrincipalOgden(139.5, 2.0, 29.55))]
    for a in (0.3, -0.3):
        sol, ref = bend(layers, a), bend(local, a)
        assert sol.neutral_axis == pytest.approx(ref.neutral_axis, rel=1e-10)
        assert sol.moment == pytest.approx(ref.moment, rel=1e-10)


def test_profile_equilibrium_and_traction_free_faces():
    layers = [(0.1, IncompressibleNeoHookean(20.0)), (0.12, IncompressibleNeoHookean(1.0)),
              (0.18, IncompressibleNeoHookean(45.0))]
    a = 2.0
    sol = bend(layers, a)
    H = sol.thickness
    lam, s_rr, s_tt = sol.profile(np.array([0.0, H]))
    assert np.max(np.abs(s_rr)) < 1e-12 * 45
    assert lam == pytest.approx([sol.lambda_bottom, sol.lambda_top])
    # radial equilibrium dσ_rr/dY = dσ_rr/dr · dr/dY = (σθθ − σrr)/r · 1/λ = a (σθθ − σrr)/λ²
    Y = np.linspace(0.01, H - 0.01, 7)
    Y = Y[np.abs(Y[:, None] - np.array([0.1, 0.22])).min(axis=1) > 2e-3]
    d = 1e-6
    lam, s_rr, s_tt = sol.profile(Y)
    ds = (sol.profile(Y + d)[1] - sol.profile(Y - d)[1]) / (2 * d)
    np.testing.assert_allclose(ds, a * (s_tt - s_rr) / lam**2, rtol=1e-6, atol=1e-9)
    # σ_rr continuous across interfaces
    for yi in (0.1, 0.22):
        below, above = sol.profile(np.array([yi - 1e-9, yi]))[1]
        assert above == pytest.approx(below, abs=1e-6)
    # two routes to the moment agree: (1/a)∫σθθ dY (trapezoid, split at interfaces) = −(1/a)∫σrr dY
    total = 0.0
    for y0, y1 in ((0.0, 0.1), (0.1, 0.22), (0.22, H)):
        Yq = np.linspace(y0, y1 - 1e-12, 4001)
        total += np.trapezoid(sol.profile(Yq)[2], Yq)
    assert total / a == pytest.approx(sol.moment, rel=1e-5)


def test_negative_curvature_is_mirror_image():
    V, F = IncompressibleNeoHookean(20.0), IncompressibleNeoHookean(45.0)
    down = bend([(0.16, V), (0.24, F)], -0.3)
    up = bend([(0.24, F), (0.16, V)], 0.3)
    assert down.neutral_axis == pytest.approx(0.4 - up.neutral_axis, rel=1e-12)
    assert down.moment == pytest.approx(-up.moment, rel=1e-12)
    assert down.lambda_bottom == pytest.approx(up.lambda_top)
    assert down.profile(np.array([0.05]))[0] == pytest.approx(up.profile(np.array([0.35]))[0])


def test_reduced_energy_derivative_matches_finite_differences():
    lam = np.array([0.8, 0.97, 1.0, 1.05, 1.3])
    for material in (IncompressibleNeoHookean(3.0), PrincipalOgden(2.0, 5.0)):
        W, dW = plane_strain_energy(material, lam)
        h = 1e-6
        fd = (plane_strain_energy(material, lam + h)[0] - plane_strain_energy(material, lam - h)[0]) / (2 * h)
        np.testing.assert_allclose(dW, fd, rtol=1e-7, atol=1e-9)


def test_moment_curvature_is_odd_and_zero_at_zero():
    layers = [(0.4, IncompressibleNeoHookean(45.0))]
    M = moment_curvature(layers, [-0.2, 0.0, 0.2])
    assert M[1] == 0.0 and M[0] == pytest.approx(-M[2])


@pytest.mark.parametrize(
    "layers, a, match",
    [
        ([], 0.1, "at least one"),
        ([(-0.1, IncompressibleNeoHookean(1.0))], 0.1, "thickness"),
        ([(0.1, NeoHookean(1.0, 10.0))], 0.1, "not incompressible"),
        ([(0.1, "steel")], 0.1, "psi"),
        ([(0.1, IncompressibleNeoHookean(1.0))], 0.0, "non-zero"),
        ([(0.1, IncompressibleNeoHookean(1.0))], np.nan, "non-zero"),
    ],
)
def test_bad_input_raises(layers, a, match):
    with pytest.raises(ValueError, match=match):
        bend(layers, a)


def test_profile_outside_block_raises():
    sol = bend([(0.4, IncompressibleNeoHookean(1.0))], 0.1)
    with pytest.raises(ValueError, match="Y must lie"):
        sol.profile(np.array([0.5]))
