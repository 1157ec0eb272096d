"""Strings, lists or None given as a number are rejected with the parameter's name (issue 35 item 5).

Before the fix they reached numpy or a comparison and failed with Python's generic ``could not convert string to
float`` / ``'<=' not supported`` / ``float() argument must be ...`` (or, for a numeric string such as ``"1.1"``,
were silently converted). The laws already checked their constants this way
(:func:`skvalve.materials.base.check_scalar`); the same helpers now guard the analytic solutions, the FE loads, the
fiber law, the bimodular law's direction and the network generator.
"""

from __future__ import annotations

import numpy as np
import pytest

from skvalve.analytic import biaxial, uniaxial
from skvalve.analytic.rivlin import bend, moment_curvature
from skvalve.fem import Solid
from skvalve.fem.meshes import box
from skvalve.materials import BimodularNeoHookean, ExponentialFiber, IncompressibleNeoHookean, NeoHookean
from skvalve.networks.generate import generate

LAW = IncompressibleNeoHookean(1.0)
NOT_NUMBERS = ["1.1", "abc", None, ["1.1", 1.2], [1.1, None], [[1.1], [1.2, 1.3]], {"a": 1}]


def _named(name: str):
    return pytest.raises((TypeError, ValueError), match=rf"\b{name}\b")


@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_uniaxial_and_biaxial_stretch(value):
    with _named("stretch"):
        uniaxial(LAW, value)
    with _named("stretch2"):
        biaxial(LAW, 1.1, value)


@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_bend_thickness_and_curvature(value):
    with _named("thickness"):
        bend([(value, LAW)], 0.1)
    with pytest.raises((TypeError, ValueError), match=r"\ba \(the curvature change\)"):
        bend([(0.1, LAW)], value)
    with _named("curvatures"):
        moment_curvature([(0.1, LAW)], value)


@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_pressure_and_nodal_force_values(value):
    solid = Solid(box(1), NeoHookean(1.0, 2.0))
    with _named("pressure"):
        solid.add_pressure("right", value)
    with _named("force"):
        solid.add_nodal_force(lambda X: X[0] == 1.0, value)


@pytest.mark.parametrize("value", NOT_NUMBERS)
def test_fiber_stretch(value):
    fiber = ExponentialFiber(1e9, 1e-16, 2.0, 1.2)
    with _named("stretch"):
        fiber.force(value)
    with _named("stretch"):
        fiber.stiffness(value)


@pytest.mark.parametrize("value", ["x", None, [1.0, "a", 0.0], [[1.0, 0.0], [0.0]], {"x": 1}])
def test_bimodular_direction(value):
    with _named("direction"):
        BimodularNeoHookean(1.0, 0.5, direction=value)


@pytest.mark.parametrize("name", ["alpha", "mu", "alpha_tol", "mu_tol"])
@pytest.mark.parametrize("value", ["10", None, [10.0]])
def test_network_parameters(name, value):
    arguments = dict(alpha=20.0, mu=0.0, n_fibers=40, alpha_tol=3.0, mu_tol=5.0, max_attempts=1)
    arguments[name] = value
    with _named(name):
        generate(**arguments)


def test_numbers_and_arrays_still_work():
    assert uniaxial(LAW, np.array([1.1, 1.2])).cauchy.shape[-1] == 2
    assert np.isfinite(ExponentialFiber(1e9, 1e-16, 2.0, 1.2).force([1.05, 1.1])).all()
    assert BimodularNeoHookean(1.0, 0.5, direction=(1, 0, 0)).direction.tolist() == [1.0, 0.0, 0.0]
    assert bend([(np.float64(0.1), LAW)], np.float32(0.5)).moment > 0
