"""FE² coupling in the solver (thomas2019 §2.4, issue 9 tests a–e): the RVE material inside a Solid.

(a) homogeneous patch against NeoHookean.cauchy + solve_rve at every Gauss point; (b) assembled tangent
against central differences of the assembled residual with the RVEs re-solved; (c) Newton's observed
rate; (d) a failed step's rewind restores the state bit for bit; (e) networks without interior
cross-links reproduce the independent affine fiber model.
"""

import numpy as np
import pytest
from _fe2_networks import affine_network

from skvalve.fem import ConvergenceError, Solid, solve
from skvalve.fem.meshes import box
from skvalve.multiscale.affine import AffineFiberModel
from skvalve.multiscale.material import RVEMaterial
from skvalve.networks.generate import generate
from skvalve.networks.rve import solve_rve

G, NU, E_F, BETA, LAMBDA_C, DIAMETER = 2.1e3, 0.49, 10.5e3, 50.5, 1.12, 450e-9
TIGHT = 1e-13  # RVE tolerance for checks at the 1e-10 / finite-difference level


@pytest.fixture(scope="module")
def nets():
    return [generate(a, m, n_fibers=60, seed=s) for s, (a, m) in enumerate([(30.0, 0.0), (45.0, 60.0), (20.0, -30.0),
                                                                              (40.0, 90.0)])]


def affine_displacement(F0):
    return lambda X, t: t * ((F0 - np.eye(3)) @ X)


F0 = np.array([[1.08, 0.02, 0.0], [0.01, 1.05, 0.0], [0.0, 0.0, 0.88]])


def test_homogeneous_patch_matches_matrix_plus_solve_rve(fiber, matrix, nets):
    """2x2x2 block, one network everywhere, affine boundary motion: the free centre node stays affine."""
    mesh = box(2)
    material = RVEMaterial([nets[0]] * mesh.nelements, matrix, fiber, tol=TIGHT)
    solid = Solid(mesh, material)
    boundary = np.unique(mesh.boundary_facets())
    solid.add_dirichlet(boundary, affine_displacement(F0))
    result = solve(solid, steps=2, progress=False, rtol=1e-12)
    u = result.u()
    centre = np.flatnonzero(np.all(np.isclose(solid.space.dof_coordinates, 0.5), axis=0))
    np.testing.assert_allclose(result.displacement()[:, centre].ravel(), (F0 - np.eye(3)) @ [0.5, 0.5, 0.5],
                               atol=1e-10)
    F = solid.deformation_gradient(u)
    sigma = material.cauchy(F)
    rve = solve_rve(nets[0], F0, fiber, material.psi, material.fiber_diameter, tol=TIGHT)
    expected = matrix.cauchy(F0) + rve.cauchy
    scale = np.abs(expected).max()
    assert np.abs(sigma - expected[:, :, None, None]).max() <= 1e-10 * scale


def test_prescribed_block_stress_per_element_network(fiber, matrix, nets):
    """Every node prescribed: F = F0 at all 32 Gauss points, each with its element's own network."""
    mesh = box((4, 1, 1), lengths=(4.0, 1.0, 1.0))
    material = RVEMaterial(nets, matrix, fiber, tol=TIGHT)
    solid = Solid(mesh, material)
    u = affine_displacement(F0)(solid.space.dof_coordinates, 1.0).T.ravel()
    assert np.abs(solid.assemble(u, 1.0, tangent=False)[0]).max() > 0  # not in equilibrium: only F matters here
    sigma = material.cauchy(solid.deformation_gradient(u))
    for e, net in enumerate(nets):
        rve = solve_rve(net, F0, fiber, material.psi, material.fiber_diameter, tol=TIGHT)
        expected = matrix.cauchy(F0) + rve.cauchy
        assert np.abs(sigma[:, :, :, e] - expected[:, :, None]).max() <= 1e-10 * np.abs(expected).max()


def stretched_bar(material, mesh, stretch=1.12):
    solid = Solid(mesh, material)
    for axis in range(3):
        solid.add_dirichlet(lambda X, a=axis: np.isclose(X[a], 0.0), 0.0, components=[axis])
    solid.add_dirichlet(lambda X: np.isclose(X[0], mesh.p[0].max()), stretch - 1.0, components=[0])
    return solid


