"""Size of the Chandran–Barocas term of Eq. 11 (skvalve.multiscale.correction)."""

import math

import numpy as np

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.materials.neo_hookean import NeoHookean
from skvalve.multiscale.correction import chandran_barocas_size
from skvalve.multiscale.material import RVEMaterial
from skvalve.networks.generate import generate
from skvalve.networks.network import Network

FIBER = ExponentialFiber.from_diameter(10.5e3, 450e-9, 50.5, 1.12)
MATRIX = NeoHookean.from_shear_poisson(2.1e3, 0.49)


def committed(material, F):
    Fq = np.broadcast_to(F[:, :, None, None], (3, 3, material.n_points, material.n_elements)).copy()
    material.cauchy(Fq)
    material.commit()
    return material


def test_vanishes_under_dilatation_by_network_equilibrium():
    material = committed(RVEMaterial([generate(35.0, 0.0, n_fibers=80, seed=3)], MATRIX, FIBER, n_points=1),
                         1.08 * np.eye(3))
    size = chandran_barocas_size(material, element_size=2.5e-4)
    reference = chandran_barocas_size(committed(material, np.diag([1.08, 1.0, 1.0])), 2.5e-4)
    assert reference.ratio[0] > 1e-3  # uniaxial: a non-zero term
    assert size.ratio[0] <= 1e-6 * reference.ratio[0]


def test_single_fiber_by_hand():
    """One fiber from the -x face to the +y face, F = diag(λ, 1, 1): only the -x end contributes, f e (1 - 1/λ)."""
    start, end = np.array([-0.5, -0.2, 0.0]), np.array([0.1, 0.5, 0.0])
    net = Network([start, end], [[0, 1]], [True, True], [0, 3])
    lam = 1.1
    F = np.diag([lam, 1.0, 1.0])
    material = committed(RVEMaterial([net], MATRIX, FIBER, n_points=1), F)
    size = chandran_barocas_size(material, element_size=1.0)
    d = F @ (end - start)
    e = -d / np.linalg.norm(d)  # from the +y end towards the -x boundary cross-link
    force = FIBER.force(np.linalg.norm(d) / np.linalg.norm(end - start))
    length = np.linalg.norm(end - start)
    area = math.pi * (450e-9) ** 2 / 4
    gamma = math.sqrt(length * area / 0.43)
    expected = 0.43 / (length * area * gamma * lam) * force * e * (1 - 1 / lam)
    np.testing.assert_allclose(size.body_force[0], expected, rtol=1e-12)
