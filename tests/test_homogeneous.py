"""Homogeneous responses (skvalve.analytic.homogeneous) against independent closed forms."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from skvalve.analytic.homogeneous import biaxial, equibiaxial, uniaxial
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden
from skvalve.materials.base import Hyperelastic

STRETCHES = np.array([0.6, 0.85, 1.0, 1.1, 1.35, 1.8])


def _ogden_uniaxial(mu, alpha, lam):
    return sum(2 * m / a * (lam**a - lam ** (-a / 2)) for m, a in zip(mu, alpha, strict=True))


@pytest.mark.parametrize(
    "law",
    [IncompressibleNeoHookean(45.0), NeoHookean(45.0, 300.0), Ogden((45.0,), (2.0,)), Ogden((45.0,), (2.0,), (0.01,))],
)
def test_neo_hookean_incompressible_closed_forms(law):
    """sigma = mu(l^2 - 1/l) uniaxial, mu(l^2 - l^-4) equibiaxial, mu(l1^2 - (l1 l2)^-2) biaxial.

    The compressible laws are asked for their incompressible limit explicitly."""
    mu = 45.0
    uni = uniaxial(law, STRETCHES, incompressible=True)
    np.testing.assert_allclose(uni.cauchy[0], mu * (STRETCHES**2 - 1 / STRETCHES), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(uni.nominal[0], mu * (STRETCHES - STRETCHES**-2), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(uni.stretches[1], STRETCHES**-0.5, rtol=1e-15)
    np.testing.assert_array_equal(uni.cauchy[1:], 0.0)
    np.testing.assert_allclose(uni.J, 1.0, rtol=1e-15)
    equi = equibiaxial(law, STRETCHES, incompressible=True)
    np.testing.assert_allclose(equi.cauchy[0], mu * (STRETCHES**2 - STRETCHES**-4), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(equi.cauchy[1], equi.cauchy[0], rtol=1e-14, atol=1e-12)
    bi = biaxial(law, 1.3, STRETCHES, incompressible=True)
    np.testing.assert_allclose(bi.cauchy[0], mu * (1.3**2 - (1.3 * STRETCHES) ** -2), rtol=1e-12)
    np.testing.assert_allclose(bi.cauchy[1], mu * (STRETCHES**2 - (1.3 * STRETCHES) ** -2), rtol=1e-12, atol=1e-12)
    assert bi.cauchy.shape == (3, STRETCHES.size) and np.all(bi.cauchy[2] == 0.0)


def test_ogden_incompressible_closed_forms():
    mu, alpha = (0.6, 0.01, 0.3), (9.0, -4.0, 2.5)
    law = Ogden(mu, alpha)
    np.testing.assert_allclose(uniaxial(law, STRETCHES).cauchy[0], _ogden_uniaxial(mu, alpha, STRETCHES), rtol=1e-11)
    equi = sum(2 * m / a * (STRETCHES**a - STRETCHES ** (-2 * a)) for m, a in zip(mu, alpha, strict=True))
    np.testing.assert_allclose(equibiaxial(law, STRETCHES).cauchy[0], equi, rtol=1e-11)


def test_lee_sacks_incompressible_closed_form():
    c0, c1, c2 = 1e-3, 1.188659e-4, 15.260081  # Texas TriValve anterior leaflet (MPa)
    x = STRETCHES**2 + 2 / STRETCHES - 3
    expected = 2 * (c0 / 2 + c1 * c2 * x * np.exp(c2 * x**2)) * (STRETCHES**2 - 1 / STRETCHES)
    compressible = LeeSacks(c0, c1, c2, 20.0669)
    np.testing.assert_allclose(uniaxial(compressible, STRETCHES, incompressible=True).cauchy[0], expected, rtol=1e-11)
    published = 2 * (c0 / 2 + c1 * c2 / 2 * np.exp(c2 * x)) * (STRETCHES**2 - 1 / STRETCHES)
    law = LeeSacks(c0, c1, c2, published_equation=True)
    np.testing.assert_allclose(uniaxial(law, STRETCHES).cauchy[0], published, rtol=1e-11)


@pytest.mark.parametrize("direction, tension_when", [([1, 0, 0], "lam>1"), ([0, 1, 0], "lam<1")])
def test_bimodular_uniaxial(direction, tension_when):
    """Along e1 the fibre is in tension for lam > 1; along e2 (lateral stretch lam^-1/2) for lam < 1."""
    law = BimodularNeoHookean(139.5, 29.55, direction)
    lam = np.array([0.8, 1.0, 1.2])
    in_tension = lam > 1 if tension_when == "lam>1" else lam < 1
    mu = np.where(in_tension, 139.5, 29.55)
    np.testing.assert_allclose(uniaxial(law, lam).cauchy[0], mu * (lam**2 - 1 / lam), rtol=1e-12, atol=1e-12)


@dataclass(frozen=True)
class _OrthotropicTestLaw(Hyperelastic):
    """psi = mu/2 (I1 - 3) + k/2 (C22 - 1)^2: coaxial with diagonal F but not isotropic (test only)."""

    mu: float = 1.0
    k: float = 3.0
    incompressible = True

    def energy_C(self, C):
        return 0.5 * self.mu * (np.trace(C) - 3) + 0.5 * self.k * (C[1, 1] - 1) ** 2

    def stress_C(self, C):
        S = self.mu * np.broadcast_to(np.eye(3).reshape((3, 3) + (1,) * (C.ndim - 2)), C.shape).copy()
        S[1, 1] += 2 * self.k * (C[1, 1] - 1)
        return S

    def elasticity_C(self, C):  # pragma: no cover - not needed here
        raise NotImplementedError


def test_uniaxial_solves_the_lateral_split_of_an_anisotropic_law():
    """Independent route: lateral stretch minimises psi(l, l2, 1/(l l2)); P1 = d(min psi)/dl (envelope)."""
    law = _OrthotropicTestLaw()

    def reduced_energy(lam):
        res = minimize_scalar(
            lambda l2: float(law.energy_C(np.diag([lam, l2, 1 / (lam * l2)]) ** 2)),
            bounds=(0.2, 3.0),
            method="bounded",
            options={"xatol": 1e-12},
        )
        return res.fun, res.x

    for lam in (0.8, 1.3):
        out = uniaxial(law, lam)
        _, lam2 = reduced_energy(lam)
        assert out.stretches[1] == pytest.approx(lam2, rel=1e-6)
        assert out.stretches[1] != pytest.approx(lam**-0.5, rel=1e-3)  # really anisotropic
        h = 1e-4
        P1 = (reduced_energy(lam + h)[0] - reduced_energy(lam - h)[0]) / (2 * h)
        assert out.nominal[0] == pytest.approx(P1, rel=1e-6)


def test_compressible_neo_hookean_uniaxial_against_independent_root():
    """sigma22 = mu/J (t^2 - 1) + lambda ln J / J = 0 (thomas2019 Eq. 13) solved here independently."""
    law = NeoHookean.from_shear_poisson(2.1, 0.3)
    mu, lm = law.mu, law.lmbda
    out = uniaxial(law, STRETCHES, incompressible=False)
    for i, lam in enumerate(STRETCHES):
        t = brentq(lambda t, lam=lam: mu * (t**2 - 1) + lm * np.log(lam * t * t), 0.1, 3.0, xtol=1e-15)
        J = lam * t * t
        assert out.stretches[1, i] == pytest.approx(t, rel=1e-12)
        assert out.J[i] == pytest.approx(J, rel=1e-12)
        assert out.cauchy[0, i] == pytest.approx(mu / J * (lam**2 - 1) + lm * np.log(J) / J, rel=1e-10, abs=1e-14)
        assert out.nominal[0, i] == pytest.approx(J * out.cauchy[0, i] / lam, rel=1e-14, abs=1e-14)
    assert np.max(np.abs(out.cauchy[1:])) < 1e-12 * np.max(np.abs(out.cauchy[0]))


def test_compressible_small_strain_poisson_ratio():
    for nu in (-0.5, 0.0, 0.3, 0.49):
        out = uniaxial(NeoHookean.from_shear_poisson(1.0, nu), 1 + 1e-6, incompressible=False)
        assert -(out.stretches[1] - 1) / 1e-6 == pytest.approx(nu, abs=1e-5)
    ogden = Ogden((0.6, 0.4), (7.0, -2.0), (0.4,))  # G = 1, K = 5 -> nu = (3K - 2G)/(6K + 2G)
    out = uniaxial(ogden, 1 + 1e-6, incompressible=False)
    assert -(out.stretches[1] - 1) / 1e-6 == pytest.approx(13 / 32, abs=1e-5)


@pytest.mark.parametrize(
    "law", [Ogden((0.6, 0.3), (9.0, -2.5), (0.5,)), LeeSacks(1e-3, 1.188659e-4, 15.260081, 20.0669)]
)
def test_compressible_biaxial_traction_free_and_direct(law):
    out = biaxial(law, 1.15, np.array([0.9, 1.0, 1.2]), incompressible=False)
    for i in range(3):
        sigma = law.cauchy(np.diag(out.stretches[:, i])[:, :, None])[..., 0]
        np.testing.assert_allclose(np.diag(sigma), out.cauchy[:, i], rtol=1e-14, atol=1e-300)
        assert abs(sigma[2, 2]) < 1e-11 * np.max(np.abs(sigma))
    eq = equibiaxial(law, 1.1, incompressible=False)
    assert eq.cauchy[0] == pytest.approx(eq.cauchy[1], rel=1e-14) and abs(eq.cauchy[2]) < 1e-11 * eq.cauchy[0]


def test_nearly_incompressible_compressible_law_approaches_incompressible_response():
    law = NeoHookean.from_shear_poisson(1.0, 0.499999)
    comp = uniaxial(law, 1.4, incompressible=False)
    inc = uniaxial(IncompressibleNeoHookean(1.0), 1.4)
    assert abs(comp.J - 1) < 1e-5
    assert comp.cauchy[0] == pytest.approx(inc.cauchy[0], rel=1e-4)


@dataclass(frozen=True)
class _AlwaysPressurised(Hyperelastic):
    """psi = p0 ln J: sigma = p0/J I never vanishes, so no traction-free state exists (test only)."""

    p0: float = 1.0

    def energy_C(self, C):
        return 0.5 * self.p0 * np.log(np.linalg.det(np.moveaxis(C, (0, 1), (-2, -1))))

    def stress_C(self, C):
        return self.p0 * np.moveaxis(np.linalg.inv(np.moveaxis(C, (0, 1), (-2, -1))), (-2, -1), (0, 1))

    def elasticity_C(self, C):  # pragma: no cover
        raise NotImplementedError


def test_errors():
    with pytest.raises(ValueError, match="no solution for the lateral stretch"):
        uniaxial(_AlwaysPressurised(), 1.2, incompressible=False)
    with pytest.raises(ValueError, match="no solution for the thickness stretch"):
        equibiaxial(_AlwaysPressurised(), 1.2, incompressible=False)
    for law in (IncompressibleNeoHookean(1.0), Ogden((1.0,), (3.0,)), BimodularNeoHookean(2.0, 1.0, [1, 0, 0])):
        with pytest.raises(ValueError, match="is incompressible"):
            uniaxial(law, 1.1, incompressible=False)
    with pytest.raises(ValueError, match="stretch must be positive"):
        uniaxial(IncompressibleNeoHookean(1.0), [1.0, -0.2])


def test_scalar_and_array_shapes():
    law = IncompressibleNeoHookean(1.0)
    assert uniaxial(law, 1.2).cauchy.shape == (3,)
    assert np.shape(uniaxial(law, 1.2).J) == ()
    assert uniaxial(law, np.ones((2, 4))).cauchy.shape == (3, 2, 4)
    assert biaxial(law, np.ones(4), 1.1).stretches.shape == (3, 4)


def test_empty_stretch_and_wrong_material():
    law = IncompressibleNeoHookean(1.0)
    empty = uniaxial(law, [])
    assert empty.cauchy.shape == (3, 0) and empty.stretches.shape == (3, 0) and empty.nominal.shape == (3, 0)
    assert biaxial(law, np.ones((0, 2)), 1.1).cauchy.shape == (3, 0, 2)
    from skvalve.materials.exponential_fiber import ExponentialFiber

    with pytest.raises(ValueError, match=r"stretch1 of shape \(2,\) and stretch2 of shape \(3,\)"):
        biaxial(law, [1.1, 1.2], [1.0, 1.1, 1.2])
    for not_a_law in ("neo-Hookean", ExponentialFiber(1.0, 1.0, 1.0, 1.1)):
        with pytest.raises(TypeError, match="continuum law"):
            uniaxial(not_a_law, 1.1)


def test_compressible_neo_hookean_biaxial_against_independent_root():
    """sigma33 = mu/J (l3^2 - 1) + lambda ln J / J = 0 (thomas2019 Eq. 13) solved here independently."""
    law = NeoHookean.from_shear_poisson(2.1, 0.45)
    mu, lm = law.mu, law.lmbda
    out = biaxial(law, 1.2, STRETCHES, incompressible=False)
    for i, lam2 in enumerate(STRETCHES):
        l3 = brentq(lambda t, lam2=lam2: mu * (t**2 - 1) + lm * np.log(1.2 * lam2 * t), 0.05, 5.0, xtol=1e-15)
        J = 1.2 * lam2 * l3
        assert out.stretches[2, i] == pytest.approx(l3, rel=1e-12)
        expected = np.array([mu / J * (1.2**2 - 1), mu / J * (lam2**2 - 1)]) + lm * np.log(J) / J
        np.testing.assert_allclose(out.cauchy[:2, i], expected, rtol=1e-10, atol=1e-13)


def test_compressible_law_must_choose_the_solve():
    """A compressible law used to be solved as incompressible when ``incompressible`` was left out."""
    law = NeoHookean.from_shear_poisson(1.0, 0.3)
    for solve in (lambda: uniaxial(law, 1.2), lambda: equibiaxial(law, 1.2), lambda: biaxial(law, 1.2, 1.1)):
        with pytest.raises(ValueError, match="NeoHookean is compressible: choose incompressible=False"):
            solve()
    with pytest.raises(TypeError, match="incompressible must be True, False or None"):
        uniaxial(law, 1.2, incompressible="no")
    # each explicit choice gives its own, different answer: free lateral stretch (J ≠ 1) vs J = 1
    own, limit = uniaxial(law, 1.2, incompressible=False), uniaxial(law, 1.2, incompressible=True)
    assert abs(own.J - 1.0) > 0.05 and limit.J == pytest.approx(1.0, abs=1e-14)
    assert own.cauchy[1] == pytest.approx(0.0, abs=1e-12) and limit.cauchy[1] == pytest.approx(0.0, abs=1e-12)
    # an incompressible law needs no keyword (and refuses False)
    assert uniaxial(IncompressibleNeoHookean(1.0), 1.2).cauchy[0] == pytest.approx(1.2**2 - 1 / 1.2, rel=1e-12)
