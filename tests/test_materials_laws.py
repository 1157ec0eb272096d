"""Law-specific closed forms (thomas2019 Eq. 10, buchanan2014 Eq. 3, Lee–Sacks variants), split(), validation."""

from __future__ import annotations

import numpy as np
import pytest
from _material_checks import random_deformations, relative_error

from skvalve.kinematics import determinant, isochoric_first_invariant, left_cauchy_green
from skvalve.materials import (
    IncompressibleNeoHookean,
    LeeSacks,
    NeoHookean,
    Ogden,
    VolumetricEnergy,
)

EYE = np.eye(3)[:, :, None]


def test_neo_hookean_cauchy_is_thomas2019_eq10():
    """sigma = mu/J (B - I) + lambda ln J / J I, written out directly."""
    law = NeoHookean.from_shear_poisson(2.1, 0.49)
    F = random_deformations(10, seed=41)
    J, B = determinant(F), left_cauchy_green(F)
    expected = law.mu / J * (B - EYE) + law.lmbda * np.log(J) / J * EYE
    assert relative_error(law.cauchy(F), expected) < 1e-12


def test_neo_hookean_principal_form_thomas2019_eq13():
    """Principal Cauchy stresses mu/J (l_a^2 - 1) + lambda ln J / J for F = diag(l1, l2, l3)."""
    law = NeoHookean(1.5, 7.0)
    lam = np.array([1.3, 0.8, 1.1])
    J = np.prod(lam)
    sigma = law.cauchy(np.diag(lam)[:, :, None])[..., 0]
    np.testing.assert_allclose(np.diag(sigma), 1.5 / J * (lam**2 - 1) + 7.0 * np.log(J) / J, rtol=1e-13)
    assert np.max(np.abs(sigma - np.diag(np.diag(sigma)))) == 0.0


def test_incompressible_neo_hookean_is_buchanan2014_eq3_up_to_pressure():
    """At J = 1 the law's Cauchy stress is mu dev(B): mu B - p I with p = mu tr(B)/3; trace free."""
    F = random_deformations(10, seed=42)
    F = F / np.cbrt(determinant(F))
    law = IncompressibleNeoHookean(45.0)
    B = left_cauchy_green(F)
    expected = 45.0 * (B - np.trace(B) / 3 * EYE)
    assert relative_error(law.cauchy(F), expected) < 1e-12
    assert np.max(np.abs(np.trace(law.cauchy(F)))) < 1e-11


@pytest.mark.parametrize("published", [False, True])
def test_lee_sacks_energy_by_hand(published):
    c0, c1, c2, D = 1e-3, 1.188659e-4, 15.260081, 20.0669  # Texas TriValve anterior leaflet, MPa
    law = LeeSacks(c0, c1, c2, D, published_equation=published)
    F = random_deformations(5, seed=43, spread=0.15)
    x = isochoric_first_invariant(F) - 3
    J = determinant(F)
    exponent = c2 * x if published else c2 * x**2
    expected = c0 / 2 * x + c1 / 2 * (np.exp(exponent) - 1) + (J - 1) ** 2 / D
    np.testing.assert_allclose(law.psi(F), expected, rtol=1e-12)


def test_lee_sacks_published_and_shipped_differ():
    F = np.diag([1.2, 1.0, 1 / 1.2])[:, :, None]
    shipped, published = LeeSacks(1.0, 0.5, 2.0), LeeSacks(1.0, 0.5, 2.0, published_equation=True)
    assert abs(shipped.pk1(F)[0, 0, 0] - published.pk1(F)[0, 0, 0]) > 0.1
    assert shipped.shear_modulus == 1.0 and published.shear_modulus == 2.0


@pytest.mark.parametrize(
    "law, expected_rest, expected_modulus, kind",
    [
        (Ogden((1.0, 0.5), (3.0, -2.0), (0.25,)), Ogden((1.0, 0.5), (3.0, -2.0)), 8.0, "quadratic"),
        (LeeSacks(1.0, 0.2, 3.0, 0.5), LeeSacks(1.0, 0.2, 3.0), 4.0, "quadratic"),
        (NeoHookean(1.0, 3.0), NeoHookean(1.0, 0.0), 3.0, "log"),
    ],
)
def test_split_recombines_to_the_law(law, expected_rest, expected_modulus, kind):
    rest, U = law.split()
    assert rest == expected_rest
    assert U == VolumetricEnergy(expected_modulus, kind)
    F = random_deformations(6, seed=44)
    J = determinant(F)
    np.testing.assert_allclose(rest.psi(F) + U.energy(J), law.psi(F), rtol=1e-12)
    # pk1 of U(J) is U'(J) cof F
    cof = np.moveaxis(J[:, None, None] * np.swapaxes(np.linalg.inv(np.moveaxis(F, -1, 0)), 1, 2), 0, -1)
    assert relative_error(rest.pk1(F) + U.first_derivative(J) * cof, law.pk1(F)) < 1e-12


