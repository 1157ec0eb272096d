"""Orientation tensor, α and μ (Thomas 2019 Eqs. 1–3) against closed forms."""

import numpy as np
import pytest
from scipy.special import i0, i1

from skvalve.networks.network import Network
from skvalve.networks.orientation import (
    anisotropy_index,
    mean_direction,
    network_alpha_mu,
    orientation_tensor,
    project,
)


def von_mises_alpha(kappa):
    """α of the axial von Mises density ∝ exp(κ cos 2(θ − μ)) from Bessel functions."""
    rho = i1(kappa) / i0(kappa)
    return 200.0 * rho / (1.0 + rho)


def test_uniform_distribution_is_isotropic():
    theta = np.linspace(0, np.pi, 360, endpoint=False)  # exact quadrature of cos², sin²
    H = orientation_tensor(theta)
    np.testing.assert_allclose(H, 0.5 * np.eye(2), atol=1e-15)
    assert anisotropy_index(H) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("mu", [0.0, 30.0, -75.0, 90.0])
def test_single_direction_is_fully_aligned(mu):
    H = orientation_tensor(np.full(5, np.radians(mu)) + np.array([0, np.pi, 0, -np.pi, 0]))
    assert anisotropy_index(H) == pytest.approx(100.0, abs=1e-10)
    assert mean_direction(H) == pytest.approx(mu, abs=1e-9)


@pytest.mark.parametrize("kappa, mu", [(0.3, 10.0), (1.0, -40.0), (3.0, 75.0)])
def test_von_mises_quadrature_matches_bessel_closed_form(kappa, mu):
    theta = np.linspace(-np.pi / 2, np.pi / 2, 720, endpoint=False)
    density = np.exp(kappa * np.cos(2 * (theta - np.radians(mu))))
    H = orientation_tensor(theta, weights=density)
    assert anisotropy_index(H) == pytest.approx(von_mises_alpha(kappa), abs=1e-10)
    assert mean_direction(H) == pytest.approx(mu, abs=1e-9)


def test_von_mises_samples_within_sampling_error():
    rng = np.random.default_rng(3)
    kappa, mu, n = 1.5, 20.0, 200_000
    theta = rng.vonmises(0.0, kappa, n) / 2 + np.radians(mu)  # axial von Mises
    H = orientation_tensor(theta)
    # standard error of α for n samples is ~0.2 %; 1 % is five of them
    assert anisotropy_index(H) == pytest.approx(von_mises_alpha(kappa), abs=1.0)
    assert mean_direction(H) == pytest.approx(mu, abs=0.5)


def test_axial_symmetry_and_rotation():
    rng = np.random.default_rng(0)
    theta = rng.uniform(-0.3, 0.5, 50)
    w = rng.uniform(0.1, 1.0, 50)
    H = orientation_tensor(theta, w)
    np.testing.assert_allclose(orientation_tensor(theta + np.pi, w), H, atol=1e-14)
    shift = 0.4
    assert mean_direction(orientation_tensor(theta + shift, w)) == pytest.approx(
        mean_direction(H) + np.degrees(shift), abs=1e-9
    )
    assert anisotropy_index(orientation_tensor(theta + shift, w)) == pytest.approx(anisotropy_index(H), abs=1e-9)


def test_plain_lists_are_accepted():
    H = orientation_tensor([0.0, np.pi / 2, 0.0])  # two fibers along x, one along y
    np.testing.assert_allclose(H, np.diag([2 / 3, 1 / 3]), atol=1e-15)
    assert anisotropy_index(H.tolist()) == pytest.approx(50.0, abs=1e-12)
    assert mean_direction(H.tolist()) == pytest.approx(0.0, abs=1e-12)


def test_projection_weights_by_projected_length():
    # two fibers along x (length 1 and 2 in plane) and one along z (projects to a point)
    nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0.0], [0, 2, 0.5], [0, 0, 0], [0, 0, 1]], dtype=float)
    net = Network(nodes, [[0, 1], [2, 3], [4, 5]], np.zeros(6, bool), np.full(6, -1))
    angles, lengths = project(net)
    np.testing.assert_allclose(lengths, [1, 2, 0], atol=1e-15)
    np.testing.assert_allclose(angles[:2], [0, np.pi / 2], atol=1e-15)
    H = orientation_tensor(angles, lengths)
    np.testing.assert_allclose(H, np.diag([1 / 3, 2 / 3]), atol=1e-15)
    alpha, mu = network_alpha_mu(net)
    assert alpha == pytest.approx(50.0) and mu == pytest.approx(90.0)
    # projecting on the xz plane sees the z fiber and the x fiber
    angles_xz, lengths_xz = project(net, normal=(0, 1, 0))
    np.testing.assert_allclose(lengths_xz, [1, 0.5, 1], atol=1e-15)


_TWO_FIBERS = Network(
    np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), [[0, 1], [0, 2]], np.zeros(3, bool), np.full(3, -1)
)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: orientation_tensor([]), "empty"),
        (lambda: orientation_tensor([0.1, np.nan]), "non-finite"),
        (lambda: orientation_tensor([0.1, 0.2], [1.0]), "weights shape"),
        (lambda: orientation_tensor([0.1], [-1.0]), "non-negative"),
        (lambda: orientation_tensor([0.1], [0.0]), "sum to zero"),
        (lambda: anisotropy_index(np.eye(3)), "2x2"),
        # used to give α = 150 %: H with a negative eigenvalue is no orientation tensor
        (lambda: anisotropy_index(np.diag([-1.0, 2.0])), "positive semi-definite"),
        # used to be silently symmetrised
        (lambda: anisotropy_index([[0.5, 0.3], [0.0, 0.5]]), "symmetric"),
        (lambda: mean_direction([[0.5, 0.3], [0.0, 0.5]]), "symmetric"),
        (lambda: project(_TWO_FIBERS, normal=(0.0, 0.0, 0.0)), "non-zero 3-vector"),
        (lambda: project(_TWO_FIBERS, normal=(0.0, 1.0)), "non-zero 3-vector"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()
