"""Continuum laws: FD consistency of stress and tangent, F = I, objectivity, small strain, validation."""

from __future__ import annotations

import numpy as np
import pytest
from _material_checks import LAWS, fd_pk1, fd_tangent, random_deformations, random_rotations, relative_error

from skvalve.kinematics import right_cauchy_green
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden

# Central differences with h = 1e-6 have truncation error ~h^2 |P'''| ~ 1e-12 and round-off
# ~eps |P| / h ~ 1e-10 (relative): 1e-7 leaves two orders of margin and still fails on any
# wrong term (a wrong term is O(1) relative).
FD_RTOL = 1e-7


def _away_from_switch(law, F):
    """For the bimodular law keep only deformations whose fibre stretch is not within FD reach of 1."""
    if not isinstance(law, BimodularNeoHookean):
        return F
    lam2 = law.fibre_stretch_squared(right_cauchy_green(F))
    return F[..., np.abs(lam2 - 1.0) > 1e-3]


@pytest.mark.parametrize("name", sorted(LAWS))
def test_tangent_matches_finite_differences_of_pk1(name):
    law = LAWS[name]
    F = _away_from_switch(law, random_deformations(12, seed=1))
    assert relative_error(law.tangent(F), fd_tangent(law, F)) < FD_RTOL


@pytest.mark.parametrize("name", sorted(LAWS))
def test_pk1_matches_finite_differences_of_psi(name):
    law = LAWS[name]
    F = _away_from_switch(law, random_deformations(12, seed=2))
    assert relative_error(law.pk1(F), fd_pk1(law, F)) < FD_RTOL


@pytest.mark.parametrize("name", sorted(LAWS))
def test_pk1_and_tangent_agree_with_separate_calls(name):
    law = LAWS[name]
    F = random_deformations(4, seed=3)
    P, A = law.pk1_and_tangent(F)
    np.testing.assert_array_equal(P, law.pk1(F))


@pytest.mark.parametrize("name", sorted(LAWS))
def test_zero_energy_and_stress_at_identity(name):
    law = LAWS[name]
    F = np.repeat(np.eye(3)[:, :, None], 2, axis=2)
    assert np.max(np.abs(law.psi(F))) < 1e-14
    assert np.max(np.abs(law.pk1(F))) < 1e-14
    assert np.max(np.abs(law.cauchy(F))) < 1e-14


@pytest.mark.parametrize("name", sorted(LAWS))
def test_objectivity(name):
    law = LAWS[name]
    F = random_deformations(6, seed=4)
    Q = random_rotations(6, seed=5)
    QF = np.einsum("ij...,jK...->iK...", Q, F)
    np.testing.assert_allclose(law.psi(QF), law.psi(F), rtol=1e-12, atol=1e-14)
    sigma = law.cauchy(F)
    rotated = np.einsum("ik...,kl...,jl...->ij...", Q, sigma, Q)
    assert relative_error(law.cauchy(QF), rotated) < 1e-12


def _linear_elasticity(G: float, lmbda: float) -> np.ndarray:
    d = np.eye(3)
    return lmbda * np.einsum("ij,kl->ijkl", d, d) + G * (
        np.einsum("ik,jl->ijkl", d, d) + np.einsum("il,jk->ijkl", d, d)
    )


SMALL_STRAIN = {
    # law, shear modulus G, Lamé lambda (None: incompressible -> deviatoric part only)
    "neo_hookean": (NeoHookean.from_shear_poisson(2.1, 0.3), 2.1, 2 * 2.1 * 0.3 / (1 - 2 * 0.3)),
    "ogden": (Ogden(mu=(0.6, 0.4), alpha=(7.0, -2.0), D=(0.4,)), 1.0, 2 / 0.4 - 2.0 / 3.0),
    "lee_sacks": (LeeSacks(1.0, 0.5, 3.0, D=0.25), 1.0, 8.0 - 2.0 / 3.0),
    "lee_sacks_published": (LeeSacks(1.0, 0.5, 3.0, D=0.25, published_equation=True), 2.5, 8.0 - 5.0 / 3.0),
    "incompressible_neo_hookean": (IncompressibleNeoHookean(3.0), 3.0, None),
    "ogden_incompressible": (Ogden(mu=(2.0, 1.0), alpha=(3.0, -2.0)), 3.0, None),
    "lee_sacks_incompressible": (LeeSacks(3.0, 1.0, 2.0), 3.0, None),
    "bimodular_compression_branch": (BimodularNeoHookean(9.0, 3.0, [0, 1, 0]), 3.0, None),
}


