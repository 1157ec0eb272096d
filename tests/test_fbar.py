"""F-bar hexahedra: tangent against central differences and against the energy, patch test, and locking at
nu = 0.495 (leaflet proportions) against a Q2/Q1 reference. The full locking study is benchmarks/locking.py."""

import numpy as np
import pytest
import skfem

from skvalve.fem import FollowerPressure, Problem, Solid, Space, solve
from skvalve.fem.elements.fbar import FBarTerm
from skvalve.fem.meshes import box, distort
from skvalve.materials import LeeSacks, NeoHookean, Ogden

# the shipped Texas TriValve anterior-leaflet law (C0, C1, C2, D): bulk/shear modulus ~ 100, nu ~ 0.495
LEAFLET = LeeSacks(1.0e-3, 1.188659e-4, 15.260081, 20.0669)


class _UncompiledNeoHookean(NeoHookean):
    """Overrides the stress without stating its invariant derivatives: no fused form, the generic path."""

    def response_C(self, C):
        return super().response_C(C)


@pytest.mark.parametrize("law", [NeoHookean(1.0, 20.0), LeeSacks(1.0, 2.0, 0.5, 0.02),
                                 Ogden(mu=(1.0, 0.2), alpha=(2.5, -2.0), D=(0.05,)), _UncompiledNeoHookean(1.0, 20.0)],
                         ids=["neo_hookean", "lee_sacks", "ogden", "generic_path"])
def test_fbar_tangent_matches_central_differences_and_forces_match_the_energy(law):
    space = Space(distort(box(2)))
    term = FBarTerm(space, law)
    rng = np.random.default_rng(0)
    u = 0.05 * rng.standard_normal(space.n_dofs)
    v = rng.standard_normal(space.n_dofs)
    contribution = term.assemble(u, 0.0, True, 0)
    block = contribution.blocks[0]
    Kv = np.bincount(block.dofs.ravel(), np.einsum("emn,en->em", block.matrices, v[block.dofs]).ravel(),
                     minlength=space.n_dofs)
    h = 1e-6
    fd = (term.assemble(u + h * v, 0.0, False, 0).internal - term.assemble(u - h * v, 0.0, False, 0).internal) / (2 * h)
    assert np.abs(Kv - fd).max() < 1e-6 * np.abs(Kv).max()
    assert np.allclose(block.matrices, block.matrices.transpose(0, 2, 1), atol=1e-12 * np.abs(block.matrices).max())

    def energy(w):
        return float((law.psi(term.modified_deformation_gradient(w)) * space.dx.T).sum())

    assert (energy(u + h * v) - energy(u - h * v)) / (2 * h) == pytest.approx(contribution.internal @ v, rel=1e-7)


@pytest.mark.parametrize("amplitude", [0.01, 0.06])
def test_compiled_laws_give_the_generic_residual_and_tangent(amplitude):
    """Two laws on interleaved elements: P and dP/dF at F_bar by the fused kernel vs MaterialRegions.evaluate."""
    mesh = distort(box(3), amount=0.2, seed=2)
    space = Space(mesh)
    laws, regions = [LEAFLET, Ogden(mu=(1.0, 0.2), alpha=(2.5, -2.0), D=(0.05,))], np.arange(mesh.nelements) % 2
    fused, generic = FBarTerm(space, laws, regions), FBarTerm(space, laws, regions, fused=False)
    u = amplitude * np.random.default_rng(3).standard_normal(space.n_dofs)
    got, expected = fused.assemble(u, 0.0, True, 0), generic.assemble(u, 0.0, True, 0)
    assert np.abs(got.internal - expected.internal).max() <= 1e-12 * np.abs(expected.internal).max()
    K, K_generic = got.blocks[0].matrices, expected.blocks[0].matrices
    assert np.abs(K - K_generic).max() <= 1e-12 * np.abs(K_generic).max()
    assert np.array_equal(fused.assemble(u, 0.0, False, 0).internal, got.internal)


def test_fbar_patch_test_reproduces_a_homogeneous_deformation():
    """Affine boundary displacement on a distorted mesh: interior nodes follow the affine field, F_bar = F."""
    mesh = distort(box(3), amount=0.25, seed=4)
    space = Space(mesh)
    problem = Problem(space, [FBarTerm(space, LEAFLET)])
    H = np.array([[0.10, 0.03, -0.02], [0.01, -0.05, 0.04], [0.02, 0.00, 0.06]])
    boundary = np.unique(mesh.facets[:, mesh.boundary_facets()])
    problem.add_dirichlet(nodes=boundary, value=lambda X, t: t * (H @ X))
    result = solve(problem, steps=2, progress=False, rtol=1e-10)
    u = result.u().reshape(-1, 3)
    assert np.abs(u - (H @ mesh.p).T).max() < 1e-9
    Fbar = problem.terms[0].modified_deformation_gradient(result.u())
    assert np.allclose(Fbar, (np.eye(3) + H)[:, :, None, None], atol=1e-9)


