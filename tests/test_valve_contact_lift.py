"""Lifting parked contact nodes (:mod:`skvalve.valve.contact_lift`): two blocks overlapping by 0.8 of the search depth
are moved apart to exactly the target overlap (the gap is linear along the facing normal), each node with the column
of vertices behind it; a lone node's lift that would fold or squeeze a thin hex is halved or refused; held nodes and
columns that reach them stay; bad arguments are refused."""

import numpy as np
import pytest
import skfem

from skvalve.fem import HyperelasticTerm, MaterialRegions, Problem, Space
from skvalve.fem.contact import ContactSurface, SurfaceContact
from skvalve.materials import NeoHookean
from skvalve.valve.contact_lift import force_limit, lift_parked_nodes
from skvalve.valve.extrude import hex_corner_jacobians
from skvalve.valve.model import ABAQUS_TO_SKFEM_HEX

DEPTH, OVERLAP = 0.1, 0.08  # the top block's lower face 0.8 of the search depth inside the bottom block


def _blocks(bottom_layers=(0.0, 0.5, 1.0)):
    """A unit cube (2x2 hexes across, layers at ``bottom_layers``) and a second one whose lower face lies OVERLAP below
    the first one's upper face; contact between the two faces (blended, as the valve)."""
    line = np.linspace(0.0, 1.0, 3)
    bottom = skfem.MeshHex.init_tensor(line, line, np.asarray(bottom_layers))
    top = skfem.MeshHex.init_tensor(line, line, np.linspace(1.0 - OVERLAP, 2.0 - OVERLAP, 3))
    mesh = skfem.MeshHex(np.hstack([bottom.p, top.p]), np.hstack([bottom.t, top.t + bottom.p.shape[1]]))
    faces = mesh.facets_satisfying(lambda X: np.isclose(X[2], 1.0) | np.isclose(X[2], 1.0 - OVERLAP), True)
    contact = SurfaceContact(Space(mesh), ContactSurface.from_facets(mesh, faces), 50.0, max_penetration=DEPTH,
                             blend=0.1, barrier=0.4)
    return mesh, contact, bottom.p.shape[1]


def _faces(mesh, u):
    """z of the bottom block's upper face nodes and of the top block's lower face nodes."""
    z = mesh.p[2] + u[2::3]
    return z[np.isclose(mesh.p[2], 1.0)], z[np.isclose(mesh.p[2], 1.0 - OVERLAP)]


def _folded(mesh, u) -> int:
    x = mesh.p.T + u.reshape(-1, 3)
    return int((hex_corner_jacobians(x, mesh.t.T[:, np.argsort(ABAQUS_TO_SKFEM_HEX)]) <= 0.0).any(axis=1).sum())


def test_parked_faces_are_lifted_to_exactly_the_target_overlap():
    mesh, contact, _ = _blocks()
    u = np.zeros(3 * mesh.p.shape[1])
    lift = lift_parked_nodes(contact, u, mesh, level=0.7, target=0.6, columns=True)
    assert np.all(u == 0.0)  # the input is not changed
    upper, lower = _faces(mesh, lift.u)
    # one face moves OVERLAP - 0.6 DEPTH (its nodes come first); then the other's nodes sit at the target, untouched
    assert upper.max() - lower.min() == pytest.approx(0.6 * DEPTH, abs=1e-12)
    assert np.allclose(lift.lifts, OVERLAP - 0.6 * DEPTH, atol=1e-12)
    assert lift.lifted.size == 9 and lift.refused.size == 0
    assert (lift.deeper_before, lift.deeper_after) == (18, 0)
    # each face node moves with its column (the three vertices through the bottom block), straight along z
    moved = np.flatnonzero(np.any(lift.u.reshape(-1, 3) != 0.0, axis=1))
    assert moved.size == 27 and np.all(mesh.p[2, moved] <= 1.0)
    np.testing.assert_allclose(lift.u.reshape(-1, 3)[moved], [[0.0, 0.0, -(OVERLAP - 0.6 * DEPTH)]] * 27, atol=1e-15)
    assert _folded(mesh, lift.u) == 0
    alone = lift_parked_nodes(contact, u, mesh)
    assert np.count_nonzero(alone.u) == alone.lifted.size == 9  # the nodes alone, along z only
    assert "lifted 9 parked nodes" in str(lift)