@pytest.mark.parametrize(
    "law",
    [Ogden((1.0,), (3.0,)), Ogden((1.0,), (3.0,), (0.1, 0.2)), LeeSacks(1.0, 0.1, 1.0), IncompressibleNeoHookean(1.0)],
)
def test_split_without_single_volumetric_term_returns_self(law):
    assert law.split() == (law, None)


def test_ogden_D_none_means_incompressible_like_lee_sacks():
    assert Ogden((1.0,), (3.0,), None) == Ogden((1.0,), (3.0,))
    assert Ogden((1.0,), (3.0,), None).incompressible


def test_incompressible_flags():
    assert Ogden((1.0,), (2.0,)).incompressible and not Ogden((1.0,), (2.0,), (1.0,)).incompressible
    assert LeeSacks(1.0, 0.1, 1.0).incompressible and not LeeSacks(1.0, 0.1, 1.0, 0.5).incompressible
    assert IncompressibleNeoHookean(1.0).incompressible and not NeoHookean(1.0, 1.0).incompressible


@pytest.mark.parametrize(
    "factory, match",
    [
        (lambda: NeoHookean(-1.0, 1.0), "parameter mu "),
        (lambda: NeoHookean(1.0, -1.0), "parameter lmbda"),
        (lambda: NeoHookean.from_shear_poisson(1.0, 0.5), "nu"),
        (lambda: NeoHookean.from_shear_poisson(1.0, 0.6), "nu"),
        (lambda: NeoHookean.from_shear_poisson(1.0, -1.0), "nu"),
        (lambda: NeoHookean.from_shear_poisson(-2.0, 0.3), "parameter G"),
        (lambda: IncompressibleNeoHookean(0.0), "parameter mu"),
        (lambda: Ogden((1.0, 2.0), (2.0,)), "mu and alpha must have the same length"),
        (lambda: Ogden((), ()), "at least one"),
        (lambda: Ogden((-1.0,), (2.0,)), r"mu\[0\]"),
        (lambda: Ogden((1.0, 1.0), (2.0, 0.0)), r"alpha\[1\]"),
        (lambda: Ogden((1.0,), (2.0,), (0.0,)), r"D\[0\]"),
        (lambda: Ogden((1.0,), (2.0,), (1.0, -1.0)), r"D\[1\]"),
        (lambda: Ogden((np.nan,), (2.0,)), "mu must be finite"),
        (lambda: Ogden.from_buchanan2014((1.0,), (2.0, 3.0)), "mu_p and alpha_p"),
        (lambda: LeeSacks(-1.0, 0.1, 1.0), "parameter c0"),
        (lambda: LeeSacks(1.0, -0.1, 1.0), "parameter c1"),
        (lambda: LeeSacks(1.0, 0.1, -1.0), "parameter c2"),
        (lambda: LeeSacks(1.0, 0.1, 1.0, 0.0), "parameter D"),
        (lambda: LeeSacks(1.0, 0.1, 1.0, 0.5, "yes"), "published_equation must be True or False"),
        (lambda: Ogden((1.0,), (2.0,), (np.nan,)), "D must be finite"),
        (lambda: VolumetricEnergy(-1.0), "modulus"),
    ],
)
def test_parameter_validation_names_the_parameter(factory, match):
    with pytest.raises(ValueError, match=match):
        factory()


@pytest.mark.parametrize("kind", ["quadratic", "log"])
def test_volumetric_energy_derivatives_match_finite_differences(kind):
    """U' and U'' (used by the mixed u/p element's K_pp) against central differences of U and U'."""
    U = VolumetricEnergy(2.5, kind)
    J, h = np.array([0.6, 0.95, 1.0, 1.3, 2.0]), 1e-6
    fd_first = (U.energy(J + h) - U.energy(J - h)) / (2 * h)
    fd_second = (U.first_derivative(J + h) - U.first_derivative(J - h)) / (2 * h)
    np.testing.assert_allclose(U.first_derivative(J), fd_first, rtol=1e-8, atol=1e-9)
    np.testing.assert_allclose(U.second_derivative(J), fd_second, rtol=1e-8)
    assert U.energy(np.array([1.0]))[0] == 0.0 and U.first_derivative(np.array([1.0]))[0] == 0.0


def test_log_volumetric_energy_rejects_non_positive_J():
    U = VolumetricEnergy(3.0, "log")
    for method in (U.energy, U.first_derivative, U.second_derivative):
        with pytest.raises(ValueError, match="J must be positive"):
            method(np.array([1.0, 0.0]))
    # the quadratic form is defined for any J (a penalty); U''(1) = k for both kinds
    assert VolumetricEnergy(3.0).second_derivative(np.array([-0.5]))[0] == 3.0
    assert U.second_derivative(np.array([1.0]))[0] == pytest.approx(3.0, rel=1e-15)


def test_non_positive_det_raises():
    F = np.diag([1.0, 1.0, -1.0])[:, :, None]
    for law in (Ogden((1.0,), (3.0,), (0.5,)), LeeSacks(1.0, 0.1, 1.0, 0.5)):
        with pytest.raises(ValueError, match="det F must be positive"):
            law.pk1(F)
