"""Amplitudes against their defining properties (end values, zero slope and curvature at the points for the
smooth step, symmetry, monotonicity; linear interpolation for tabular)."""

import numpy as np
import pytest

from skvalve.fem.amplitudes import SmoothStep, Tabular, smooth_step_polynomial


def test_smooth_step_polynomial_defining_properties():
    h = 1e-5
    s = smooth_step_polynomial
    assert s(0.0) == 0.0 and s(1.0) == 1.0
    for x in (0.0, 1.0):  # one-sided differences: first and second derivative vanish at both ends
        inside = h if x == 0.0 else -h
        assert abs((s(x + inside) - s(x)) / inside) < 1e-8
        assert abs((s(x + 2 * inside) - 2 * s(x + inside) + s(x)) / inside**2) < 1e-3
    xi = np.linspace(0, 1, 101)
    assert np.allclose(s(xi) + s(1 - xi), 1.0)  # odd symmetry about (1/2, 1/2)
    assert np.all(np.diff(s(xi)) > 0)
    # slope at the middle: 30 xi^2 (1 - xi)^2 = 15/8
    assert (s(0.5 + h) - s(0.5 - h)) / (2 * h) == pytest.approx(15 / 8, rel=1e-8)


def test_smooth_step_between_points_and_outside():
    amp = SmoothStep((0.5, 1.5), (0.0, 1.0), name="Amp-1")  # the pressure amplitude of the TriValve inputs
    assert amp(0.0) == 0.0 and amp(0.5) == 0.0 and amp(1.5) == 1.0 and amp(2.0) == 1.0
    assert amp(1.0) == pytest.approx(0.5)
    assert amp(0.75) == pytest.approx(0.25**3 * (10 - 15 * 0.25 + 6 * 0.25**2))
    three = SmoothStep((0.0, 1.0, 3.0), (2.0, -1.0, 5.0))
    assert np.allclose(three([0.0, 1.0, 3.0]), [2.0, -1.0, 5.0])
    assert three(2.0) == pytest.approx(-1.0 + 6.0 * 0.5)


def test_tabular_is_piecewise_linear():
    amp = Tabular((0.0, 1.0, 2.0), (0.0, 2.0, 1.0))
    assert np.allclose(amp([-1.0, 0.5, 1.5, 3.0]), [0.0, 1.0, 1.5, 1.0])
    assert Tabular((0.3,), (4.0,))(7.0) == 4.0


@pytest.mark.parametrize("times, values, message", [
    ((1.0, 0.5), (0.0, 1.0), "increasing"),
    ((0.0, 1.0), (0.0,), "as many"),
    ((0.0, np.nan), (0.0, 1.0), "finite"),
])
def test_bad_amplitudes_are_rejected(times, values, message):
    with pytest.raises(ValueError, match=message):
        SmoothStep(times, values, name="bad")
