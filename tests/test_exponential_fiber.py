"""ExponentialFiber (Thomas 2019 Eq. 9): closed-form values, FD stiffness, C¹ at λc, validation."""

import math

import numpy as np
import pytest

from skvalve.materials.exponential_fiber import ExponentialFiber

PAPER = dict(E_f=10.5e3, beta=50.5, lambda_c=1.12)


@pytest.fixture
def fiber():
    return ExponentialFiber.from_diameter(diameter=450e-9, **PAPER)


def test_area_from_diameter(fiber):
    assert fiber.A_f == pytest.approx(math.pi * (450e-9) ** 2 / 4, rel=1e-15)


def test_force_matches_eq9_by_hand(fiber):
    ea = 10.5e3 * fiber.A_f
    lam = 1.05
    expected_below = ea / 50.5 * (math.exp(50.5 * 0.5 * (lam**2 - 1)) - 1)
    assert fiber.force(lam) == pytest.approx(expected_below, rel=1e-13)
    lam = 1.3
    ec = 0.5 * (1.12**2 - 1)
    expected_above = ea / 50.5 * (math.exp(50.5 * ec) - 1) + ea * 1.12 * math.exp(50.5 * ec) * (lam - 1.12)
    assert fiber.force(lam) == pytest.approx(expected_above, rel=1e-13)
    assert fiber.force(1.0) == 0.0


@pytest.mark.parametrize("compression", ["paper", "buckle"])
def test_stiffness_is_derivative_of_force(compression):
    fiber = ExponentialFiber(2.0, 3.0, 10.0, 1.2, compression=compression)
    lam = np.concatenate([np.linspace(0.6, 0.99, 7), np.linspace(1.01, 1.19, 9), [1.25, 1.6]])
    h = 1e-6
    fd = (fiber.force(lam + h) - fiber.force(lam - h)) / (2 * h)
    np.testing.assert_allclose(fiber.stiffness(lam), fd, rtol=1e-8)


def test_c1_continuity_at_critical_stretch(fiber):
    lc, eps = 1.12, 1e-10
    f_minus, f_plus = fiber.force(lc - eps), fiber.force(lc + eps)
    k_minus, k_plus = fiber.stiffness(lc - eps), fiber.stiffness(lc + eps)
    # a jump would be O(1) relative; a C¹ law changes by k·2ε in force and O(ε) in stiffness
    assert abs(f_plus - f_minus) <= 4 * eps * k_plus
    assert abs(k_plus - k_minus) <= 1e-7 * abs(k_plus)
    # linear above λc: the stiffness is constant
    np.testing.assert_allclose(fiber.stiffness([1.2, 1.5, 2.0]), k_plus, rtol=1e-14)


def test_compression_modes():
    paper = ExponentialFiber(1.0, 1.0, 50.5, 1.12)
    buckle = ExponentialFiber(1.0, 1.0, 50.5, 1.12, compression="buckle", slack_stiffness=0.0)
    lam = np.array([0.3, 0.7, 0.95])
    # paper's form: compressive, bounded below by -E_f A_f / β
    assert np.all(paper.force(lam) < 0) and np.all(paper.force(lam) > -1 / 50.5)
    np.testing.assert_array_equal(buckle.force(lam), 0.0)
    np.testing.assert_allclose(buckle.force([1.05]), paper.force([1.05]), rtol=1e-15)


def test_vectorised_shapes(fiber):
    lam = np.full((2, 3), 1.1)
    assert fiber.force(lam).shape == (2, 3) and fiber.stiffness(lam).shape == (2, 3)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(E_f=-1, A_f=1, beta=1, lambda_c=1.1), "E_f"),
        (dict(E_f=1, A_f=0, beta=1, lambda_c=1.1), "A_f"),
        (dict(E_f=1, A_f=1, beta=float("nan"), lambda_c=1.1), "beta"),
        (dict(E_f=1, A_f=1, beta=1, lambda_c=0.9), "lambda_c"),
        (dict(E_f=1, A_f=1, beta=1, lambda_c=1.1, compression="none"), "compression"),
    ],
)
def test_validation_names_parameter(kwargs, name):
    with pytest.raises(ValueError, match=name):
        ExponentialFiber(**kwargs)


