"""Mesh utilities (:mod:`skvalve.fem.meshes`): corner Jacobians of hexahedra against closed forms."""

import numpy as np
import skfem

from skvalve.fem.meshes import box, distort, hex_corner_jacobians


def test_corner_jacobians_of_an_affine_map_are_its_determinant():
    """x = A X: every corner of the unit cube has J = det A (the cube's edges have unit length)."""
    cube = skfem.MeshHex()
    assert np.array_equal(hex_corner_jacobians(cube.p.T, cube.t.T), np.ones((1, 8)))
    A = np.array([[2.0, 0.3, 0.0], [0.1, 1.0, 0.2], [0.0, 0.4, 1.5]])
    assert np.allclose(hex_corner_jacobians(cube.p.T @ A.T, cube.t.T), np.linalg.det(A), rtol=1e-14)
    # a reflection turns every corner negative
    assert np.all(hex_corner_jacobians(cube.p.T * [-1.0, 1.0, 1.0], cube.t.T) < 0.0)


def test_a_corner_pushed_past_the_cells_centre_is_the_only_folded_one():
    """Corner 7 of the unit cube, (1, 1, 1), moved to (0.3, 0.3, 0.3): its edges to corners 4, 5, 6 are
    (-0.3, 0.7, 0.7), (0.7, -0.3, 0.7), (0.7, 0.7, -0.3), whose determinant (a - b)^2 (a + 2b) with a = -0.3,
    b = 0.7 is 1.1, and the corner's edges point along -x, -y, -z (sign -1): J = -1.1. Corner 4 keeps the edges
    (0.3, -0.7, -0.7), (0, -1, 0), (0, 0, -1): J = 0.3, as 5 and 6 by symmetry; 0-3 are untouched (J = 1). A distorted
    box of 27 cells folds nowhere."""
    cube = skfem.MeshHex()
    points = cube.p.T.copy()
    points[7] = 0.3
    J = hex_corner_jacobians(points, cube.t.T)[0]
    assert np.allclose(J, [1.0, 1.0, 1.0, 1.0, 0.3, 0.3, 0.3, -1.1], rtol=0.0, atol=1e-14)
    mesh = distort(box(3), amount=0.2, seed=1)
    assert np.all(hex_corner_jacobians(mesh.p.T, mesh.t.T) > 0.0)
