"""Bimodular neo-Hookean (buchanan2014 Eq. 4): branches, behaviour exactly at the switch, directions."""

from __future__ import annotations

import numpy as np
import pytest
from _material_checks import fd_tangent, random_deformations, relative_error

from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean

MU_T, MU_C = 139.5, 29.55  # buchanan2014 Table 3 fibrosa (kPa)


def _uniaxial(lam: float) -> np.ndarray:
    return np.diag([lam, lam**-0.5, lam**-0.5])[:, :, None]


@pytest.mark.parametrize("lam, mu", [(1.2, MU_T), (1.0 + 1e-12, MU_T), (0.8, MU_C), (1.0 - 1e-12, MU_C)])
def test_branch_is_neo_hookean_with_the_active_modulus(lam, mu):
    law = BimodularNeoHookean(MU_T, MU_C, [1, 0, 0])
    # uniaxial stretch times a shear that leaves F e1 = lam e1, so that Ibar1 - 3 is O(1) in every case
    F = np.einsum("ij...,jk->ik...", _uniaxial(lam), np.array([[1, 0.2, 0], [0, 1, 0], [0, 0, 1.0]]))
    ref = IncompressibleNeoHookean(mu)
    np.testing.assert_array_equal(law.pk1(F), ref.pk1(F))
    np.testing.assert_array_equal(law.tangent(F), ref.tangent(F))
    np.testing.assert_array_equal(law.psi(F), ref.psi(F))


def test_exactly_at_the_switch_uses_compression_modulus_and_jumps():
    """lambda_a = 1 exactly (a = e1, F e1 = e1 + shear out of plane) -> mu_compression; the
    energy and stress jump to the tension values for any lambda_a > 1."""
    law = BimodularNeoHookean(MU_T, MU_C, [1, 0, 0])
    F_switch = np.array([[1.0, 0.3, 0.0], [0.0, 1.1, 0.0], [0.0, 0.0, 1 / 1.1]])[:, :, None]
    assert law.fibre_stretch_squared(np.einsum("kI...,kJ...->IJ...", F_switch, F_switch))[0] == 1.0
    np.testing.assert_array_equal(law.pk1(F_switch), IncompressibleNeoHookean(MU_C).pk1(F_switch))
    np.testing.assert_array_equal(law.tangent(F_switch), IncompressibleNeoHookean(MU_C).tangent(F_switch))
    # one ulp into tension: the tension branch, an O(1) jump in energy proportional to mu+ - mu-
    F_tension = F_switch.copy()
    F_tension[0, 0] = np.nextafter(1.0, 2.0)
    psi_switch, psi_tension = law.psi(F_switch)[0], law.psi(F_tension)[0]
    I1bar_minus_3 = 2 * psi_switch / MU_C
    assert psi_tension - psi_switch == pytest.approx(0.5 * (MU_T - MU_C) * I1bar_minus_3, rel=1e-9)
    # at F = I both branches give zero energy and stress: no jump there
    eye = np.eye(3)[:, :, None]
    assert law.psi(eye)[0] == 0.0 and np.all(law.pk1(eye) == 0.0)


def test_one_sided_tangents_match_fd_next_to_the_switch():
    law = BimodularNeoHookean(MU_T, MU_C, [0, 1, 0])
    for lam2 in (1.0 + 1e-4, 1.0 - 1e-4):  # FD step 1e-6 stays on one side
        F = np.array([[1.1, 0.0, 0.2], [0.0, lam2, 0.0], [0.0, 0.1, 1 / (1.1 * lam2)]])[:, :, None]
        assert relative_error(law.tangent(F), fd_tangent(law, F)) < 1e-7


