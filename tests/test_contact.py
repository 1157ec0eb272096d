"""Penalty self-contact (skvalve.fem.contact): gap derivatives and tangent against finite differences, two
blocks pressed together against the homogeneous closed form, no pass-through, contact pressure and area."""

import numpy as np
import pytest
import skfem
from scipy.optimize import brentq

from skvalve.analytic.homogeneous import uniaxial
from skvalve.fem import Problem, Space, solve
from skvalve.fem.contact import ContactSurface, SurfaceContact, gap_derivatives, oriented_quads
from skvalve.fem.elements.constitutive import MaterialRegions
from skvalve.fem.elements.hyperelastic import HyperelasticTerm
from skvalve.materials import NeoHookean

LAW = NeoHookean(1.0, 2.0)


def _random_state(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def pair_central_differences(derivatives, x: np.ndarray, h: float = 1e-6):
    """For each of the 12 coordinates k of ``x`` (n, 12) = [xs, x1, x2, x3]: k and the central differences of the
    value and of the gradient returned by ``derivatives(xs, x1, x2, x3)``."""
    for k in range(12):
        step = np.zeros(12)
        step[k] = h
        plus = derivatives(*np.split(x + step, 4, axis=1))
        minus = derivatives(*np.split(x - step, 4, axis=1))
        yield k, (plus[0] - minus[0]) / (2 * h), (plus[1] - minus[1]) / (2 * h)


def test_gap_gradient_and_hessian_match_central_differences():
    x = _random_state().normal(size=(6, 12))
    g, grad, hess = gap_derivatives(x[:, :3], x[:, 3:6], x[:, 6:9], x[:, 9:])
    for k, value_slope, gradient_slope in pair_central_differences(gap_derivatives, x):
        np.testing.assert_allclose(value_slope, grad[:, k], atol=1e-8)
        np.testing.assert_allclose(gradient_slope, hess[:, :, k], atol=1e-7)
    # the gap is the signed distance to the plane: check against a direct construction
    normal = np.cross(x[:, 6:9] - x[:, 3:6], x[:, 9:] - x[:, 3:6])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    np.testing.assert_allclose(g, np.einsum("ij,ij->i", x[:, :3] - x[:, 6:9], normal))


def two_blocks(n_bottom: int, n_top: int, gap: float = 0.0) -> skfem.MeshHex:
    """Unit cubes [0,1]^3 and [0,1]^2 x [1+gap, 2+gap], meshed n x n x n each, as one mesh."""
    bottom = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, n_bottom + 1),) * 3)
    top = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, n_top + 1),) * 2, np.linspace(1 + gap, 2 + gap, n_top + 1))
    p = np.hstack([bottom.p, top.p])
    t = np.hstack([bottom.t, top.t + bottom.p.shape[1]])
    return skfem.MeshHex(p, t)


SMOOTHING = 0.01


def block_contact_problem(n_bottom: int, n_top: int, penalty: float, gap: float = 0.0, blend: float = 0.0,
                          barrier: float | None = None):
    mesh = two_blocks(n_bottom, n_top, gap)
    space = Space(mesh)
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, LAW))])
    facets = mesh.facets_satisfying(lambda X: np.abs(X[2] - 1.0) < 1e-9, boundaries_only=True)
    facets = np.concatenate([facets, mesh.facets_satisfying(lambda X: np.abs(X[2] - 1.0 - gap) < 1e-9,
                                                            boundaries_only=True)]) if gap else facets
    surface = ContactSurface.from_facets(mesh, facets)
    contact = problem.add_term(SurfaceContact(space, surface, penalty, smoothing=SMOOTHING, blend=blend,
                                              barrier=barrier))
    problem.add_dirichlet(lambda X: X[0] == 0.0, 0.0, components=[0])
    problem.add_dirichlet(lambda X: X[1] == 0.0, 0.0, components=[1])
    problem.add_dirichlet(lambda X: X[2] == 0.0, 0.0, components=[2])
    return problem, contact


