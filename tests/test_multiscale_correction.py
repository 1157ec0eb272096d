"""Size of the Chandran–Barocas term of Eq. 11 (skvalve.multiscale.correction), on cases with known answers.

Zero: dilatation (network equilibrium), a network symmetric about the RVE centre under any F (pairwise
cancellation); zero mean over realisations; a single fiber by hand; the first-order effect of a body force on a
bar against its closed form (sign and units of the assembly).
"""

import math

import numpy as np
import pytest

from skvalve.fem import Solid
from skvalve.fem.meshes import box
from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.materials.neo_hookean import NeoHookean
from skvalve.multiscale.correction import body_force_effect, chandran_barocas_size, point_symmetric
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


def test_vanishes_for_a_network_symmetric_about_the_centre_under_a_general_F():
    """Each crossing has an opposite one (e, n, m -> -e, -n, -m, same f): the terms cancel pair by pair, for any F."""
    net = generate(35.0, 20.0, n_fibers=80, seed=5)
    F = np.array([[1.10, 0.06, -0.02], [0.03, 0.97, 0.04], [0.01, -0.05, 0.92]])
    single = chandran_barocas_size(committed(RVEMaterial([net], MATRIX, FIBER, n_points=1), F), 1.0)
    both = chandran_barocas_size(committed(RVEMaterial([point_symmetric(net)], MATRIX, FIBER, n_points=1), F), 1.0)
    assert np.linalg.norm(single.body_force[0]) > 0.0
    # the doubled network has twice the fiber length L: the same crossings would give half the single one's b
    assert np.linalg.norm(both.body_force[0]) <= 1e-9 * np.linalg.norm(single.body_force[0])


def test_realisations_average_out_as_a_fluctuation():
    """Statistically homogeneous networks under one F: b has zero mean; the mean of 16 realisations is ~1/sqrt(16)
    of a single one's size (a fluctuation, not a systematic body force). Seeded, so deterministic."""
    F = np.diag([1.12, 1.06, 1.0 / (1.12 * 1.06)])
    networks = [generate(35.0, 0.0, n_fibers=80, seed=s) for s in range(16)]
    size = chandran_barocas_size(committed(RVEMaterial(networks, MATRIX, FIBER, n_points=1), F), 1.0)
    rms = np.sqrt(np.mean(np.sum(size.body_force**2, axis=1)))
    mean = np.linalg.norm(size.body_force.mean(axis=0))
    assert mean < 2.5 * rms / np.sqrt(len(networks))  # 1/sqrt(n) with a margin (a 2.5-sigma bound)


def test_grazing_crossings_are_what_min_cosine_leaves_out():
    material = committed(RVEMaterial([generate(35.0, 0.0, n_fibers=150, seed=7)], MATRIX, FIBER, n_points=1),
                         np.diag([1.1, 1.05, 0.87]))
    every = chandran_barocas_size(material, 1.0).body_force
    assert np.array_equal(chandran_barocas_size(material, 1.0, min_cosine=0.0).body_force, every)
    nothing = chandran_barocas_size(material, 1.0, min_cosine=1.1).body_force  # no crossing has |e.n| >= 1.1
    assert np.all(nothing == 0.0)


def test_body_force_effect_against_the_closed_form_bar():
    """div sigma = b along x on a bar (nu = 0, fixed at x = 0, free at x = L): E u'' = b, u(L) = -b L^2/(2E).

    With nu = 0 the 3-D problem is the 1-D one, whose trilinear FE nodal values are exact (consistent loads), and the
    nodal forces sum to b times the volume (units: N/m^3 times m^3)."""
    length, G, b = 2.0, 50.0, 3.0
    solid = Solid(box((6, 1, 1), lengths=(length, 0.5, 0.5)), NeoHookean.from_shear_poisson(G, 0.0))
    solid.add_dirichlet(lambda X: np.isclose(X[0], 0.0), 0.0, components=[0])
    solid.add_dirichlet(lambda X: np.isclose(X[1], 0.0), 0.0, components=[1])
    solid.add_dirichlet(lambda X: np.isclose(X[2], 0.0), 0.0, components=[2])
    solid.check_supports()
    nel, nqp = solid.space.dx.shape
    body = np.zeros((nel, nqp, 3))
    body[:, :, 0] = b
    effect = body_force_effect(solid, body, np.zeros(solid.space.n_dofs), 0.0)
    assert effect.nodal_force.reshape(-1, 3)[:, 0].sum() == pytest.approx(b * length * 0.25, rel=1e-12)
    X = solid.space.dof_coordinates
    ux = effect.displacement_change[solid.space.displacement_dofs(np.arange(X.shape[1]), [0])].ravel()
    exact = -b / (2 * G) * (length * X[0] - X[0] ** 2 / 2)  # E = 2G(1 + nu) = 2G
    np.testing.assert_allclose(ux, exact, rtol=0, atol=1e-10 * np.abs(exact).max())