def _strip(nx: int, nz: int, length: float = 4.0, thickness: float = 0.78, width: float = 0.2) -> skfem.MeshHex:
    return skfem.MeshHex.init_tensor(np.linspace(0, length, nx + 1), np.linspace(0, width, 2),
                                     np.linspace(0, thickness, nz + 1))


def _strip_problem(kind: str, nx: int, nz: int) -> Problem:
    """Plane-strain strip (u_y = 0) clamped at x = 0, of the leaflet's thickness, 4 mm long."""
    mesh = _strip(nx, nz)
    if kind == "fbar":
        space = Space(mesh)
        problem = Problem(space, [FBarTerm(space, LEAFLET)])
    else:
        problem = Solid(mesh, LEAFLET, formulation="up" if kind == "q2q1" else "u")
    problem.add_dirichlet(lambda X: np.isclose(X[0], 0.0), 0.0)
    problem.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), 0.0, components=[1])
    return problem


def _cantilever_force(kind: str, nx: int, nz: int, tip: float = 0.0078) -> float:
    """End face moved by ``tip`` (1 % of the thickness) across the strip: the force needed."""
    problem = _strip_problem(kind, nx, nz)
    problem.add_dirichlet(lambda X: np.isclose(X[0], 4.0), tip, components=[2])
    return float(solve(problem, steps=1, progress=False).reaction(lambda X: np.isclose(X[0], 4.0))[2])


def _plate_deflection(kind: str, nx: int, nz: int, pressure: float = 1e-7) -> float:
    """Strip clamped at both ends under a follower pressure on top: mid-span deflection of the mid-plane."""
    problem = _strip_problem(kind, nx, nz)
    problem.add_dirichlet(lambda X: np.isclose(X[0], 4.0), 0.0)
    mesh = problem.mesh
    problem.add_term(FollowerPressure(problem.space, mesh.facets_satisfying(lambda x: np.isclose(x[2], 0.78),
                                                                           boundaries_only=True), pressure))
    u = solve(problem, steps=1, progress=False).u()
    X = problem.space.dof_coordinates if kind == "q2q1" else mesh.p
    mid = np.flatnonzero(np.isclose(X[0], 2.0) & np.isclose(X[2], 0.39))
    return float(u[3 * mid + 2].mean())


def test_cantilever_of_leaflet_proportions_does_not_lock():
    reference = _cantilever_force("q2q1", 10, 2)  # within 0.3 % of 20 x 4 (benchmarks/locking.py)
    fbar = _cantilever_force("fbar", 20, 4)
    q1 = _cantilever_force("q1", 20, 4)
    assert fbar == pytest.approx(reference, rel=0.03)
    assert q1 > 2.0 * reference  # full-integration Q1 locks: more than twice as stiff


def test_pressurised_plate_strip_does_not_lock():
    reference = _plate_deflection("q2q1", 20, 4)  # within 0.2 % of 40 x 8 (benchmarks/locking.py)
    fbar = _plate_deflection("fbar", 40, 4)
    q1 = _plate_deflection("q1", 40, 4)
    assert fbar == pytest.approx(reference, rel=0.03)
    assert abs(q1) < 0.7 * abs(reference)  # Q1 deflects 40 % too little


def test_fbar_term_energy_is_the_potential_of_its_forces():
    """FBarTerm.energy (used by the incremental solver's line search) against the internal force by central
    differences, on two laws in two regions; an inverted element makes it +inf."""
    space = Space(distort(box(2)))
    regions = np.arange(space.mesh.t.shape[1]) % 2
    term = FBarTerm(space, [LEAFLET, NeoHookean(1.0, 20.0)], regions=regions)
    rng = np.random.default_rng(4)
    u = 0.03 * rng.standard_normal(space.n_dofs)
    v = rng.standard_normal(space.n_dofs)
    h = 1e-6
    fd = (term.energy(u + h * v, 0.0) - term.energy(u - h * v, 0.0)) / (2 * h)
    assert fd == pytest.approx(term.assemble(u, 0.0, False, 0).internal @ v, rel=1e-6)
    assert term.energy(np.zeros(space.n_dofs), 0.0) == pytest.approx(0.0, abs=1e-14)
    folded = -2.5 * space.mesh.p.T.ravel()  # x = -1.5 X: every Jacobian negative
    assert term.energy(folded, 0.0) == np.inf