def test_bad_stretch_and_diameter(fiber):
    with pytest.raises(ValueError, match="stretch"):
        fiber.force([1.0, -0.1])
    with pytest.raises(ValueError, match="diameter"):
        ExponentialFiber.from_diameter(1.0, 0.0, 1.0, 1.1)


@pytest.mark.parametrize("compression", ["paper", "buckle"])
def test_energy_derivative_is_force(compression):
    fiber = ExponentialFiber(2.0, 3.0, 50.5, 1.12, compression=compression)
    lam = np.array([0.6, 0.9, 0.999, 1.05, 1.11, 1.13, 1.4])
    h = 1e-6
    fd = (fiber.energy(lam + h) - fiber.energy(lam - h)) / (2 * h)
    np.testing.assert_allclose(fd, fiber.force(lam), rtol=1e-7, atol=1e-9 * fiber.axial_rigidity)
    assert fiber.energy(1.0) == 0.0 and np.all(fiber.energy(lam) >= 0)


def test_overflow_raises_naming_the_stretch():
    """exp(β e_G) leaves float range for β = 1e4 at λ = 1.09 (β e_G ≈ 940 > 709): ValueError, not inf."""
    steep = ExponentialFiber(1.0, 1.0, 1e4, 1.1)
    for method in (steep.force, steep.stiffness, steep.energy):
        with pytest.raises(ValueError, match="overflows at stretch 1.09"):
            method([1.0, 1.09])
        assert np.isfinite(method(1.0))


@pytest.mark.parametrize("beta", [1e-17, 1e-12, 1e-9])
def test_small_beta_gives_the_linear_limit(beta):
    """(exp(β e) − 1)/β lost every digit for tiny β (β = 1e-17 gave force 0, not e_G = 0.105 at λ = 1.1)."""
    fiber = ExponentialFiber(1.0, 1.0, beta, 1.5)
    lam = np.array([0.9, 1.1, 1.3, 1.7])
    strain = 0.5 * (np.minimum(lam, 1.5) ** 2 - 1)  # e_G, capped at λc for the linear branch
    # f = e_G (1 + β e_G/2 + …) below λc; above, f(λc) + λc (1 + β e_c) (λ − λc)
    expected = np.where(lam < 1.5, strain, strain + 1.5 * (lam - 1.5))
    np.testing.assert_allclose(fiber.force(lam), expected, rtol=10 * beta + 1e-15)
    assert fiber.force(1.1) == pytest.approx(0.105, rel=10 * beta + 1e-14)
    # the energy ∫ f dλ: for λ < λc, ∫₁^λ (s² − 1)/2 ds = (λ³ − 1)/6 − (λ − 1)/2
    assert fiber.energy(1.1) == pytest.approx((1.1**3 - 1) / 6 - 0.05, rel=10 * beta + 1e-13)


@pytest.mark.parametrize("bad", ["10.5e3", None, np.array([1.0, 2.0]), True, [1.0]])
def test_parameters_must_be_real_numbers(bad):
    for name, args in (
        ("E_f", (bad, 1.0, 50.5, 1.12)),
        ("A_f", (1.0, bad, 50.5, 1.12)),
        ("beta", (1.0, 1.0, bad, 1.12)),
        ("lambda_c", (1.0, 1.0, 50.5, bad)),
    ):
        with pytest.raises(TypeError, match=f"ExponentialFiber: parameter {name} must be a real number"):
            ExponentialFiber(*args)
    with pytest.raises(TypeError, match="slack_stiffness"):
        ExponentialFiber(1.0, 1.0, 50.5, 1.12, slack_stiffness=bad)
    with pytest.raises(TypeError, match="diameter"):
        ExponentialFiber.from_diameter(1.0, bad, 50.5, 1.12)
