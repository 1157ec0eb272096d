"""Ogden law: closed-form energy, equal-stretch tangents, neo-Hookean limit, split, buchanan2014 mapping."""

from __future__ import annotations

import numpy as np
import pytest
from _material_checks import fd_tangent, random_deformations, random_rotations, relative_error

from skvalve.materials import IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden

OGDEN_LAWS = {
    "incompressible": Ogden(mu=(0.6, 0.01, 0.3), alpha=(9.0, -4.0, 2.5)),
    "one_D": Ogden(mu=(0.6, 0.01, 0.3), alpha=(9.0, -4.0, 2.5), D=(0.5,)),
    "two_D": Ogden(mu=(1.0, 0.2), alpha=(2.0, -1.5), D=(0.8, 2.0)),
    # Texas TriValve 1.0 anterior chordae (MPa, alpha ~ 50; Mathur et al. 2022, CC BY-NC-SA 4.0)
    "texas_chordae": Ogden(
        mu=(4.212040401935249, 7.621400389279001, 15.437445816336888),
        alpha=(50.42991853603889, 0.016468374322372, 50.43046978340582),
        D=(7.3584e-04,),
    ),
}


def _equal_stretch_deformations() -> dict[str, np.ndarray]:
    R = random_rotations(1, seed=11)[..., 0]
    return {
        "identity": np.eye(3),
        "diag_aab": np.diag([1.07, 1.07, 0.93]),
        "diag_abb_isochoric": np.diag([1.05, 1.05**-0.5, 1.05**-0.5]),
        "a_times_R": 1.04 * R,
        "rotated_diag_aab": R @ np.diag([0.96, 1.03, 1.03]),
        "nearly_equal": np.diag([1.03, 1.03 + 1e-9, 0.97]),
    }


@pytest.mark.parametrize("law_name", sorted(OGDEN_LAWS))
@pytest.mark.parametrize("case", sorted(_equal_stretch_deformations()))
def test_tangent_at_coincident_stretches_matches_fd(law_name, case):
    law = OGDEN_LAWS[law_name]
    F = _equal_stretch_deformations()[case][:, :, None]
    A = law.tangent(F)
    assert np.all(np.isfinite(A))
    # relative to the tangent's size; alpha ~ 50 makes |A| large, FD round-off scales with it
    assert relative_error(A, fd_tangent(law, F)) < 1e-7


def test_energy_matches_principal_stretch_formula():
    """psi against the Abaqus formula evaluated by hand from diag(l1, l2, l3) (no eigen-solver)."""
    mu, alpha, D = (0.6, 0.3), (9.0, -2.5), (0.5, 1.5)
    law = Ogden(mu, alpha, D)
    stretches = np.array([[1.2, 0.9, 1.05], [0.8, 0.8, 1.3], [1.0, 1.0, 1.0]])
    for lam in stretches:
        J = np.prod(lam)
        bar = lam * J ** (-1 / 3)
        expected = sum(2 * m / a**2 * (np.sum(bar**a) - 3) for m, a in zip(mu, alpha, strict=True))
        expected += (J - 1) ** 2 / D[0] + (J - 1) ** 4 / D[1]
        R = random_rotations(1, seed=3)[..., 0]
        F = R @ np.diag(lam) @ R.T  # a symmetric F with the same principal stretches
        assert law.psi(F[:, :, None])[0] == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_alpha_two_one_term_is_incompressible_neo_hookean():
    """mu_Ogden = mu: N = 1, alpha = 2 is psi = mu/2 (I1bar - 3), identical stress and tangent."""
    F = random_deformations(10, seed=21)
    ogden, neo = Ogden((1.7,), (2.0,)), IncompressibleNeoHookean(1.7)
    assert relative_error(ogden.pk1(F), neo.pk1(F)) < 1e-12
    assert relative_error(ogden.tangent(F), neo.tangent(F)) < 1e-12
    assert relative_error(ogden.psi(F), neo.psi(F)) < 1e-12


def test_alpha_two_compressible_has_neo_hookean_deviatoric_stress_at_J1():
    """At J = 1 the compressible Ogden(alpha=2) and Bonet–Wood neo-Hookean share sigma' = mu dev B."""
    F = random_deformations(10, seed=22)
    F = F / np.cbrt(np.linalg.det(np.moveaxis(F, -1, 0)))  # isochoric
    ogden, neo = Ogden((1.7,), (2.0,), (0.3,)), NeoHookean(1.7, 5.0)

    def dev(s):
        return s - np.trace(s) / 3 * np.eye(3)[:, :, None]

    assert relative_error(dev(ogden.cauchy(F)), dev(neo.cauchy(F))) < 1e-12
    expected = 1.7 * dev(np.einsum("iK...,jK...->ij...", F, F))
    assert relative_error(dev(ogden.cauchy(F)), expected) < 1e-12


def test_alpha_two_with_D_equals_lee_sacks_without_exponential():
    """LeeSacks(c0, c1=0, c2, D) and Ogden((c0,), (2,), (D,)) are the same energy."""
    F = random_deformations(8, seed=23)
    a, b = Ogden((0.8,), (2.0,), (0.4,)), LeeSacks(0.8, 0.0, 3.0, 0.4)
    assert relative_error(a.psi(F), b.psi(F)) < 1e-12
    assert relative_error(a.tangent(F), b.tangent(F)) < 1e-12


def test_buchanan2014_mapping():
    """Eq. 1: sum mu_p/alpha_p (...) equals Abaqus form with mu_i = mu_p alpha_p / 2."""
    law = Ogden.from_buchanan2014(mu_p=[3.0, -1.0], alpha_p=[4.0, -2.0])
    assert law.mu == (6.0, 1.0)
    assert law.shear_modulus == pytest.approx(3.0 * 4.0 / 2 + (-1.0) * (-2.0) / 2)
    F = np.diag([1.3, 0.95, 1 / (1.3 * 0.95)])[:, :, None]
    lam = np.diag(F[..., 0])
    expected = 3.0 / 4.0 * (np.sum(lam**4) - 3) + (-1.0) / (-2.0) * (np.sum(lam**-2.0) - 3)
    assert law.psi(F)[0] == pytest.approx(expected, rel=1e-12)