def test_assembled_tangent_matches_central_differences(fiber, matrix, nets):
    mesh = box((2, 1, 1), lengths=(2.0, 1.0, 1.0))
    material = RVEMaterial(nets[:2], matrix, fiber, tol=TIGHT)
    solid = stretched_bar(material, mesh)
    pattern = solid.pattern
    free = pattern.free
    rng = np.random.default_rng(0)
    X = solid.space.dof_coordinates
    u = np.zeros(solid.space.n_dofs)
    u[0::3] = 0.1 * X[0] / 2.0
    u[free] += 0.02 * rng.uniform(-1, 1, free.size)
    _, tangent = solid.assemble(u, 1.0, tangent=True)
    K = solid.tangent_matrix(tangent).toarray()
    h = 1e-6
    numeric = np.zeros_like(K)
    for j, dof in enumerate(free):
        du = np.zeros_like(u)
        du[dof] = h
        plus = solid.assemble(u + du, 1.0, tangent=False)[0][free]
        minus = solid.assemble(u - du, 1.0, tangent=False)[0][free]
        numeric[:, j] = (plus - minus) / (2 * h)
    assert np.abs(K - numeric).max() <= 1e-6 * np.abs(K).max()


def test_newton_converges_quadratically(fiber, matrix, nets):
    mesh = box((2, 2, 1), lengths=(2.0, 2.0, 1.0))
    material = RVEMaterial(nets, matrix, fiber, tol=TIGHT)
    solid = stretched_bar(material, mesh, stretch=1.3)
    result = solve(solid, steps=1, progress=False, rtol=1e-13, line_search=False)
    residuals = np.array([record["relative_residual"] for record in result.log])
    usable = residuals[(residuals < 1e-1) & (residuals > 1e-12)]
    assert usable.size >= 3, residuals
    rates = np.log(usable[2:] / usable[1:-1]) / np.log(usable[1:-1] / usable[:-2])
    assert rates.max() >= 1.8, (residuals, rates)


def test_failed_step_rewinds_bit_for_bit(fiber, matrix, nets):
    mesh = box((2, 2, 1), lengths=(2.0, 2.0, 1.0))

    def fresh():
        material = RVEMaterial(nets, matrix, fiber)
        return material, stretched_bar(material, mesh, stretch=1.2)

    material, solid = fresh()
    first = solve(solid, steps=[0.5], progress=False)
    committed = material.state()
    with pytest.raises(ConvergenceError):
        solve(solid, steps=[1.0], u0=first.u(), t0=0.5, max_iter=1, max_cutbacks=0, progress=False)
    after = material.state()
    for name in ("positions", "F", "sensitivity", "fiber_stretch"):
        assert np.array_equal(getattr(after, name), getattr(committed, name)), name
    retried = solve(solid, steps=[1.0], u0=first.u(), t0=0.5, progress=False).u()
    material2, solid2 = fresh()  # the same path without the failed attempt
    first2 = solve(solid2, steps=[0.5], progress=False)
    straight = solve(solid2, steps=[1.0], u0=first2.u(), t0=0.5, progress=False).u()
    assert np.array_equal(retried, straight)
    assert np.array_equal(material.state().positions, material2.state().positions)


class MatrixPlusAffine:
    """Reference quadrature-point material: neo-Hookean matrix plus the affine fiber model."""

    incompressible = False

    def __init__(self, matrix, affine):
        self.matrix, self.affine = matrix, affine

    def pk1_and_tangent(self, F):
        P, A = self.matrix.pk1_and_tangent(F)
        Pf, Af = self.affine.pk1_and_tangent(F)
        return P + Pf, A + Af

    def pk1(self, F):
        return self.pk1_and_tangent(F)[0]

    def cauchy(self, F):
        return self.matrix.cauchy(F) + self.affine.cauchy(F)


def test_affine_networks_reproduce_the_affine_fiber_model(fiber, matrix):
    mesh = box((2, 2, 1), lengths=(2.0, 2.0, 1.0))
    networks = [affine_network(seed) for seed in range(mesh.nelements)]
    rve_solid = stretched_bar(RVEMaterial(networks, matrix, fiber), mesh)
    reference = stretched_bar(MatrixPlusAffine(matrix, AffineFiberModel(networks, fiber)), mesh)
    u_rve = solve(rve_solid, steps=2, progress=False, rtol=1e-12).u()
    u_ref = solve(reference, steps=2, progress=False, rtol=1e-12).u()
    assert np.abs(u_rve - u_ref).max() <= 1e-10 * np.abs(u_ref).max()
    assert np.abs(u_ref).max() > 0.1  # the bar did stretch