def test_a_lift_that_would_fold_a_thin_hex_is_halved_or_refused():
    """The bottom block's upper layer is 0.015 thick, less than the 0.02 lift its face's nodes would need."""
    layers = (0.0, 0.985, 1.0)
    mesh, contact, n_bottom = _blocks(layers)
    u = np.zeros(3 * mesh.p.shape[1])
    refused = lift_parked_nodes(contact, u, mesh, halvings=0, max_stretch_change=10.0)  # folding
    assert refused.refused.size == 9 and np.all(refused.refused < n_bottom)  # the thin layer's nodes stay
    assert refused.lifted.size == 9 and np.all(refused.lifted >= n_bottom)  # the top block's nodes move instead
    upper, lower = _faces(mesh, refused.u)
    assert upper.max() - lower.min() == pytest.approx(0.6 * DEPTH, abs=1e-12)
    halved = lift_parked_nodes(contact, u, mesh, halvings=1, max_stretch_change=10.0)
    assert halved.refused.size == 0
    moved_down = halved.lifted < n_bottom
    assert moved_down.sum() == 9 and np.allclose(halved.lifts[moved_down], 0.5 * (OVERLAP - 0.6 * DEPTH))
    assert _folded(mesh, halved.u) == 0 and _folded(mesh, refused.u) == 0


@pytest.mark.parametrize("kwargs", [{"target": 0.7, "level": 0.6}, {"target": 0.0}, {"level": 1.0},
                                    {"sweeps": 0}, {"halvings": -1}, {"max_stretch_change": 0.0},
                                    {"max_stretch_change": float("nan")}])
def test_bad_lift_arguments_are_refused(kwargs):
    mesh, contact, _ = _blocks()
    with pytest.raises(ValueError, match="lift_parked_nodes"):
        lift_parked_nodes(contact, np.zeros(3 * mesh.p.shape[1]), mesh, **kwargs)


def test_a_non_finite_state_is_refused():
    mesh, contact, _ = _blocks()
    u = np.zeros(3 * mesh.p.shape[1])
    u[7] = np.nan
    with pytest.raises(ValueError, match="finite"):
        lift_parked_nodes(contact, u, mesh)


def test_a_lift_that_would_squeeze_a_thin_hex_too_much_is_halved_until_it_does_not():
    """With the stretch bound (0.2): 0.02 through a 0.015 layer is a change of 1.33, 0.02/8 = 0.0025 one of 0.167."""
    mesh, contact, n_bottom = _blocks((0.0, 0.985, 1.0))
    lift = lift_parked_nodes(contact, np.zeros(3 * mesh.p.shape[1]), mesh)
    moved_down = lift.lifted < n_bottom
    assert moved_down.sum() == 9 and np.allclose(lift.lifts[moved_down], (OVERLAP - 0.6 * DEPTH) / 8)
    x = mesh.p.T + lift.u.reshape(-1, 3)  # every vertex pair of every hex changed its stretch by at most 0.2
    for a in range(8):
        for b in range(a + 1, 8):
            ends = mesh.t[[a, b]]
            change = (np.linalg.norm(x[ends[1]] - x[ends[0]], axis=1)
                      / np.linalg.norm(mesh.p.T[ends[1]] - mesh.p.T[ends[0]], axis=1) - 1.0)
            assert np.all(np.abs(change) <= 0.2 + 1e-12)
    upper, lower = _faces(mesh, lift.u)
    assert upper.max() - lower.min() == pytest.approx(0.6 * DEPTH, abs=1e-12)  # the top block's face takes the rest
    column = lift_parked_nodes(contact, np.zeros(3 * mesh.p.shape[1]), mesh, columns=True)  # not squeezed
    assert np.allclose(column.lifts, OVERLAP - 0.6 * DEPTH) and np.all(column.lifted < n_bottom)
    z = mesh.p[2] + column.u[2::3]
    np.testing.assert_allclose(z[np.isclose(mesh.p[2], 1.0)] - z[np.isclose(mesh.p[2], 0.985)], 0.015, atol=1e-12)