@pytest.mark.parametrize("name", sorted(SMALL_STRAIN))
def test_small_strain_limit_is_linear_elasticity(name):
    """Tangent at F = I equals isotropic Hooke's law with the same G and nu (deviatoric if incompressible)."""
    law, G, lmbda = SMALL_STRAIN[name]
    A = law.tangent(np.eye(3)[:, :, None])[..., 0]
    if lmbda is None:  # isochoric law: sigma = 2 G dev(eps), A = G(dd + dd) - 2G/3 d x d
        expected = _linear_elasticity(G, -2.0 * G / 3.0)
    else:
        expected = _linear_elasticity(G, lmbda)
    assert relative_error(A, expected) < 1e-13
    # and the stress of a small strain is Hooke's law applied to it
    eps = 1e-7 * np.array([[1.0, 0.3, -0.2], [0.3, -0.5, 0.1], [-0.2, 0.1, 0.4]])
    sigma = law.cauchy((np.eye(3) + eps)[:, :, None])[..., 0]
    assert relative_error(sigma, np.einsum("ijkl,kl->ij", expected, eps)) < 1e-5


def test_bimodular_small_strain_tension_branch():
    law = BimodularNeoHookean(9.0, 3.0, [0, 0, 1])
    eps = 1e-7 * np.diag([-0.5, -0.5, 1.0])
    sigma = law.cauchy((np.eye(3) + eps)[:, :, None])[..., 0]
    np.testing.assert_allclose(sigma, 2 * 9.0 * eps, rtol=1e-5)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_shapes_lists_and_batches_agree_pointwise(name):
    """F of shape (3, 3), a nested list and a (3, 3, 2, 5) batch give the per-point values."""
    law = LAWS[name]
    F = random_deformations(10, seed=6)
    if isinstance(law, BimodularNeoHookean):
        F = _away_from_switch(law, F)[..., :1].repeat(10, axis=-1)
    single = F[..., 0]
    for method, tensor_ndim in (("psi", 0), ("pk1", 2), ("cauchy", 2), ("tangent", 4)):
        value = getattr(law, method)(single)
        assert np.shape(value) == (3,) * tensor_ndim
        np.testing.assert_array_equal(getattr(law, method)(single.tolist()), value)
        batched = getattr(law, method)(F.reshape(3, 3, 2, 5))
        assert batched.shape == (3,) * tensor_ndim + (2, 5)
        expected = getattr(law, method)(F).reshape((3,) * tensor_ndim + (2, 5))
        np.testing.assert_allclose(batched, expected, rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(batched[..., 0, 0], value, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("name", sorted(LAWS))
@pytest.mark.parametrize("method", ["psi", "pk1", "cauchy", "tangent"])
def test_bad_deformations_raise_naming_the_point(name, method):
    law = LAWS[name]
    F = random_deformations(3, seed=7)
    reflected = F.copy()
    reflected[2, :, 1] *= -1.0  # det F < 0 at batch index 1
    with pytest.raises(ValueError, match=r"det F must be positive.*batch index \(1,\)"):
        getattr(law, method)(reflected)
    with pytest.raises(ValueError, match="det F must be positive"):
        getattr(law, method)(np.diag([1.0, 1.0, 0.0]))
    for bad in (np.nan, np.inf):
        broken = F.copy()
        broken[0, 1, 2] = bad  # det F is not even defined: say so, not 'det F = nan'
        with pytest.raises(ValueError, match=r"F must be finite.*batch index \(2,\)"):
            getattr(law, method)(broken)
    with pytest.raises(ValueError, match="shape"):
        getattr(law, method)(np.eye(2))


@pytest.mark.parametrize("method", ["psi", "pk1", "cauchy", "tangent"])
def test_overflow_raises_instead_of_returning_inf_or_nan(method):
    """exp(c2 (I1bar - 3)^2) overflows at stretch 3 for c2 = 1000: a ValueError, never inf/NaN."""
    law = LeeSacks(1.0, 0.1, 1000.0, 0.5)
    F = np.stack([np.eye(3), np.diag([3.0, 1.0, 1.0])], axis=-1)
    with np.errstate(all="ignore"), pytest.raises(ValueError, match=r"overflows.*batch index \(1,\)"):
        getattr(law, method)(F)
    assert np.all(np.isfinite(getattr(law, method)(F[..., :1])))