def test_per_element_directions_broadcast_and_are_normalised():
    F = random_deformations(6, seed=31)  # (3, 3, 6)
    rng = np.random.default_rng(32)
    directions = rng.standard_normal((3, 6)) * rng.uniform(0.1, 10.0, 6)
    law = BimodularNeoHookean(MU_T, MU_C, directions)
    np.testing.assert_allclose(np.linalg.norm(law.direction, axis=0), 1.0, rtol=1e-15)
    P = law.pk1(F)
    for e in range(6):
        single = BimodularNeoHookean(MU_T, MU_C, directions[:, e])
        np.testing.assert_allclose(P[..., e], single.pk1(F[..., e : e + 1])[..., 0], rtol=1e-14, atol=1e-14)
    # (3, 1, n) directions against a (3, 3, q, n) quadrature batch
    Fq = np.stack([F, F], axis=2)
    law_q = BimodularNeoHookean(MU_T, MU_C, directions[:, None, :])
    np.testing.assert_allclose(law_q.pk1(Fq)[:, :, 1, :], P, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(mu_tension=-1.0, mu_compression=1.0, direction=[1, 0, 0]), "mu_tension"),
        (dict(mu_tension=1.0, mu_compression=0.0, direction=[1, 0, 0]), "mu_compression"),
        (dict(mu_tension=1.0, mu_compression=1.0, direction=[0, 0, 0]), "direction.*zero"),
        (dict(mu_tension=1.0, mu_compression=1.0, direction=[[1, 0], [0, 0], [0, 0]]), "direction.*zero"),
        (dict(mu_tension=1.0, mu_compression=1.0, direction=[1, 0]), "direction.*shape"),
        (dict(mu_tension=1.0, mu_compression=1.0, direction=[np.nan, 0, 1]), "direction.*finite"),
    ],
)
def test_invalid_parameters_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        BimodularNeoHookean(**kwargs)


def test_direction_batch_mismatch_raises():
    law = BimodularNeoHookean(MU_T, MU_C, np.ones((3, 4)))
    with pytest.raises(ValueError, match="direction batch shape"):
        law.pk1(random_deformations(5, seed=1))


# ---------------------------------------------------------------- smoothed switch
SMOOTH = BimodularNeoHookean(139.5, 29.55, direction=(1.0, 2.0, 0.5), smoothing=1e-2)


def test_smoothed_tangent_and_stress_match_finite_differences_across_the_switch():
    """Stretches straddling λ_a = 1 within the smoothing width, off-axis direction."""
    rng = np.random.default_rng(7)
    F = np.eye(3)[:, :, None] + 4e-3 * rng.standard_normal((3, 3, 12))
    P, A = SMOOTH.pk1_and_tangent(F)
    assert relative_error(A, fd_tangent(SMOOTH, F)) < 1e-6
    h = 1e-7
    dpsi = np.empty_like(P)
    for k in range(3):
        for L in range(3):
            dF = np.zeros_like(F)
            dF[k, L] = h
            dpsi[k, L] = (SMOOTH.psi(F + dF) - SMOOTH.psi(F - dF)) / (2 * h)
    assert relative_error(P, dpsi) < 1e-6


@pytest.mark.parametrize("lam", [0.9, 1.1])
def test_smoothed_law_equals_published_law_away_from_the_switch(lam):
    """Outside the tanh layer (|I4 - 1| >> δ) the two laws coincide to tanh's tail, e^{-2|I4-1|/δ}."""
    sharp = BimodularNeoHookean(139.5, 29.55, direction=(1.0, 0.0, 0.0))
    smooth = BimodularNeoHookean(139.5, 29.55, direction=(1.0, 0.0, 0.0), smoothing=1e-2)
    F = np.diag([lam, lam**-0.5, lam**-0.5])
    tail = 2.0 * np.exp(-2.0 * abs(lam**2 - 1.0) / 1e-2)
    assert relative_error(smooth.cauchy(F), sharp.cauchy(F)) < 1e-6 + tail


def test_negative_smoothing_is_rejected():
    with pytest.raises(ValueError, match="smoothing"):
        BimodularNeoHookean(1.0, 1.0, (1.0, 0.0, 0.0), smoothing=-1.0)
