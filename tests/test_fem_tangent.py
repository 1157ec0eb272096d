"""Finite-difference checks of the assembled tangents (domain, mixed u/p, follower pressure),
of the compiled neo-Hookean fast path against the generic law, and of the sparse solvers."""

import numpy as np
import pytest
import scipy.sparse as sp

from skvalve.fem import Solid
from skvalve.fem.elements.constitutive import neo_hookean_response
from skvalve.fem.meshes import annulus_sector, box, distort, rectangle
from skvalve.fem.solvers import linsolve
from skvalve.materials import IncompressibleNeoHookean, NeoHookean, Ogden


def _random_state_and_direction(solid: Solid, scale: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A random displacement u (size ``scale``) and direction v, both zero on constrained dofs."""
    rng = np.random.default_rng(seed)
    free = solid.pattern.free
    u = np.zeros(solid.space.n_dofs)
    u[free] = scale * rng.standard_normal(free.size)
    v = np.zeros_like(u)
    v[free] = rng.standard_normal(free.size)
    return u, v


def _full_tangent_check(solid: Solid, scale: float = 0.05, seed: int = 1) -> float:
    """max |K v - (R(u+hv) - R(u-hv)) / 2h| / max |K v| on the free dofs at a random state."""
    pat = solid.pattern
    u, v = _random_state_and_direction(solid, scale, seed)
    residual, tangent = solid.assemble(u, 0.7)
    K = solid.tangent_matrix(tangent)
    h = 1e-6
    plus, _ = solid.assemble(u + h * v, 0.7, tangent=False)
    minus, _ = solid.assemble(u - h * v, 0.7, tangent=False)
    fd = (plus - minus)[pat.free] / (2 * h)
    Kv = K @ v[pat.free]
    # the full-matrix product used by the predictor must agree too
    assert np.allclose(solid.apply(tangent, v)[pat.free], Kv, rtol=1e-12, atol=1e-12 * abs(Kv).max())
    return float(np.abs(Kv - fd).max() / np.abs(Kv).max())


CASES = {
    "hex Q1 u": lambda: Solid(distort(box(2)), NeoHookean(1.0, 2.0)),
    "tet P2 u": lambda: Solid(box(1, kind="tet"), Ogden(mu=(0.6, 0.4), alpha=(3.0, -2.0), D=(0.5,)), order=2),
    "hex Q2/Q1 split": lambda: Solid(distort(box(1)), NeoHookean(1.0, 50.0), formulation="up"),
    "hex Q2/Q1 incompressible": lambda: Solid(box(1), IncompressibleNeoHookean(1.0), formulation="up"),
    "quad Q2/Q1 plane strain": lambda: Solid(distort(rectangle(2)), IncompressibleNeoHookean(2.0), formulation="up"),
    "tri P2/P1 plane strain": lambda: Solid(rectangle(2, kind="tri"), NeoHookean(1.0, 20.0), formulation="up"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_domain_tangent_matches_finite_differences(name):
    solid = CASES[name]()
    solid.add_dirichlet("left", 0.0)
    # central differences with h = 1e-6: truncation ~h^2, round-off ~1e-16/h -> ~1e-9 relative
    assert _full_tangent_check(solid) < 1e-6


def _pressure_part_check(solid: Solid, scale: float, seed: int = 2) -> float:
    """Same check restricted to the follower-pressure terms: (K_p v - FD of R_p) / |K_p v|."""
    u, v = _random_state_and_direction(solid, scale, seed)

    def pressure_residual(state):
        return sum(np.bincount(load.element_dofs.ravel(), load.element_terms(state, 0.7, False)[0].ravel(),
                               minlength=state.size) for load in solid.pressures)

    h = 1e-6
    fd = (pressure_residual(u + h * v) - pressure_residual(u - h * v)) / (2 * h)
    Kv = np.zeros_like(u)
    for load in solid.pressures:
        kp = load.element_terms(u, 0.7, True)[1]
        Kv += np.bincount(load.element_dofs.ravel(), np.einsum("emn,en->em", kp, v[load.element_dofs]).ravel(),
                          minlength=u.size)
    assert np.abs(Kv).max() > 0.1
    return float(np.abs(Kv - fd).max() / np.abs(Kv).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_follower_pressure_load_stiffness_matches_finite_differences(dim):
    if dim == 3:
        solid = Solid(distort(box(2)), NeoHookean(1.0, 3.0))
        solid.add_dirichlet("left", 0.0).add_pressure("right", 0.8).add_pressure("top", lambda t: -0.3 * t)
    else:
        solid = Solid(annulus_sector(1.0, 1.5, 2, 3), IncompressibleNeoHookean(1.0), formulation="up")
        solid.add_dirichlet("theta0", 0.0, components=[1]).add_dirichlet("theta1", 0.0, components=[0])
        solid.add_pressure("inner", 0.8)
    # pressure terms alone at a large deformation (scale 0.2), then the whole tangent
    assert _pressure_part_check(solid, scale=0.2) < 1e-7
    assert _full_tangent_check(solid, scale=0.01) < 1e-6
    # and the load stiffness is genuinely non-symmetric (so the check above is not trivial)
    _, tangent = solid.assemble(np.zeros(solid.space.n_dofs) + 0.01, 1.0)
    kp = tangent.contributions[solid.terms.index(solid.pressures[0])].blocks[0].matrices
    assert np.abs(kp - kp.transpose(0, 2, 1)).max() > 1e-3 * np.abs(kp).max()


def test_neo_hookean_fast_path_equals_generic_law():
    rng = np.random.default_rng(0)
    F = np.eye(3)[:, :, None, None] + 0.2 * rng.standard_normal((3, 3, 4, 5))
    law = NeoHookean(1.3, 4.0)
    P, A = neo_hookean_response(F, law.mu, law.lmbda, True)
    P_ref, A_ref = law.pk1_and_tangent(F)
    assert np.allclose(P, P_ref, rtol=1e-12, atol=1e-12)
    assert np.allclose(A, A_ref.transpose(5, 4, 0, 1, 2, 3), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", linsolve.available_solvers())
def test_sparse_solvers_handle_nonsymmetric_systems(name):
    rng = np.random.default_rng(3)
    n = 40
    A = sp.random(n, n, density=0.1, random_state=4) + sp.eye(n) * 5.0
    assert abs(A - A.T).max() > 0
    b = rng.standard_normal(n)
    x = linsolve.solve(A.tocsr(), b, name)
    assert np.allclose(A @ x, b, rtol=1e-10, atol=1e-10)
    assert linsolve.solver_name(name) == name


def test_singular_system_raises():
    A = sp.csr_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    with pytest.raises(np.linalg.LinAlgError):
        linsolve.solve(A, np.array([1.0, 0.0]), "scipy")


def test_unknown_solver_name_raises():
    with pytest.raises(ValueError, match="unknown sparse solver"):
        linsolve.solver_name("mumps")