def test_held_nodes_do_not_move():
    """Holding the bottom block's face (as a prescribed or linked node would be): the top block's face moves instead."""
    mesh, contact, n_bottom = _blocks()
    u = np.zeros(3 * mesh.p.shape[1])
    free = lift_parked_nodes(contact, u, mesh)
    assert np.all(free.lifted < n_bottom)  # unheld, the bottom face moves first (lower ids)
    held = np.arange(n_bottom)
    lift = lift_parked_nodes(contact, u, mesh, held=held)
    assert lift.lifted.size == 9 and np.all(lift.lifted >= n_bottom)
    assert np.all(lift.u[: 3 * n_bottom] == 0.0)
    upper, lower = _faces(mesh, lift.u)
    assert upper.max() - lower.min() == pytest.approx(0.6 * DEPTH, abs=1e-12)


def test_a_column_that_reaches_a_held_node_is_refused():
    """The bottom block's base held (a support): its face nodes' columns reach it, so the top block's face moves."""
    mesh, contact, n_bottom = _blocks()
    base = np.flatnonzero(np.isclose(mesh.p[2], 0.0))
    lift = lift_parked_nodes(contact, np.zeros(3 * mesh.p.shape[1]), mesh, held=base, columns=True)
    assert lift.refused.size == 9 and np.all(lift.refused < n_bottom)
    assert lift.lifted.size == 9 and np.all(lift.lifted >= n_bottom)
    assert np.all(lift.u[: 3 * n_bottom] == 0.0)


def test_a_force_limit_halves_lifts_until_the_forces_they_cause_are_small_enough():
    """Neo-Hookean blocks, the lone face nodes lifted: the force a lift causes grows with it, so a limit between the
    forces of a full and a halved lift halves every lift once; an inverted element is refused, not raised."""
    mesh, contact, n_bottom = _blocks()
    space = contact.space
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 2.0)))])
    problem.add_dirichlet(lambda X: np.isclose(X[2], 0.0), 0.0)
    u = np.zeros(space.n_dofs)

    def largest_force(v):
        r, _ = problem.assemble(v, 1.0, tangent=False)
        r[problem.pattern.fixed] = 0.0
        return np.linalg.norm(r.reshape(-1, 3), axis=1).max()

    full = lift_parked_nodes(contact, u, mesh)
    half = lift_parked_nodes(contact, u, mesh, halvings=0, max_stretch_change=1.0)
    assert half.lifts.size == 9
    one_node = u.copy()
    one_node[3 * full.lifted[0] + 2] = -full.lifts[0]
    whole, halved = largest_force(one_node), largest_force(0.5 * one_node)
    assert halved < whole
    limit = 0.5 * (whole + halved)
    limited = lift_parked_nodes(contact, u, mesh, accept=force_limit(problem, 1.0, limit, mesh))
    assert limited.lifted[0] == full.lifted[0] and limited.lifts[0] == pytest.approx(0.5 * full.lifts[0], rel=1e-12)
    halvings = np.log2(full.lifts[0] / limited.lifts[:9])  # the first sweep's (bottom face) lifts: halved full ones
    np.testing.assert_allclose(halvings, np.round(halvings), atol=1e-9)
    assert largest_force(limited.u) <= limit  # each move was checked on every vertex it could load
    with pytest.raises(ValueError, match="max_force"):
        force_limit(problem, 1.0, -1.0, mesh)
    flat = u.copy()
    flat[2::3][np.isclose(mesh.p[2], 1.0)] = -0.5  # the upper layer of the bottom block inverted
    assert force_limit(problem, 1.0, 1e9, mesh)(flat, [int(np.flatnonzero(np.isclose(mesh.p[2], 1.0))[0])]) is False
