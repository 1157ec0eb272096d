"""Bending without locking: plane-strain cantilever, nearly incompressible neo-Hookean (nu = 0.4999).

Clamped at x = 0, the end face x = L moved down uniformly by a small d (u_x free there);
the end stiffness k = F/d is compared with Timoshenko beam theory for plane strain and
nu -> 1/2: compliance 1/k = L^3/(mu H^3) + 1.2 L/(mu H) (E' = 4 mu, I = H^3/12,
shear coefficient 5/6). The uniform end displacement stiffens the tip slightly compared
with a shear-traction load, so agreement is expected within ~2 %.

Observed convergence order of the compliance of Q2/Q1: its error is governed by the stress
singularity r^(lambda-1) at the clamped corners (clamped-free right angle, incompressible:
Williams' equation sin^2(lambda pi/2) = 1 - lambda^2, lambda = 0.594), so asymptotically the
energy-type error decays as h^(2 lambda) = h^1.19; on coarse meshes the smooth bending error
(h^4 for a quadratic-element energy functional) still contributes, so the observed order lies
between the two and decreases towards 2 lambda under refinement.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from skvalve.fem import Solid
from skvalve.fem.meshes import rectangle
from skvalve.materials import NeoHookean

L, H, D = 10.0, 1.0, 0.01
MATERIAL = NeoHookean.from_shear_poisson(1.0, 0.4999)
TIMOSHENKO = L**3 / (MATERIAL.mu * H**3) + 1.2 * L / (MATERIAL.mu * H)


def _compliance(n: int, formulation: str, order: int) -> float:
    solid = Solid(rectangle((10 * n, n), (L, H)), MATERIAL, formulation=formulation, order=order)
    solid.add_dirichlet("left", 0.0).add_dirichlet("right", -D, components=[1])
    result = solid.solve(steps=1, progress=False)
    return -D / result.reaction("right")[1]


@pytest.fixture(scope="module")
def studies():
    sizes = [1, 2, 4, 8]
    return {
        "Q2/Q1": np.array([_compliance(n, "up", 2) for n in sizes]),
        "Q1": np.array([_compliance(n, "u", 1) for n in sizes]),
    }


def test_williams_exponent():
    lam = brentq(lambda x: np.sin(x * np.pi / 2) ** 2 + x**2 - 1.0, 0.3, 0.9)
    assert lam == pytest.approx(0.594, abs=2e-3)


def test_mixed_element_does_not_lock(studies):
    mixed = studies["Q2/Q1"]
    # already on one element through the thickness within 5 %, converged within 2 % of beam theory
    assert mixed[0] == pytest.approx(TIMOSHENKO, rel=0.05)
    assert mixed[-1] == pytest.approx(TIMOSHENKO, rel=0.02)


def test_q1_displacement_element_locks(studies):
    q1 = studies["Q1"]
    # volumetric locking: even with 8 x 80 elements the tip is ~20x too stiff
    assert np.all(q1 < 0.1 * TIMOSHENKO)
    assert np.all(q1 < 0.1 * studies["Q2/Q1"])


def test_observed_convergence_order_of_mixed_element(studies):
    mixed = studies["Q2/Q1"]
    differences = np.abs(np.diff(mixed))
    orders = np.log2(differences[:-1] / differences[1:])
    two_lambda = 2 * brentq(lambda x: np.sin(x * np.pi / 2) ** 2 + x**2 - 1.0, 0.3, 0.9)
    # between the singular-corner rate 2 lambda = 1.19 and the smooth rate 4, decreasing towards 2 lambda
    assert np.all(orders > two_lambda - 0.1)
    assert np.all(orders < 2.5)
    assert orders[-1] <= orders[0] + 0.05
    # monotone convergence from the stiff side
    assert np.all(np.diff(mixed) > 0)
