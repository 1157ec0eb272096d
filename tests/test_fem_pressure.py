r"""Follower pressure: inflation of a thick-walled incompressible neo-Hookean cylinder (plane strain).

Closed form (derived in docs/fem.md): with the hoop stretch :math:`\lambda = r/R`,
incompressibility :math:`r^2 - R^2 = a^2 - A^2` and radial equilibrium,

.. math::  p = \mu\Big[\ln\frac{\lambda_a}{\lambda_b} + \frac{\lambda_b^{-2} - \lambda_a^{-2}}{2}\Big].

It is checked here independently by integrating the equilibrium equation
:math:`p = \int_a^b (\sigma_{\theta\theta} - \sigma_{rr})/r\,dr` numerically.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from skvalve.fem import Solid
from skvalve.fem.meshes import annulus_sector
from skvalve.materials import IncompressibleNeoHookean

A, B, MU = 1.0, 1.5, 1.0


def closed_form_pressure(a: np.ndarray) -> np.ndarray:
    b = np.sqrt(B**2 + a**2 - A**2)
    la, lb = a / A, b / B
    return MU * (np.log(la / lb) + 0.5 * (lb**-2 - la**-2))


def test_closed_form_equals_integrated_equilibrium():
    a = 1.4
    c = a**2 - A**2

    def integrand(r):
        lam = r / np.sqrt(r**2 - c)
        return MU * (lam**2 - lam**-2) / r

    b = np.sqrt(B**2 + c)
    assert closed_form_pressure(np.array(a)) == pytest.approx(quad(integrand, a, b, epsabs=1e-13)[0], rel=1e-10)


@pytest.fixture(scope="module")
def inflation():
    mesh = annulus_sector(A, B, 4, 6)
    solid = Solid(mesh, IncompressibleNeoHookean(MU), formulation="up")
    solid.add_dirichlet("theta0", 0.0, components=[1]).add_dirichlet("theta1", 0.0, components=[0])
    p_max = 0.35
    solid.add_pressure("inner", p_max)
    result = solid.solve(steps=5, progress=False)
    return solid, result, p_max


def test_inflation_matches_closed_form(inflation):
    solid, result, p_max = inflation
    inner = np.array([[A], [0.0]])
    radii = np.array([A + result.evaluate("displacement", inner, step=k)[0, 0] for k in range(len(result))])
    pressures = p_max * np.array(result.load_factors)
    assert radii[-1] > 1.3 * A  # large deformation
    exact = closed_form_pressure(radii)
    # Q2/Q1 on a 4 x 6 curved mesh: discretisation error ~1e-5 of the pressure scale
    assert np.allclose(pressures, exact, rtol=0, atol=2e-4 * p_max)


def test_inflation_is_axisymmetric_and_isochoric(inflation):
    solid, result, _ = inflation
    angles = np.linspace(0.0, np.pi / 2, 7)
    points = A * np.vstack([np.cos(angles), np.sin(angles)]) * (1 + 1e-4)
    x = points + result.evaluate("displacement", points)
    assert np.allclose(np.hypot(*x), np.hypot(*x)[0], rtol=1e-4)
    F = result.evaluate("deformation_gradient")
    assert np.allclose(np.linalg.det(F.transpose(2, 0, 1)), 1.0, atol=1e-3)
    # global equilibrium per unit width: the pressure resultant on the inner arc is p times its
    # projected length, i.e. the deformed end coordinates (exact for any curve), balanced by the supports
    p = 0.35
    end_y = A + result.evaluate("displacement", np.array([[0.0], [A]]))[1, 0]
    end_x = A + result.evaluate("displacement", np.array([[A], [0.0]]))[0, 0]
    assert result.reaction("theta1")[0] == pytest.approx(-p * end_y, rel=1e-7)
    assert result.reaction("theta0")[1] == pytest.approx(-p * end_x, rel=1e-7)


def sphere_closed_form_pressure(a, A=1.0, B=1.5, mu=1.0):
    """Incompressible neo-Hookean thick sphere: p = mu [g(lb) - g(la)], g(l) = l^-4/2 + 2/l,
    b^3 = B^3 + a^3 - A^3 (radial equilibrium with s_tt - s_rr = mu (l^2 - l^-4), dr/r = dl/(l(1-l^3)))."""
    b = np.cbrt(B**3 + a**3 - A**3)
    la, lb = a / A, b / B
    return mu * (0.5 * lb**-4 + 2.0 / lb - 0.5 * la**-4 - 2.0 / la)


def test_sphere_closed_form_equals_integrated_equilibrium():
    a, A, B = 1.3, 1.0, 1.5
    c = a**3 - A**3

    def integrand(r):
        lam = r / np.cbrt(r**3 - c)
        return 2.0 * (lam**2 - lam**-4) / r

    b = np.cbrt(B**3 + c)
    assert sphere_closed_form_pressure(a) == pytest.approx(quad(integrand, a, b, epsabs=1e-13)[0], rel=1e-10)


def test_sphere_inflation_3d_matches_closed_form():
    """Octant of a thick sphere (B/A = 1.5), curved Q2/Q1 hexahedra (24 cells), follower pressure
    up to 0.45 mu, below the limit-point pressure 0.4935 mu of this geometry."""
    from skvalve.fem.meshes import spherical_shell_octant

    solid = Solid(spherical_shell_octant(1.0, 1.5, 2, 2), IncompressibleNeoHookean(1.0), formulation="up")
    for axis, name in enumerate(("x0", "y0", "z0")):
        solid.add_dirichlet(name, 0.0, components=[axis])
    p_max = 0.45
    solid.add_pressure("inner", p_max)
    result = solid.solve(steps=4, progress=False)
    pole = np.array([[1.0], [0.0], [0.0]])
    radii = np.array([1.0 + result.evaluate("displacement", pole, step=k)[0, 0] for k in range(len(result))])
    assert radii[-1] > 1.3
    # 24 cells: discretisation error ~1e-4 of the pressure scale (observed 4e-5)
    assert np.allclose(p_max * np.array(result.load_factors), sphere_closed_form_pressure(radii), atol=3e-4 * p_max)
