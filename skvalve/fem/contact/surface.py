"""Contact surfaces of hex meshes: boundary quadrilaterals oriented outward and split into triangles.

Both contact laws of :mod:`skvalve.fem.contact` (the IPC barrier and the penalty) see a body's surface as a
:class:`ContactSurface`: its quads in cyclic order with the normal pointing away from the owning hex, the two triangles
of each quad, the surface's nodes and their reference tributary areas.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ContactSurface", "oriented_quads"]


def oriented_quads(X: np.ndarray, quads: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """Quads (n, 4) in cyclic order with the normal pointing away from the points ``inside`` (n, 3).

    ``X`` (n_nodes, 3) reference coordinates; each quad's nodes are sorted by angle about its centroid in
    its best-fit plane (so any input order works), then reversed where the normal faces ``inside``.
    """
    quads = np.asarray(quads, dtype=np.int64)
    P = X[quads]  # (n, 4, 3)
    centre = P.mean(axis=1, keepdims=True)
    rel = P - centre
    normal = np.cross(rel[:, 0], rel[:, 1]) + np.cross(rel[:, 1], rel[:, 2]) + np.cross(rel[:, 2], rel[:, 3]) \
        + np.cross(rel[:, 3], rel[:, 0]) + np.cross(rel[:, 0], rel[:, 2])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    e1 = rel[:, 0] / np.linalg.norm(rel[:, 0], axis=1, keepdims=True)
    e2 = np.cross(normal, e1)
    angle = np.arctan2(np.einsum("nkj,nj->nk", rel, e2), np.einsum("nkj,nj->nk", rel, e1))
    ordered = np.take_along_axis(quads, np.argsort(angle, axis=1), axis=1)
    Q = X[ordered]
    area_vector = np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1])
    flip = np.einsum("ij,ij->i", area_vector, Q.mean(axis=1) - np.asarray(inside, dtype=float)) < 0.0
    ordered[flip] = ordered[flip][:, ::-1]
    return ordered


@dataclass
class ContactSurface:
    """A surface of quadrilateral faces (cyclic, outward) split into triangles.

    Attributes
    ----------
    quads : (n_faces, 4) scalar node indices, cyclic, normal outward.
    triangles : (2 n_faces, 3) the triangles (face k gives triangles 2k and 2k+1).
    nodes : (n_nodes,) the surface's nodes, sorted.
    nodal_area : (n_nodes,) reference tributary area of each of ``nodes`` (a quarter of each adjacent face).
    """

    quads: np.ndarray
    triangles: np.ndarray
    nodes: np.ndarray
    nodal_area: np.ndarray

    @classmethod
    def from_quads(cls, X: np.ndarray, quads: np.ndarray, inside: np.ndarray | None = None) -> ContactSurface:
        """From reference coordinates ``X`` (n, 3) and faces (cyclic unless ``inside``: points behind each face)."""
        X = np.asarray(X, dtype=float)
        quads = np.asarray(quads, dtype=np.int64)
        if quads.ndim != 2 or quads.shape[1] != 4 or quads.shape[0] == 0:
            raise ValueError(f"contact surface: faces must have shape (n > 0, 4); got {quads.shape}")
        if quads.min() < 0 or quads.max() >= X.shape[0]:
            raise ValueError(f"contact surface: face node indices must lie in 0..{X.shape[0] - 1}")
        if inside is not None:
            quads = oriented_quads(X, quads, inside)
        triangles = np.stack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
        Q = X[quads]
        area = 0.5 * np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]), axis=1)
        if not np.all(area > 0.0):
            raise ValueError(f"contact surface: degenerate face(s) {np.flatnonzero(~(area > 0))[:10].tolist()}")
        nodes, inverse = np.unique(quads, return_inverse=True)
        nodal_area = np.bincount(inverse.ravel(), np.repeat(area / 4.0, 4), minlength=nodes.size)
        return cls(quads, triangles, nodes, nodal_area)

    @classmethod
    def from_facets(cls, mesh, facets: np.ndarray) -> ContactSurface:
        """From boundary facets of a scikit-fem hex mesh (oriented away from their element)."""
        facets = np.asarray(facets, dtype=np.int64).ravel()
        owner = mesh.f2t[0, facets]
        inside = mesh.p[:, mesh.t[:, owner]].mean(axis=1).T
        return cls.from_quads(mesh.p.T, mesh.facets[:, facets].T, inside)
