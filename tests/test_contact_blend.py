"""Blended contact (skvalve.fem.contact.blend): barycentric derivatives and the blended energy's force and tangent
against central differences, the closed-form block contact kept exactly, a force that stays continuous where a node
slides over a concave crease (where the closest-triangle rule jumps), and no search memory."""

import numpy as np
import pytest
import skfem
from test_contact import block_contact_problem, closed_form_force, pair_central_differences

from skvalve.fem import Space, solve
from skvalve.fem.contact import ContactSurface, SurfaceContact
from skvalve.fem.contact import blend as contact_blend
from skvalve.fem.contact.blend import free_edges, normalisation, sheets, weighted_mean_energy
from skvalve.fem.contact.geometry import barycentric_derivatives, near_pairs, smooth_step

BLEND = 0.1


def test_barycentric_coordinates_and_their_derivatives():
    x = np.random.default_rng(0).normal(size=(8, 12))
    lam, grad, hess = barycentric_derivatives(*np.split(x, 4, axis=1))
    # closed form: the projection residual d - xi a - eta b is normal to the triangle's plane
    d, a, b = x[:, :3] - x[:, 3:6], x[:, 6:9] - x[:, 3:6], x[:, 9:] - x[:, 3:6]
    normal_part = d - lam[:, 1:2] * a - lam[:, 2:3] * b
    np.testing.assert_allclose(np.einsum("ij,ij->i", normal_part, a), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", normal_part, b), 0.0, atol=1e-12)
    np.testing.assert_allclose(lam.sum(axis=1), 1.0)
    for k, value_slope, gradient_slope in pair_central_differences(barycentric_derivatives, x):
        np.testing.assert_allclose(value_slope, grad[:, :, k], atol=1e-7)
        np.testing.assert_allclose(gradient_slope, hess[:, :, :, k], atol=1e-6)


def test_smooth_step_and_normalisation_are_continuous_with_their_derivatives():
    t = np.linspace(-0.5, 1.5, 2001)
    value, first, second = smooth_step(t)
    np.testing.assert_allclose(value + smooth_step(1.0 - t)[0], 1.0, atol=1e-14)
    h = t[1] - t[0]
    np.testing.assert_allclose(np.gradient(value, h)[1:-1], first[1:-1], atol=1e-5)
    np.testing.assert_allclose(np.gradient(first, h)[1:-1], second[1:-1], atol=20 * h)  # S''' jumps at 0, 1
    total = np.linspace(0.0, 2.0, 2001)
    M, M1, _ = normalisation(total)
    assert np.all(M >= 0.9 - 1e-12) and np.all(np.diff(M) >= 0.0)
    np.testing.assert_allclose(M[total >= 1.0], total[total >= 1.0])  # a full share is an exact mean
    np.testing.assert_allclose(np.gradient(M, total[1] - total[0])[1:-1], M1[1:-1], atol=2e-3)


def _rough_state(problem, seed: int) -> np.ndarray:
    """The 3x3 top face pushed into the 2x2 bottom face, some nodes just above it, slid sideways at random."""
    X = problem.space.dof_coordinates
    top = X[2] > 1.0 - 1e-9
    top[:27] = False
    rng = np.random.default_rng(seed)
    u = np.zeros(problem.space.n_dofs)
    u[2::3][top] = -0.03 + 0.06 * rng.random(top.sum())
    u[0::3][top] = 0.15 * rng.normal(size=top.sum())
    u[1::3][top] = 0.15 * rng.normal(size=top.sum())
    u[2::3][~top] += 0.02 * rng.normal(size=(~top).sum())
    return u


@pytest.mark.parametrize("barrier", [None, 0.0])
def test_blended_force_is_the_energy_gradient_and_the_tangent_its_derivative(monkeypatch, barrier):
    """Central differences of the full term (search included: the blended energy is smooth) on states where
    pairs are partly shared, partly covered (past a free edge) and just above their face; the facing factors come
    from the committed state. With the depth barrier from zero overlap (it then acts on every touching pair)."""
    totals = []

    def recorded(total, *args):
        totals.append(np.array(total))
        return normalisation(total, *args)

    monkeypatch.setattr(contact_blend, "normalisation", recorded)
    problem, contact = block_contact_problem(2, 3, 30.0, blend=BLEND, barrier=barrier)
    h = 1e-6
    seen = {"above": 0, "shared": 0}
    for seed in (3, 5):
        u = _rough_state(problem, seed)
        contact.assemble(u, 1.0, False, None)
        contact.commit()  # the facing factors: from the committed state's normals, fixed within a step
        pairs = contact.active_pairs(u)
        seen["above"] += int(np.sum(pairs.gap > 0.0))
        seen["shared"] += int(np.sum(np.any((pairs.weights > -BLEND) & (pairs.weights < BLEND), axis=1)))
        energy = contact.energy(u)
        full = contact.assemble(u, 1.0, True, None)
        K, f = full.matrix.toarray(), full.internal
        dofs = np.unique(3 * np.concatenate([pairs.node, contact.surface.triangles[pairs.triangle].ravel()])[:, None]
                         + np.arange(3))
        assert energy > 0.0
        for dof in dofs:
            step = np.zeros_like(u)
            step[dof] = h
            assert (contact.energy(u + step) - contact.energy(u - step)) / (2 * h) == pytest.approx(
                f[dof], abs=1e-7 * np.abs(f).max())
            fp = contact.assemble(u + step, 1.0, False, None).internal
            fm = contact.assemble(u - step, 1.0, False, None).internal
            np.testing.assert_allclose((fp - fm) / (2 * h), K[:, dof], atol=1e-6 * np.abs(K).max())
        np.testing.assert_allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    assert seen["above"] > 0 and seen["shared"] > 5
    # the sheets' share totals cover all three branches of the normalisation M
    totals = np.concatenate(totals)
    assert np.any(totals < 0.8) and np.any((totals > 0.8) & (totals < 1.0)) and np.any(totals > 1.0)


@pytest.mark.parametrize(("n_top", "rel"), [(2, 1e-6), (3, 1e-2)])
def test_blocks_pressed_together_carry_the_closed_form_force(n_top, rel):
    """Matching faces: every node sits on a vertex or an edge of the other face, where the shares sum to one or
    more, so the blended energy is the exact penalty energy and the closed form holds to solver tolerance.
    Non-matching faces: within the node-to-surface patch error (as the closest-triangle rule, 1 %)."""
    penalty, shortening = 50.0, 0.2
    problem, contact = block_contact_problem(2, n_top, penalty, blend=BLEND)
    problem.add_dirichlet(lambda X: X[2] == 2.0, -shortening, components=[2])
    result = solve(problem, steps=4, progress=False, rtol=1e-10, solver="scipy")
    pressure, _ = closed_form_force(shortening, penalty)
    assert -result.reaction(lambda X: X[2] == 2.0)[2] == pytest.approx(pressure, rel=rel)
    assert contact.active_pairs(result.u()).touching > 0


def _crease_forces(blend: float, slides: np.ndarray) -> np.ndarray:
    """Total contact force on the top block as its 3x3 face, 0.05 deep, slides in x over the 2x2 bottom face
    bent into a valley along x = 0.5 (a concave crease, 0.15 deep)."""
    problem, contact = block_contact_problem(2, 3, 30.0, blend=blend)
    X = problem.space.dof_coordinates
    bottom = np.arange(X.shape[1]) < 27
    u = np.zeros(problem.space.n_dofs)
    u[2::3][bottom] = -0.3 * (0.5 - np.abs(X[0, bottom] - 0.5)) * X[2, bottom]  # the valley, fading to the base
    top = ~bottom
    forces = []
    for slide in slides:
        v = u.copy()
        v[0::3][top] = slide
        v[2::3][top] = -0.05 - 0.3 * (0.5 - np.abs(X[0, top] + slide - 0.5).clip(max=0.5))  # the valley, 0.05 deep
        forces.append(contact.assemble(v, 1.0, False, None).internal[: 3 * X.shape[1]].reshape(-1, 3)[top].sum(0))
    return np.array(forces)


def test_the_force_stays_continuous_where_a_node_slides_over_a_concave_crease():
    """The closest-triangle rule has dead zones over a concave crease (a node deep in it projects outside both
    faces' bands), so the force jumps as a node slides across: its largest change from one position to the next
    does not shrink when the slide is sampled twice as finely. The blended force's does, by half (continuous)."""
    largest = {}
    for blend in (0.0, BLEND):
        for samples in (201, 401):
            forces = _crease_forces(blend, np.linspace(-0.2, 0.2, samples))
            largest[blend, samples] = np.abs(np.diff(forces, axis=0)).max() / np.abs(forces).max()
    assert largest[0.0, 401] > 0.05 and largest[0.0, 401] / largest[0.0, 201] > 0.9
    assert largest[BLEND, 401] / largest[BLEND, 201] == pytest.approx(0.5, abs=0.05)


def test_blended_contact_has_no_search_memory_and_checks_its_band():
    problem, contact = block_contact_problem(2, 3, 30.0, blend=BLEND)
    u = _rough_state(problem, 3)
    first = contact.assemble(u, 1.0, False, None).internal
    contact.assemble(_rough_state(problem, 5), 1.0, False, None)
    np.testing.assert_array_equal(contact.assemble(u, 1.0, False, None).internal, first)
    with pytest.raises(ValueError, match="blend"):
        SurfaceContact(problem.space, contact.surface, 1.0, blend=0.7)
    # free edges: the boundaries of the 2x2 and the 3x3 face, 8 + 12 edges, each on one triangle
    assert free_edges(contact.surface.triangles).sum() == 8 + 12


def _tilt_forces(blend: float, angles: np.ndarray) -> np.ndarray:
    """Total contact force on the top block, tilted about the line x = 0.5, z = 1 by each angle and lowered 0.05,
    with the facing test at 0.75 (normals more than 41 degrees from opposed start to drop out)."""
    problem, contact = block_contact_problem(2, 3, 30.0, blend=blend)
    contact.opposing = 0.75
    X = problem.space.dof_coordinates
    top = np.arange(X.shape[1]) >= 27
    forces = []
    for angle in angles:
        u = np.zeros(problem.space.n_dofs)
        dx, dz = X[0, top] - 0.5, X[2, top] - 1.0
        u[0::3][top] = np.cos(angle) * dx - np.sin(angle) * dz - dx
        u[2::3][top] = np.sin(angle) * dx + np.cos(angle) * dz - dz - 0.05
        contact.assemble(u, 1.0, False, None)
        contact.commit()
        forces.append(contact.assemble(u, 1.0, False, None).internal[: 3 * X.shape[1]].reshape(-1, 3)[top].sum(0))
    return np.array(forces)


def test_the_facing_factor_switches_pairs_off_smoothly_as_the_normals_turn():
    """Tilting the top block turns its nodes' normals away from the bottom face's: past the facing threshold the
    closest-triangle rule drops pairs at once (a jump that does not shrink with the sampling), blended contact fades
    them over the facing band (the largest change halves with the sampling step). Its facing factor is taken from
    the committed state, which ``state``/``restore`` carry."""
    largest = {}
    for blend in (0.0, BLEND):
        for samples in (101, 201):
            forces = _tilt_forces(blend, np.linspace(0.5, 0.9, samples))
            largest[blend, samples] = np.abs(np.diff(forces, axis=0)).max() / np.abs(forces).max()
    assert largest[0.0, 201] > 0.05 and largest[0.0, 201] / largest[0.0, 101] > 0.9
    assert largest[BLEND, 201] / largest[BLEND, 101] == pytest.approx(0.5, abs=0.1)
    problem, contact = block_contact_problem(2, 3, 30.0, blend=BLEND)
    u = _rough_state(problem, 3)
    contact.assemble(u, 1.0, False, None)
    contact.commit()
    saved = contact.state()
    force = contact.assemble(u, 1.0, False, None).internal
    contact.assemble(np.zeros_like(u), 1.0, False, None)
    contact.commit()
    contact.restore(saved)
    np.testing.assert_array_equal(contact.assemble(u, 1.0, False, None).internal, force)
    with pytest.raises(ValueError, match="committed_displacement"):
        contact.restore({"committed_displacement": np.zeros(5)})


def test_the_search_radius_misses_no_pair():
    """With a shallow search depth (as on the thin 1.1 shells) the tree search finds the same pairs as a search of
    every node against every triangle, with the top face slid over a grid of offsets so that projections fall past
    triangle edges and corners (a radius of r + depth, r the largest centroid-corner distance, missed pairs at 31
    of these 121 offsets: blended shares reach past a corner by up to 0.6 r)."""
    for blend in (0.0, BLEND):
        problem, contact = block_contact_problem(2, 3, 30.0, blend=blend)
        contact.max_penetration = 0.04
        top = np.arange(problem.space.n_scalar) >= 27
        for sx in np.linspace(0.0, 0.25, 11):
            for sy in np.linspace(0.0, 0.25, 11):
                u = np.zeros(problem.space.n_dofs)
                u[0::3][top], u[1::3][top], u[2::3][top] = sx, sy, -0.02
                found = contact.active_pairs(u)
                contact.search_radius = lambda corners, centroid: np.inf
                everything = contact.active_pairs(u)
                del contact.search_radius
                assert np.array_equal(found.node, everything.node)
                assert np.array_equal(found.triangle, everything.triangle)


def test_a_node_between_two_sheets_feels_each_in_full():
    """Shares are normalised per sheet: a node pressed into one sheet (share 1, energy psi) with another sheet's
    triangle just above it (share 0.8, no energy) keeps the energy psi; normalised together it would be psi / 1.8.
    The sheets are the node's triangles connected through shared vertices."""
    triangles = np.array([[0, 1, 2], [1, 2, 3], [10, 11, 12]])
    node = np.array([20, 20, 20])
    group = sheets(node, triangles)
    assert group[0] == group[1] != group[2]
    assert np.unique(sheets(np.array([20, 21]), triangles[:2])).size == 2  # other nodes: other groups
    dofs = (3 * np.column_stack([node, triangles])[:, :, None] + np.arange(3)).reshape(-1, 12)
    zeros = np.zeros((3, 12))
    phi, psi = np.array([1.0, 0.0, 0.8]), np.array([0.5, 0.0, 0.0])
    area = np.zeros(21)
    area[20] = 2.0
    hess = np.zeros((3, 12, 12))
    for groups, expected in ((group, 2.0 * 0.5), (np.zeros(3, dtype=int), 2.0 * 0.5 / 1.8)):
        _, _, energy = weighted_mean_energy(node, groups, dofs, area, phi, zeros, hess, psi, zeros, hess, 63, True)
        assert energy == pytest.approx(expected)


def test_each_triangles_own_search_radius_misses_no_pair_on_a_graded_surface():
    """Triangles of very different sizes (the bottom face graded 0.05 to 0.65 across, the top one uniform): the search
    with each triangle's own radius finds exactly the pairs of a search of every node against every triangle, for
    both contact rules, with the top face slid over a grid of offsets."""
    graded = np.array([0.0, 0.05, 0.15, 0.35, 1.0])
    bottom = skfem.MeshHex.init_tensor(graded, graded, np.linspace(0.0, 1.0, 3))
    top = skfem.MeshHex.init_tensor(*(np.linspace(0.0, 1.0, 4),) * 2, np.linspace(1.0, 2.0, 3))
    mesh = skfem.MeshHex(np.hstack([bottom.p, top.p]), np.hstack([bottom.t, top.t + bottom.p.shape[1]]))
    surface = ContactSurface.from_facets(mesh, mesh.facets_satisfying(lambda X: np.isclose(X[2], 1.0), True))
    upper = np.arange(mesh.p.shape[1]) >= bottom.p.shape[1]
    for blend in (0.0, BLEND):
        contact = SurfaceContact(Space(mesh), surface, 30.0, max_penetration=0.04, blend=blend)
        radii = contact.search_radius(*(lambda c: (c, c.mean(axis=1)))(mesh.p.T[surface.triangles]))
        assert radii.max() > 5.0 * radii.min()  # the per-triangle radius matters here
        for sx in np.linspace(0.0, 0.3, 7):
            for sy in np.linspace(0.0, 0.3, 7):
                u = np.zeros(3 * mesh.p.shape[1])
                u[0::3][upper], u[1::3][upper], u[2::3][upper] = sx, sy, -0.02
                found = contact.active_pairs(u)
                contact.search_radius = lambda corners, centroid: np.inf
                everything = contact.active_pairs(u)
                del contact.search_radius
                assert found.size > 0
                assert np.array_equal(found.node, everything.node)
                assert np.array_equal(found.triangle, everything.triangle)


def test_near_pairs_lists_every_point_within_each_centres_own_radius():
    """Against all pairs' distances: per-centre radii and one scalar radius, sorted by point then centre."""
    rng = np.random.default_rng(7)
    points, centres = rng.random((200, 3)), rng.random((50, 3))
    distance = np.linalg.norm(points[:, None] - centres[None], axis=2)
    for radius in (rng.uniform(0.01, 0.4, 50), 0.2):
        point, centre = near_pairs(points, centres, radius)
        expected = np.argwhere(distance <= np.broadcast_to(radius, (50,))[None])
        np.testing.assert_array_equal(np.column_stack([point, centre]), expected)  # argwhere: row-major order
    empty = near_pairs(points, centres + 10.0, 0.1)
    assert empty[0].size == empty[1].size == 0