def closed_form_force(shortening: float, penalty: float) -> tuple[float, float]:
    """Nominal pressure and stretch of two unit blocks in series with a two-pass penalty: d = 2(1 - lam) + h(|P|)."""
    def mismatch(lam):
        return 2.0 * (1.0 - lam) + overlap(abs(uniaxial(LAW, lam, incompressible=False).nominal[0]), penalty) \
            - shortening
    lam = brentq(mismatch, 1.0 - shortening / 2.0, 1.0)
    return abs(float(uniaxial(LAW, lam, incompressible=False).nominal[0])), lam


def overlap(pressure: float, penalty: float) -> float:
    """Inverse of the two-pass pressure 2 p(h): p = eps h^2 / (2 h0) below h0, eps (h - h0/2) above."""
    if pressure / 2 < penalty * SMOOTHING / 2:
        return float(np.sqrt(pressure * SMOOTHING / penalty))
    return pressure / (2 * penalty) + SMOOTHING / 2


def test_two_blocks_pressed_together_match_the_closed_form():
    n_bottom = n_top = 2
    penalty, shortening = 50.0, 0.2
    problem, contact = block_contact_problem(n_bottom, n_top, penalty)
    top = 2.0
    problem.add_dirichlet(lambda X: X[2] == top, -shortening, components=[2])
    # start the top block slightly pressed so that contact supports it from the first iteration
    result = solve(problem, steps=4, progress=False, rtol=1e-10, solver="scipy")
    u = result.u()
    pressure, lam = closed_form_force(shortening, penalty)
    reaction = -result.reaction(lambda X: X[2] == top)[2]
    assert reaction == pytest.approx(pressure, rel=1e-6)
    # the contact faces of both blocks carry the closed-form pressure (nominal, per reference area)
    faces = contact.face_pressure(u)
    np.testing.assert_allclose(faces, pressure, rtol=1e-6)
    # penetration |P| / (2 eps) between the faces, and the contact area is both faces' current area
    z = problem.space.dof_coordinates[2] + u[2::3]
    lateral = uniaxial(LAW, lam, incompressible=False).stretches[1]
    assert contact.contact_area(u) == pytest.approx(2.0 * lateral**2, rel=1e-9)
    on_bottom = np.isclose(problem.space.dof_coordinates[2], 1.0) & (np.arange(z.size) < (n_bottom + 1) ** 3)
    on_top = np.isclose(problem.space.dof_coordinates[2], 1.0) & (np.arange(z.size) >= (n_bottom + 1) ** 3)
    penetration = z[on_bottom].max() - z[on_top].min()
    assert penetration == pytest.approx(overlap(pressure, penalty), rel=1e-6)


def test_no_pass_through_and_penetration_falls_with_the_penalty():
    """Without contact the top block would be pushed 0.5 through the bottom one; with it the overlap is
    the penalty's closed-form overlap, which falls with eps."""
    shortening = 0.5
    overlaps = []
    for penalty in (20.0, 200.0):
        problem, contact = block_contact_problem(2, 2, penalty)
        problem.add_dirichlet(lambda X: X[2] == 2.0, -shortening, components=[2])
        u = solve(problem, steps=5, progress=False, solver="scipy").u()
        x = problem.space.dof_coordinates + u.reshape(-1, 3).T
        n_bottom = 27
        depth = x[2, :n_bottom].max() - x[2, n_bottom:].min()
        pressure, _ = closed_form_force(shortening, penalty)
        assert depth == pytest.approx(overlap(pressure, penalty), rel=1e-6)
        overlaps.append(depth)
    assert overlaps[1] < 0.5 * overlaps[0]


