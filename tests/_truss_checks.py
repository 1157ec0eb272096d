"""Shared small set-ups of the truss and continuation tests."""

import numpy as np
import skfem

from skvalve.fem import Solid, Space
from skvalve.materials import NeoHookean


def two_nodes(L: float = 2.0):
    """A single L-cube hex: its space, the vertex at the origin and the vertex at (L, 0, 0) (a bar's two ends)."""
    space = Space(skfem.MeshHex().scaled([L, L, L]))
    X = space.dof_coordinates
    a = int(np.flatnonzero(np.all(np.isclose(X, 0.0), axis=0))[0])
    b = int(np.flatnonzero(np.isclose(X[0], L) & np.isclose(X[1], 0) & np.isclose(X[2], 0))[0])
    return space, a, b


def sheared_block():
    """A unit block (4x4x4 hexes) clamped at x = 0 whose face x = 1 is moved 0.5 along z: bending and shear."""
    solid = Solid(skfem.MeshHex().refined(2), NeoHookean(1.0, 10.0))
    solid.add_dirichlet(lambda X: X[0] == 0.0, 0.0)
    solid.add_dirichlet(lambda X: X[0] == 1.0, np.array([0.0, 0.0, 0.5]))
    return solid
