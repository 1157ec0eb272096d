"""FE² quadrature-point material (thomas2019 §2.4): stress, tangent, commit/rewind, affine limit.

References are independent of the coupling: ``solve_rve`` per point (cold-started), the
matrix law on its own, finite differences, and the first Piola–Kirchhoff affine model.
"""

import math

import numpy as np
import pytest
from _fe2_networks import affine_network

from skvalve.multiscale.affine import AffineFiberModel
from skvalve.multiscale.material import RVEMaterial, cauchy_to_pk1
from skvalve.networks.generate import generate
from skvalve.networks.network import Network
from skvalve.networks.rve import solve_rve

# model parameters of the order of the paper's (SI units); the checks hold for any values
G, NU, E_F, BETA, LAMBDA_C, DIAMETER = 2.1e3, 0.49, 10.5e3, 50.5, 1.12, 450e-9
TOL = 1e-12  # RVE force balance, tight so that 1e-10 comparisons and finite differences are meaningful


@pytest.fixture(scope="module")
def networks():
    return [generate(30.0, 0.0, n_fibers=80, seed=1), generate(45.0, 60.0, n_fibers=80, seed=2)]


def random_F(rng, n_points, n_elements, size=0.08):
    """Deformation gradients near a biaxial stretch, shape (3, 3, n_points, n_elements)."""
    base = np.diag([1.10, 1.06, 0.86])
    F = base[:, :, None, None] + size * rng.uniform(-1, 1, (3, 3, n_points, n_elements))
    return F


def test_stress_equals_matrix_plus_solve_rve_at_every_point(fiber, matrix, networks):
    rng = np.random.default_rng(0)
    F = random_F(rng, 2, 2)
    material = RVEMaterial(networks, matrix, fiber, n_points=2, tol=TOL)
    sigma = material.cauchy(F)
    for e, net in enumerate(networks):
        for q in range(2):
            rve = solve_rve(net, F[:, :, q, e], fiber, material.psi, material.fiber_diameter, tol=TOL)
            expected = matrix.cauchy(F[:, :, q, e]) + rve.cauchy
            np.testing.assert_allclose(sigma[:, :, q, e], expected, rtol=0, atol=1e-10 * np.abs(expected).max())


def test_pk1_is_J_sigma_F_inverse_transpose(fiber, matrix, networks):
    F = random_F(np.random.default_rng(1), 2, 2)
    material = RVEMaterial(networks, matrix, fiber, n_points=2, tol=TOL)
    P = material.pk1(F)
    for e in range(2):
        for q in range(2):
            Fq = F[:, :, q, e]
            expected = np.linalg.det(Fq) * material.cauchy(F)[:, :, q, e] @ np.linalg.inv(Fq).T
            np.testing.assert_allclose(P[:, :, q, e], expected, atol=1e-10 * np.abs(expected).max())


def test_tangent_matches_central_differences_with_rves_resolved(fiber, matrix, networks):
    rng = np.random.default_rng(2)
    F = random_F(rng, 1, 2)
    material = RVEMaterial(networks, matrix, fiber, n_points=1, tol=TOL)
    material.commit()
    _, A = material.pk1_and_tangent(F)
    h = 1e-6
    numeric = np.zeros_like(A)
    for k in range(3):
        for L in range(3):
            dF = np.zeros_like(F)
            dF[k, L] = h
            numeric[:, :, k, L] = (material.pk1(F + dF) - material.pk1(F - dF)) / (2 * h)
    scale = np.abs(A).max()
    np.testing.assert_allclose(A, numeric, rtol=0, atol=1e-6 * scale)


def test_cauchy_to_pk1_tangent_against_finite_differences():
    """The conversion alone, for a σ(F) with a closed-form dσ/dF (σ = F Fᵀ, T_ijkL = δ_ik F_jL + F_iL δ_jk)."""
    rng = np.random.default_rng(3)
    F = np.eye(3)[:, :, None] + 0.2 * rng.uniform(-1, 1, (3, 3, 4))
    eye = np.eye(3)

    def sigma_and_T(F):
        sigma = np.einsum("iK...,jK...->ij...", F, F)
        T = np.einsum("ik,jL...->ijkL...", eye, F) + np.einsum("iL...,jk->ijkL...", F, eye)
        return sigma, T

    _, A = cauchy_to_pk1(F, *sigma_and_T(F))
    h = 1e-6
    for k in range(3):
        for L in range(3):
            dF = np.zeros_like(F)
            dF[k, L] = h
            plus = cauchy_to_pk1(F + dF, sigma_and_T(F + dF)[0], None)[0]
            minus = cauchy_to_pk1(F - dF, sigma_and_T(F - dF)[0], None)[0]
            np.testing.assert_allclose(A[:, :, k, L], (plus - minus) / (2 * h), atol=1e-8)


