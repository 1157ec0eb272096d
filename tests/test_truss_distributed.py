"""Bars whose ends are weighted averages of nodes (a distributing coupling, ``BarEnd``) and the chordae
insertion patches built from them."""

import numpy as np
import pytest
import scipy.sparse as sp
import skfem

from skvalve.fem import Space
from skvalve.fem.elements.truss import BarEnd, Truss
from skvalve.materials.uniaxial import LinearUniaxial, OgdenUniaxial, TensionOnly
from skvalve.valve.chordae import insertion_patches

CABLE = TensionOnly(OgdenUniaxial((1.5, 0.2), (12.0, 2.0)), slack_fraction=1e-3, transition=0.02)


def _space():
    return Space(skfem.MeshHex().refined(1))  # 27 vertices on the unit cube


def _matrix(contribution, n):
    block = contribution.blocks[0]
    m = block.dofs.shape[1]
    rows = np.repeat(block.dofs[:, :, None], m, axis=2).ravel()
    cols = np.repeat(block.dofs[:, None, :], m, axis=1).ravel()
    return sp.csr_matrix((block.matrices.ravel(), (rows, cols)), shape=(n, n))


def test_end_at_the_mean_of_two_nodes_splits_the_force_and_matches_a_bar_to_that_point():
    space = _space()
    X = space.mesh.p.T
    a1, a2, b = 0, 1, 26  # the bar runs from the midpoint of vertices 0 and 1 to vertex 26
    ends = (BarEnd(np.array([[a1, a2]]), np.array([[0.5, 0.5]])), BarEnd.single(np.array([b])))
    area, modulus, rest = 0.3, 7.0, 1.2
    truss = Truss(space, ends, area, LinearUniaxial(modulus), rest_length=[rest])
    u = np.random.default_rng(1).normal(scale=0.05, size=space.n_dofs)
    c = truss.assemble(u, 0.0, True, 1)
    x = X + u.reshape(-1, 3)
    d = x[b] - 0.5 * (x[a1] + x[a2])
    length = np.linalg.norm(d)
    force = area * modulus * (length / rest - 1.0) * d / length  # closed form: linear law, nominal stress
    f = c.internal.reshape(-1, 3)
    assert np.allclose(f[b], force, rtol=1e-12, atol=0)
    assert np.allclose(f[a1], -0.5 * force, rtol=1e-12, atol=0) and np.allclose(f[a2], -0.5 * force, rtol=1e-12)


@pytest.mark.parametrize("seed", [0, 1])
def test_distributed_tangent_matches_central_differences(seed):
    space = _space()
    rng = np.random.default_rng(seed)
    ends = (BarEnd(np.array([[0, 1, 3], [4, 5, 5]]), np.array([[0.2, 0.5, 0.3], [0.6, 0.4, 0.0]])),
            BarEnd(np.array([[26, 25], [20, 26]]), np.array([[0.7, 0.3], [0.5, 0.5]])))
    truss = Truss(space, ends, [0.3, 0.2], CABLE, rest_length=[1.0, 0.9], slack_stretch=[0.95, 1.0])
    u = rng.normal(scale=0.08, size=space.n_dofs)
    K = _matrix(truss.assemble(u, 0.0, True, 1), space.n_dofs)
    direction, h = rng.normal(size=space.n_dofs), 1e-6
    plus = truss.assemble(u + h * direction, 0.0, False, 1).internal
    minus = truss.assemble(u - h * direction, 0.0, False, 1).internal
    exact = K @ direction
    assert np.linalg.norm((plus - minus) / (2 * h) - exact) <= 1e-7 * np.linalg.norm(exact)
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()


def test_single_weight_ends_are_the_plain_bar():
    space = _space()
    u = np.random.default_rng(4).normal(scale=0.05, size=space.n_dofs)
    plain = Truss(space, [[0, 26]], 0.3, CABLE, rest_length=[1.9])
    padded = Truss(space, (BarEnd(np.array([[0, 7]]), np.array([[1.0, 0.0]])), BarEnd.single(np.array([26]))), 0.3,
                   CABLE, rest_length=[1.9])
    one, two = plain.assemble(u, 0, True, 1), padded.assemble(u, 0, True, 1)
    assert np.allclose(one.internal, two.internal, rtol=1e-14, atol=1e-300)
    K1, K2 = _matrix(one, space.n_dofs), _matrix(two, space.n_dofs)
    assert abs(K1 - K2).max() <= 1e-14 * abs(K1).max()


def test_bad_weights_are_named():
    space = _space()
    with pytest.raises(ValueError, match="end a: weights of bar"):
        Truss(space, (BarEnd(np.array([[0, 1]]), np.array([[0.5, 0.6]])), BarEnd.single(np.array([26]))), 0.3, CABLE)
    with pytest.raises(ValueError, match="node indices"):
        Truss(space, (BarEnd(np.array([[0, 99]]), np.array([[0.5, 0.5]])), BarEnd.single(np.array([26]))), 0.3, CABLE)


def test_insertion_patch_is_the_cells_around_the_node_and_keeps_the_slack():
    """A cable from a corner vertex of a 2x2x2 hex block (one cell around it) and one from the centre vertex
    (all 8 cells: all 27 vertices) to a vertex no cell uses: the ends become the cell-vertex averages, the far
    end stays single, and the rest length shifts by the change of chord so that path - chord is unchanged."""
    block = skfem.MeshHex().refined(1)
    points = np.hstack([block.p, [[3.0], [0.5], [0.5]]])  # vertex 27: a papillary tip, in no cell
    cells = block.t
    centre = int(np.flatnonzero(np.all(np.isclose(block.p, 0.5), axis=0))[0])
    corner = int(np.flatnonzero(np.all(np.isclose(block.p, 0.0), axis=0))[0])
    ends = np.array([[corner, 27], [centre, 27]])
    rest = np.array([3.4, 2.7])
    (end_a, end_b), new_rest, slack = insertion_patches(cells, points, ends, rest)
    corner_cell = np.flatnonzero(np.any(cells == corner, axis=0))
    assert corner_cell.size == 1
    assert set(end_a.nodes[0][end_a.weights[0] > 0]) == set(cells[:, corner_cell[0]])
    assert set(end_a.nodes[1][end_a.weights[1] > 0]) == set(range(27))
    assert np.allclose(end_a.weights.sum(axis=1), 1.0) and np.all(end_b.nodes == 27)
    X = points.T
    centroid = np.array([X[cells[:, corner_cell[0]]].mean(axis=0), X[:27].mean(axis=0)])
    old_chord = np.linalg.norm(X[27] - X[ends[:, 0]], axis=1)
    new_chord = np.linalg.norm(X[27] - centroid, axis=1)
    assert np.allclose(new_rest - new_chord, rest - old_chord, rtol=0, atol=1e-14)
    assert np.allclose(slack, new_chord / new_rest, rtol=1e-14)
