"""skvalve.kinematics against numpy and closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from _material_checks import random_deformations, random_rotations

from skvalve import kinematics as kin

F = random_deformations(7, seed=51)
F_FIRST = np.moveaxis(F, -1, 0)  # (n, 3, 3) for numpy.linalg


def test_cauchy_green_determinant_inverse_cofactor_vs_numpy():
    np.testing.assert_allclose(
        np.moveaxis(kin.right_cauchy_green(F), -1, 0), np.swapaxes(F_FIRST, 1, 2) @ F_FIRST, rtol=1e-14
    )
    np.testing.assert_allclose(
        np.moveaxis(kin.left_cauchy_green(F), -1, 0), F_FIRST @ np.swapaxes(F_FIRST, 1, 2), rtol=1e-14
    )
    np.testing.assert_allclose(kin.determinant(F), np.linalg.det(F_FIRST), rtol=1e-13)
    np.testing.assert_allclose(np.moveaxis(kin.inverse(F), -1, 0), np.linalg.inv(F_FIRST), rtol=1e-12, atol=1e-14)
    cof = np.linalg.det(F_FIRST)[:, None, None] * np.swapaxes(np.linalg.inv(F_FIRST), 1, 2)
    np.testing.assert_allclose(np.moveaxis(kin.cofactor(F), -1, 0), cof, rtol=1e-12, atol=1e-14)


def test_invariants_vs_numpy_eigenvalues():
    C = np.swapaxes(F_FIRST, 1, 2) @ F_FIRST
    eig = np.linalg.eigvalsh(C)
    I1, I2, I3 = kin.invariants(F)
    np.testing.assert_allclose(I1, eig.sum(axis=1), rtol=1e-13)
    np.testing.assert_allclose(I2, eig[:, 0] * eig[:, 1] + eig[:, 1] * eig[:, 2] + eig[:, 0] * eig[:, 2], rtol=1e-13)
    np.testing.assert_allclose(I3, eig.prod(axis=1), rtol=1e-13)
    np.testing.assert_allclose(kin.isochoric_first_invariant(F), I3 ** (-1 / 3) * I1, rtol=1e-13)
    np.testing.assert_allclose(kin.principal_stretches(F).T, np.sqrt(eig), rtol=1e-13)


def test_polar_decomposition():
    R, U = kin.polar_decomposition(F)
    R_, U_ = np.moveaxis(R, -1, 0), np.moveaxis(U, -1, 0)
    np.testing.assert_allclose(R_ @ U_, F_FIRST, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(np.swapaxes(R_, 1, 2) @ R_, np.broadcast_to(np.eye(3), R_.shape), atol=1e-13)
    np.testing.assert_allclose(np.linalg.det(R_), 1.0, rtol=1e-13)
    np.testing.assert_allclose(U_, np.swapaxes(U_, 1, 2), atol=1e-14)
    assert np.all(np.linalg.eigvalsh(U_) > 0)
    # a known rotation of a known stretch is recovered
    Q = random_rotations(1, seed=52)[..., 0]
    stretch = np.array([[1.2, 0.1, 0.0], [0.1, 0.9, 0.05], [0.0, 0.05, 1.1]])
    R1, U1 = kin.polar_decomposition((Q @ stretch)[:, :, None])
    np.testing.assert_allclose(R1[..., 0], Q, atol=1e-13)
    np.testing.assert_allclose(U1[..., 0], stretch, atol=1e-13)
    with pytest.raises(ValueError, match="det F > 0"):
        kin.polar_decomposition(np.diag([1.0, 1.0, -1.0])[:, :, None])


def test_log_strain_of_uniaxial_stretch_and_rotation():
    lam = 1.37
    F1 = np.diag([lam, 1.0, 1.0])[:, :, None]
    for spatial in (True, False):
        h = kin.log_strain(F1, spatial=spatial)[..., 0]
        np.testing.assert_allclose(h, np.diag([np.log(lam), 0.0, 0.0]), atol=1e-15)
    # spatial strain rotates with F, material strain does not
    Q = random_rotations(1, seed=53)[..., 0]
    QF = np.einsum("ij,jK...->iK...", Q, F)
    np.testing.assert_allclose(kin.log_strain(QF, spatial=False), kin.log_strain(F, spatial=False), atol=1e-13)
    np.testing.assert_allclose(kin.log_strain(QF), np.einsum("ik,kl...,jl->ij...", Q, kin.log_strain(F), Q), atol=1e-13)


def test_green_lagrange_and_identity_like():
    E = kin.green_lagrange(F)
    np.testing.assert_allclose(
        np.moveaxis(E, -1, 0), 0.5 * (np.swapaxes(F_FIRST, 1, 2) @ F_FIRST - np.eye(3)), rtol=1e-13, atol=1e-15
    )
    eye = kin.identity_like(np.zeros((3, 3, 2, 5)))
    assert eye.shape == (3, 3, 2, 5) and np.all(eye[..., 1, 3] == np.eye(3))


def test_bad_input():
    with pytest.raises(ValueError, match="shape"):
        kin.right_cauchy_green(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="singular"):
        kin.inverse(np.zeros((3, 3, 1)))
    nan_F = F.copy()
    nan_F[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match=r"non-finite.*batch index \(3,\)"):
        kin.inverse(nan_F)
    for fun in (kin.polar_decomposition, kin.log_strain):
        with pytest.raises(ValueError, match="finite F"):
            fun(nan_F)
        with pytest.raises(ValueError, match="det F > 0"):
            fun(np.diag([1.0, -1.0, 1.0]))