def test_commit_and_rewind_restore_state_bit_for_bit(fiber, matrix, networks):
    rng = np.random.default_rng(4)
    F1 = random_F(rng, 2, 2, size=0.02)
    material = RVEMaterial(networks, matrix, fiber, n_points=2)
    material.pk1_and_tangent(F1)
    material.commit()
    committed = material.state()
    F2 = F1 + 0.05 * rng.uniform(-1, 1, F1.shape)
    P_before, A_before = material.pk1_and_tangent(F2)
    material.pk1_and_tangent(F2 + 0.1 * np.eye(3)[:, :, None, None])  # a failed attempt
    material.rewind()
    after = material.state()
    for name in ("positions", "F", "sensitivity", "fiber_stretch"):
        assert np.array_equal(getattr(after, name), getattr(committed, name)), name
    P_again, A_again = material.pk1_and_tangent(F2)
    assert np.array_equal(P_again, P_before) and np.array_equal(A_again, A_before)


def test_commit_moves_the_warm_start(fiber, matrix, networks):
    F = random_F(np.random.default_rng(5), 2, 2, size=0.02)
    material = RVEMaterial(networks, matrix, fiber, n_points=2)
    material.cauchy(F)
    before = material.state()
    material.commit()
    after = material.state()
    assert not np.array_equal(before.positions, after.positions)
    np.testing.assert_array_equal(after.F, F.transpose(3, 2, 0, 1).reshape(-1, 3, 3))
    np.testing.assert_array_equal(material.committed_fiber_stretch(1, 1).shape, (networks[1].n_fibers,))


def test_all_boundary_networks_give_the_affine_fiber_model(fiber, matrix):
    nets = [affine_network(1), affine_network(2)]
    F = random_F(np.random.default_rng(6), 3, 2, size=0.1)
    material = RVEMaterial(nets, matrix, fiber, n_points=3)
    affine = AffineFiberModel(nets, fiber, n_points=3)
    P, A = material.pk1_and_tangent(F)
    P_matrix, A_matrix = matrix.pk1_and_tangent(F)
    P_affine, A_affine = affine.pk1_and_tangent(F)
    np.testing.assert_allclose(P - P_matrix, P_affine, rtol=0, atol=1e-10 * np.abs(P_affine).max())
    np.testing.assert_allclose(A - A_matrix, A_affine, rtol=0, atol=1e-10 * np.abs(A_affine).max())
    np.testing.assert_allclose(material.fiber_cauchy(F), affine.cauchy(F), atol=1e-10 * np.abs(P_affine).max())


def test_affine_model_fiber_stress_by_hand(fiber):
    """One fiber along x through the cube: σ_xx = ψ f(λ)/A_f, with L = 1 (Eq. 8)."""
    net = Network([[-0.5, 0.1, 0.0], [0.5, 0.1, 0.0]], [[0, 1]], [True, True], [0, 1])
    lam = 1.1
    F = np.diag([lam, 1.0, 1.0])[:, :, None, None]
    sigma = AffineFiberModel([net], fiber, n_points=1).cauchy(F)[:, :, 0, 0]
    area = math.pi * DIAMETER**2 / 4
    force = E_F * area / BETA * (math.exp(BETA * 0.5 * (lam**2 - 1)) - 1)
    assert sigma[0, 0] == pytest.approx(0.43 * force / area, rel=1e-12)


def test_bad_input_is_named(fiber, matrix, networks):
    material = RVEMaterial(networks, matrix, fiber, n_points=2)
    with pytest.raises(ValueError, match="shape"):
        material.cauchy(np.ones((3, 3, 2, 3)))
    F = np.tile(np.eye(3)[:, :, None, None], (1, 1, 2, 2))
    F[0, 0, 1, 1] = -1.0
    with pytest.raises(ValueError, match="element 1, point 1"):
        material.cauchy(F)
    with pytest.raises(TypeError, match="NeoHookean"):
        RVEMaterial(networks, object(), fiber)
