"""Shared small set-ups of the truss and continuation tests."""

import numpy as np
import skfem

from skvalve.fem import Solid, Space
from skvalve.fem.elements.truss import Truss
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


def two_blocks_with_chord(law, area: float, rest_length: float, slack_stretch: float | None = None):
    """Two unit blocks 2 apart on the x axis (the second translated to x = 3), a Neo-Hookean solid, and one truss of
    ``law`` from the centre of the first block's face x = 1 (``face``) to that of the second's face x = 3
    (``anchor``). Returns ``(solid, chord, face, anchor)``; the caller prescribes the supports."""
    first = skfem.MeshHex().refined(1)
    second = skfem.MeshHex().refined(1).translated([3.0, 0.0, 0.0])
    mesh = skfem.MeshHex(np.hstack([first.p, second.p]), np.hstack([first.t, second.t + first.p.shape[1]]))
    solid = Solid(mesh, NeoHookean(1.0, 5.0))
    X = solid.space.dof_coordinates
    face = np.flatnonzero(np.isclose(X[0], 1.0) & np.isclose(X[1], 0.5) & np.isclose(X[2], 0.5))[0]
    anchor = np.flatnonzero(np.isclose(X[0], 3.0) & np.isclose(X[1], 0.5) & np.isclose(X[2], 0.5))[0]
    extra = {} if slack_stretch is None else {"slack_stretch": [slack_stretch]}
    chord = solid.add_term(Truss(solid.space, [[face, anchor]], area, law, rest_length=[rest_length], **extra))
    return solid, chord, face, anchor
