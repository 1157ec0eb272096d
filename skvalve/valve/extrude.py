r"""Shell midsurfaces (Abaqus S4R) extruded into layers of trilinear hexahedra.

The Texas TriValve 1.1 leaflets are midsurface shells of section thickness :math:`h`. Each shell node
:math:`X` gets the averaged unit normal

.. math::

    n(X) = \frac{\sum_{e \ni X} a_e}{\lVert\sum_{e \ni X} a_e\rVert}, \qquad
    a_e = \tfrac12\,(x_{e,3} - x_{e,1})\times(x_{e,4} - x_{e,2}),

the area-weighted normals :math:`a_e` of the quadrilaterals around it (the vector area of a
possibly warped quad, oriented by its node order as Abaqus orients the shell's positive side
``SPOS``). Layer :math:`k = 0..n` of nodes sits at :math:`X + (k/n - 1/2)\,h\,n(X)` and every quad
becomes :math:`n` hexahedra in Abaqus C3D8 order (the quad at layer :math:`k`, then the same quad at
layer :math:`k+1`). Since :math:`(x_2 - x_1)\times(x_4 - x_1)` points along :math:`+n`, the hexes are
positively oriented; this is checked at all eight corners of every hex (``det J > 0``) and a quad
whose own normal opposes the averaged normal of one of its nodes (inconsistently oriented
neighbours, a fold) is reported with its element index. The shell's negative face ``SNEG`` is face
``S1`` of the bottom layer, ``SPOS`` face ``S2`` of the top layer.

The extrusion keeps the midsurface in the middle of the solid and the thickness along the normal;
the volume of a flat patch is exactly area x thickness, and a closed ring of quads on a cylinder
extrudes into the exact prism between the inner and outer polygons (tested).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ExtrudedShell", "nodal_normals", "extrude_shell", "hex_corner_jacobians", "hex_volumes"]

#: Reference corner coordinates (xi, eta, zeta) of the Abaqus C3D8 node order.
_CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                     [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


@dataclass
class ExtrudedShell:
    """Hexahedra from a shell midsurface.

    Attributes
    ----------
    nodes : (n_shell_nodes * (layers + 1), 3) coordinates; node ``j`` of layer ``k`` is ``k * n_shell_nodes + j``.
    hexes : (n_quads * layers, 8) node indices in Abaqus C3D8 order; hex ``layer * n_quads + e``.
    shell_element : (n_hexes,) the quad each hex comes from.
    layer : (n_hexes,) its layer (0 = the ``SNEG`` side).
    normals : (n_shell_nodes, 3) the averaged unit normals used.
    """

    nodes: np.ndarray
    hexes: np.ndarray
    shell_element: np.ndarray
    layer: np.ndarray
    normals: np.ndarray
    layers: int

    def layer_nodes(self, k: int) -> np.ndarray:
        """Indices of the nodes of layer ``k`` (shell node order)."""
        n = self.normals.shape[0]
        return np.arange(k * n, (k + 1) * n)

    def face_hexes(self, face: str) -> np.ndarray:
        """Hexes carrying the shell face ``"SPOS"`` (their face S2) or ``"SNEG"`` (their face S1), quad order."""
        n_quads = self.hexes.shape[0] // self.layers
        if face.upper() == "SNEG":
            return np.arange(n_quads)
        if face.upper() == "SPOS":
            return np.arange((self.layers - 1) * n_quads, self.layers * n_quads)
        raise ValueError(f"shell face must be 'SPOS' or 'SNEG'; got {face!r}")


def nodal_normals(nodes: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """Area-weighted averaged unit normals at the nodes (zero rows for nodes no quad uses)."""
    x = nodes[quads]  # (n, 4, 3)
    area = 0.5 * np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
    summed = np.zeros_like(nodes, dtype=float)
    for corner in range(4):
        np.add.at(summed, quads[:, corner], area)
    norm = np.linalg.norm(summed, axis=1)
    used = np.zeros(nodes.shape[0], dtype=bool)
    used[quads.ravel()] = True
    degenerate = np.flatnonzero(used & ~(norm > 0.0))
    if degenerate.size:
        raise ValueError(f"shell nodes {degenerate[:10].tolist()}: the normals of their quads cancel (a fold or "
                         "inconsistently oriented neighbours)")
    out = np.zeros_like(summed)
    out[used] = summed[used] / norm[used, None]
    bad = np.flatnonzero(np.any(np.einsum("eci,ei->ec", out[quads], area) <= 0.0, axis=1))
    if bad.size:
        raise ValueError(f"shell elements {bad[:10].tolist()} face against the averaged normal of one of their nodes "
                         "(inconsistent orientation or a fold)")
    return out


def hex_corner_jacobians(nodes: np.ndarray, hexes: np.ndarray) -> np.ndarray:
    """det(dX/dxi) of the trilinear map at the eight corners of each hex (Abaqus order), shape (n, 8)."""
    xi = _CORNERS
    # dN_a/dxi_j at corner c: (1/8) xi_aj prod_{k != j} (1 + xi_ak xi_ck)
    factors = 1.0 + xi[None, :, :] * xi[:, None, :]  # (c, a, k)
    dN = np.empty((8, 8, 3))
    for j in range(3):
        others = [k for k in range(3) if k != j]
        dN[:, :, j] = 0.125 * xi[None, :, j] * factors[:, :, others[0]] * factors[:, :, others[1]]
    jac = np.einsum("nai,caj->ncij", nodes[hexes], dN)
    return np.linalg.det(jac)


def hex_volumes(nodes: np.ndarray, hexes: np.ndarray) -> np.ndarray:
    """Volumes of trilinear hexes (2x2x2 Gauss rule, exact for the trilinear map's Jacobian)."""
    g = 1.0 / np.sqrt(3.0)
    points = np.array([[a, b, c] for a in (-g, g) for b in (-g, g) for c in (-g, g)])
    xi = _CORNERS
    total = np.zeros(hexes.shape[0])
    x = nodes[hexes]
    for p in points:
        f = 1.0 + xi * p  # (a, k)
        dN = np.stack([0.125 * xi[:, j] * np.prod(np.delete(f, j, axis=1), axis=1) for j in range(3)], axis=1)
        total += np.linalg.det(np.einsum("nai,aj->nij", x, dN))
    return total


def extrude_shell(nodes: np.ndarray, quads: np.ndarray, thickness, layers: int) -> ExtrudedShell:
    """Extrude quads (n, 4) on ``nodes`` (N, 3) into ``layers`` hexes through ``thickness``.

    ``thickness``: one number, or one per quad (a node takes the mean over its quads).
    Raises ``ValueError`` naming the hexes with a non-positive corner Jacobian.
    """
    nodes = np.asarray(nodes, dtype=float)
    quads = np.asarray(quads, dtype=np.int64)
    if quads.ndim != 2 or quads.shape[1] != 4:
        raise ValueError(f"shell elements must be quads of shape (n, 4); got {quads.shape}")
    if int(layers) != layers or layers < 1:
        raise ValueError(f"layers must be a positive integer; got {layers!r}")
    layers = int(layers)
    h = np.broadcast_to(np.asarray(thickness, dtype=float), (quads.shape[0],))
    if not np.all(np.isfinite(h) & (h > 0)):
        raise ValueError("shell thickness must be positive and finite")
    node_h = np.zeros(nodes.shape[0])
    count = np.zeros(nodes.shape[0])
    for corner in range(4):
        np.add.at(node_h, quads[:, corner], h)
        np.add.at(count, quads[:, corner], 1.0)
    node_h = np.divide(node_h, count, out=np.zeros_like(node_h), where=count > 0)
    normals = nodal_normals(nodes, quads)
    n = nodes.shape[0]
    stacked = np.vstack([nodes + ((k / layers - 0.5) * node_h)[:, None] * normals for k in range(layers + 1)])
    hexes = np.vstack([np.hstack([quads + k * n, quads + (k + 1) * n]) for k in range(layers)])
    det = hex_corner_jacobians(stacked, hexes)
    bad = np.flatnonzero(np.any(det <= 0.0, axis=1))
    if bad.size:
        shell = bad % quads.shape[0]
        raise ValueError(f"extrusion gives {bad.size} hex(es) with det J <= 0 at a corner, from shell elements "
                         f"{np.unique(shell)[:10].tolist()}: thickness too large for the curvature there")
    n_quads = quads.shape[0]
    return ExtrudedShell(stacked, hexes, np.tile(np.arange(n_quads), layers), np.repeat(np.arange(layers), n_quads),
                         normals, layers)