def test_contact_tangent_matches_central_differences_with_fixed_active_set():
    problem, contact = block_contact_problem(2, 3, 30.0)
    rng = _random_state(1)
    u = np.zeros(problem.space.n_dofs)
    X = problem.space.dof_coordinates
    top = X[2] > 1.0 - 1e-9
    top[: 27] = False
    u[2::3][top] = -0.05  # the top block overlaps by 0.05
    u += 0.01 * rng.normal(size=u.size)
    pairs = contact.active_pairs(u)
    assert pairs.size > 10
    K = contact.assemble_pairs(u, 1.0, pairs, True).matrix.toarray()
    h = 1e-6
    dofs = np.unique(3 * np.concatenate([pairs.node, contact.surface.triangles[pairs.triangle].ravel()])[:, None]
                     + np.arange(3))
    for dof in dofs[:: max(1, dofs.size // 25)]:
        step = np.zeros_like(u)
        step[dof] = h
        fp = contact.assemble_pairs(u + step, 1.0, pairs, False).internal
        fm = contact.assemble_pairs(u - step, 1.0, pairs, False).internal
        np.testing.assert_allclose((fp - fm) / (2 * h), K[:, dof], atol=1e-6 * np.abs(K).max())
    assert np.allclose(K, K.T)


def _upper_block_pressed(problem) -> np.ndarray:
    """A displacement that presses the upper block's bottom face 0.05 into the lower block (non-matching faces)."""
    u = np.zeros(problem.space.n_dofs)
    top = problem.space.dof_coordinates[2] > 1.0 - 1e-9
    top[: 27] = False
    u[2::3][top] = -0.05
    return u


def test_the_search_memory_saved_with_a_state_gives_back_its_active_set():
    """Non-matching faces (2 on 3 cells): nodes of one face sit on edges of the other's triangles, where the search
    keeps the triangle of its last search. The memory taken by ``state`` and given back by ``restore`` after other
    searches (here one at the open state, which forgets every pair) reproduces the active set at the same ``u``."""
    problem, contact = block_contact_problem(2, 3, 30.0)
    u = _upper_block_pressed(problem)
    u += 0.01 * _random_state(2).normal(size=u.size)
    before = contact.active_pairs(u)
    memory = contact.state()
    assert contact.active_pairs(np.zeros_like(u)).size == 0
    assert np.all(contact.state()["previous_triangle"] == -1)
    problem.restore({f"{problem.terms.index(contact)}/{key}": value for key, value in memory.items()})
    after = contact.active_pairs(u)
    assert before.size > 10
    assert np.array_equal(before.node, after.node) and np.array_equal(before.triangle, after.triangle)
    with pytest.raises(ValueError, match="previous_triangle"):
        contact.restore({"previous_triangle": np.zeros(3, dtype=int)})


def test_problem_state_is_keyed_by_term_name():
    """``Problem.state`` keys a term's arrays by its name, so a term added before it does not move its keys; a second
    term of the same name is ``name#2``; positional keys (kept states of format 3) still restore; a key that names no
    term is refused, naming it."""
    problem, contact = block_contact_problem(2, 3, 30.0)
    u = _upper_block_pressed(problem)
    contact.active_pairs(u)
    saved = problem.state()
    assert saved and all(key.startswith(f"{contact.name}/") for key in saved)
    problem.terms.insert(0, HyperelasticTerm(problem.space, MaterialRegions(problem.space.mesh, LAW)))
    assert problem.term_labels()[:2] == ["solid", "solid#2"]
    assert set(problem.state()) == set(saved)  # the contact's keys did not move
    before = contact.active_pairs(u)
    contact.active_pairs(np.zeros_like(u))  # forget
    problem.restore(saved)
    after = contact.active_pairs(u)
    assert before.size and np.array_equal(before.triangle, after.triangle)
    contact.active_pairs(np.zeros_like(u))
    index = problem.terms.index(contact)
    problem.restore({f"{index}/{key.split('/', 1)[1]}": value for key, value in saved.items()})  # format 3
    assert np.array_equal(contact.active_pairs(u).triangle, before.triangle)
    with pytest.raises(ValueError, match="no term 'ipc contact'.*solid, solid#2"):
        problem.restore({"ipc contact/kappa": np.array(1.0)})


def test_open_surfaces_have_no_pairs_and_own_neighbourhood_is_excluded():
    problem, contact = block_contact_problem(2, 2, 10.0, gap=0.1)
    assert contact.active_pairs(np.zeros(problem.space.n_dofs)).size == 0
    # a single bent sheet: its own faces never act on its nodes, however it is bent
    mesh = skfem.MeshHex.init_tensor(np.linspace(0, 4, 9), np.linspace(0, 1, 3), np.linspace(0, 0.2, 2))
    space = Space(mesh)
    facets = mesh.facets_satisfying(lambda X: np.abs(X[2] - 0.2) < 1e-9, boundaries_only=True)
    sheet = SurfaceContact(space, ContactSurface.from_facets(mesh, facets), 10.0)
    X = space.dof_coordinates
    u = np.zeros(space.n_dofs)
    u[2::3] = -0.3 * np.sin(np.pi * X[0] / 4.0) ** 2  # a fold downwards: the top surface becomes concave
    assert sheet.active_pairs(u).size == 0


def test_contact_pairs_closer_than_exclude_within_in_the_reference_are_never_active():
    """The two faces at z = 1 coincide in the reference: pressed 0.1 into each other, every node pairs (9 per face,
    two passes). A node over a triangle lies at most its circumradius (0.37 here) from the centroid in the
    reference: excluded within 0.4, none pairs (what keeps rim nodes off their own leaflet's inner face); within 0.1
    (below the smallest vertex-centroid distance, 0.24), all still do."""
    problem, contact = block_contact_problem(2, 2, 50.0)
    X = problem.space.dof_coordinates
    u = np.zeros(problem.space.n_dofs)
    u[2::3][X[2] > 1.0 + 1e-9] -= 0.1
    top_face = np.flatnonzero(np.isclose(X[2], 1.0))
    top_face = top_face[top_face >= 27]  # the top block's copy of the face
    u[3 * top_face + 2] -= 0.1
    assert contact.active_pairs(u).size == 18
    contact.exclude_within = 0.1
    assert contact.active_pairs(u).size == 18
    contact.exclude_within = 0.4
    assert contact.active_pairs(u).size == 0
    with pytest.raises(ValueError, match="exclude_within"):
        SurfaceContact(problem.space, contact.surface, 1.0, exclude_within=-1.0)


def test_search_depth_and_rounding_default_to_the_mean_face_edge():
    """Without ``max_penetration`` the search depth is the mean edge of the surface's faces, without ``smoothing`` the
    rounding 1 % of it (0.5 and 0.005 on the 2 x 2 faces of unit blocks); given, they are taken as they are."""
    problem, contact = block_contact_problem(2, 2, 10.0)
    default = SurfaceContact(problem.space, contact.surface, 10.0)
    assert default.max_penetration == pytest.approx(0.5, rel=1e-12)
    assert default.smoothing == pytest.approx(0.005, rel=1e-12)
    given = SurfaceContact(problem.space, contact.surface, 10.0, max_penetration=0.2, smoothing=0.05)
    assert (given.max_penetration, given.smoothing) == (0.2, 0.05)


def test_oriented_quads_point_away_from_inside():
    X = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    quads = oriented_quads(X, np.array([[0, 2, 1, 3]]), inside=np.array([[0.5, 0.5, -1.0]]))
    Q = X[quads[0]]
    normal = np.cross(Q[2] - Q[0], Q[3] - Q[1])
    assert normal[2] > 0 and sorted(quads[0].tolist()) == [0, 1, 2, 3]
    with pytest.raises(ValueError, match="shape"):
        ContactSurface.from_quads(X, np.array([[0, 1, 2]]))


def test_non_matching_faces_carry_the_closed_form_force_within_the_node_to_surface_patch_error():
    """3x3 faces on 2x2 faces: two-pass node-to-surface contact does not pass the contact patch test exactly
    (the nodal forces of one side do not map to a uniform traction on the other), so the total force is
    checked to 1 % (it is 0.3 % off here) and the solve must converge."""
    penalty, shortening = 50.0, 0.2
    problem, contact = block_contact_problem(2, 3, penalty)
    problem.add_dirichlet(lambda X: X[2] == 2.0, -shortening, components=[2])
    result = solve(problem, steps=4, progress=False, rtol=1e-8, solver="scipy")
    pressure, _ = closed_form_force(shortening, penalty)
    assert -result.reaction(lambda X: X[2] == 2.0)[2] == pytest.approx(pressure, rel=1e-2)
    assert contact.active_pairs(result.u()).size == 9 + 16
