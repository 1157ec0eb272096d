"""Fit of (G, E_f, β, λc) with the homogeneous RVE model (thomas2019 §2.6): recovery of known parameters."""

import numpy as np
import pytest

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.materials.neo_hookean import NeoHookean
from skvalve.multiscale.fit import BiaxialData, FiberParameters, Setting, fit_parameters, r_squared
from skvalve.multiscale.homogeneous import HomogeneousBiaxial
from skvalve.multiscale.material import RVEMaterial
from skvalve.networks.generate import generate

TRUE = FiberParameters(G=2.1e3, E_f=10.5e3, beta=50.5, lambda_c=1.12)


@pytest.fixture(scope="module")
def setting():
    nets = [generate(35.0, 0.0, n_fibers=60, seed=s) for s in range(2)]
    return Setting(nets, nu=0.49, psi=0.43, diameter=450e-9, thickness=0.406e-3)


def synthetic(setting, ratio, levels=5, max_tension=40.0):
    """Tension-controlled path of the model itself (a different solve from the fit's stretch-controlled one)."""
    matrix = NeoHookean.from_shear_poisson(TRUE.G, setting.nu)
    fiber = ExponentialFiber.from_diameter(TRUE.E_f, setting.diameter, TRUE.beta, TRUE.lambda_c)
    model = HomogeneousBiaxial(RVEMaterial(setting.networks, matrix, fiber, n_points=1), setting.thickness)
    goal = max_tension * np.array(ratio) / max(ratio)
    states = model.solve(goal, increments=levels)
    return BiaxialData(f"{ratio[0]}:{ratio[1]}", [s.stretches[:2] for s in states], [s.tensions for s in states])


def test_fit_recovers_known_parameters_with_and_without_noise(setting):
    data = [synthetic(setting, (1.0, 1.0)), synthetic(setting, (1.0, 0.5))]
    start = FiberParameters(G=2.5e3, E_f=9.0e3, beta=45.0, lambda_c=1.13)
    result = fit_parameters(data, setting, start)
    for name in ("G", "E_f", "beta", "lambda_c"):
        assert getattr(result.params, name) == pytest.approx(getattr(TRUE, name), rel=1e-4), name
    assert result.r2_overall == pytest.approx(1.0, abs=1e-10)
    rng = np.random.default_rng(0)
    noisy = [BiaxialData(d.label, d.stretch, d.tension + 0.5 * rng.standard_normal(d.tension.shape)) for d in data]
    noisy_fit = fit_parameters(noisy, setting, start)
    assert 0.98 < noisy_fit.r2_overall < 1.0
    assert noisy_fit.params.lambda_c == pytest.approx(TRUE.lambda_c, rel=0.02)
    assert noisy_fit.params.beta == pytest.approx(TRUE.beta, rel=0.25)


def test_r_squared_eq12():
    y = np.array([1.0, 2.0, 3.0, 4.0])
    assert r_squared(y, y) == 1.0
    assert r_squared(y, np.full(4, 2.5)) == 0.0
    assert r_squared(y, y + [0.1, -0.1, 0.1, -0.1]) == pytest.approx(1 - 0.04 / 5.0)
