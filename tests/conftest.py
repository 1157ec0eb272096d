"""Shared fixtures: the FE² laws with model parameters of the order of thomas2019's (SI units).

The checks that use them hold for any values; the numbers are not asserted anywhere.
"""

import pytest

from skvalve.materials import ExponentialFiber, NeoHookean

FE2_G, FE2_NU, FE2_E_F, FE2_BETA, FE2_LAMBDA_C, FE2_DIAMETER = 2.1e3, 0.49, 10.5e3, 50.5, 1.12, 450e-9


@pytest.fixture(scope="module")
def fiber():
    return ExponentialFiber.from_diameter(FE2_E_F, FE2_DIAMETER, FE2_BETA, FE2_LAMBDA_C)


@pytest.fixture(scope="module")
def matrix():
    return NeoHookean.from_shear_poisson(FE2_G, FE2_NU)
