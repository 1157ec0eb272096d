"""Geometry measures of a valve for mathur2022 Tables 2–3: orifice area, leaflet area, leaflet centres.

All measures take plain arrays (node coordinates, face connectivity as node indices, ordered node
loops), so the same calls measure the reference configuration ``X`` and a deformed one ``X + u``.

* **Orifice area**: the annulus is a closed, generally non-planar (saddle-shaped) loop of nodes. Its
  area is that of the polygon projected on the loop's least-squares plane (normal = right singular
  vector of the centred points with the smallest singular value), i.e. ``|n · a|`` with the vector area
  ``a = 1/2 Σ x_i × x_{i+1}`` (Stokes: the flux of ``n`` through any surface spanning the loop).
* **Surface area**: triangles exactly; bilinear quadrilaterals by 3 × 3 Gauss quadrature of
  ``|∂x/∂ξ × ∂x/∂η|`` (exact for plane quads, O(h²) on curved surfaces).
* **Leaflet centre region** (paper Fig. 4d, "leaflet centers", not defined there in numbers): the faces
  nearest — by face-centroid distance — to the leaflet's centre point, added until they cover
  ``fraction`` (default 10 %) of the leaflet's area. The centre point is the face centroid closest to
  the area-weighted mean of the face centroids. Chosen once on the reference configuration, the same
  faces are then followed through the deformation.

Which surface of the 0.78 mm leaflets Table 2 measures is not stated in the paper; :func:`leaflet_surfaces`
gives the ventricular, atrial and mid surfaces of both the brick (1.0) and the shell (1.1) models.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from ..io.abaqus import HEX_FACE_NODES, AbaqusModel

__all__ = [
    "best_fit_plane", "loop_area", "boundary_loops", "face_areas", "surface_area", "offset_points",
    "centre_region", "nearest_loop", "LeafletSurfaces", "ValveAreas", "leaflet_surfaces", "orifice_area",
    "valve_areas", "union_surface", "annulus_nodes", "SURFACES", "LEAFLETS",
]

_GAUSS3 = (np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)]), np.array([5.0, 8.0, 5.0]) / 9.0)


def best_fit_plane(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Centroid and unit normal of the least-squares plane through ``points`` (n, 3), n >= 3."""
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 3:
        raise ValueError(f"need at least 3 points in 3D, got an array of shape {points.shape}")
    centroid = points.mean(axis=0)
    _, singular, vt = np.linalg.svd(points - centroid, full_matrices=False)
    if singular[1] <= 1e-12 * max(singular[0], 1e-300):
        raise ValueError("the points are collinear: no plane")
    return centroid, vt[2]


def loop_area(points: np.ndarray, loop: np.ndarray | None = None) -> float:
    """Area enclosed by a closed node loop, projected on the loop's best-fit plane (orifice area).

    ``loop`` orders node indices into ``points`` (the last node connects back to the first); without it,
    ``points`` themselves are the ordered loop.
    """
    xyz = np.asarray(points, dtype=float)
    if loop is not None:
        xyz = xyz[np.asarray(loop)]
    centroid, normal = best_fit_plane(xyz)
    relative = xyz - centroid
    vector_area = 0.5 * np.cross(relative, np.roll(relative, -1, axis=0)).sum(axis=0)
    return float(abs(vector_area @ normal))


def boundary_loops(faces: np.ndarray) -> list[np.ndarray]:
    """Ordered node loops of the boundary of a surface mesh (edges used by exactly one face), longest first.

    ``faces``: (m, 3) triangles or (m, 4) quads of node indices, consistently or not oriented; a triangle
    written as a quad with a repeated corner (``[a, b, c, c]``) contributes its three edges.
    """
    faces = np.asarray(faces)
    edges = np.stack([faces, np.roll(faces, -1, axis=1)], axis=-1).reshape(-1, 2)
    edges = edges[edges[:, 0] != edges[:, 1]]
    keys, counts = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    neighbours: dict[int, list[int]] = defaultdict(list)
    for a, b in keys[counts == 1].tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    if any(len(n) != 2 for n in neighbours.values()):
        raise ValueError("the surface boundary is not a set of simple loops (a node has != 2 boundary edges)")
    loops, seen = [], set()
    for start in neighbours:
        if start in seen:
            continue
        loop, previous, current = [start], None, start
        seen.add(start)
        while True:
            a, b = neighbours[current]
            following = b if a == previous else a
            if following == start:
                break
            loop.append(following)
            seen.add(following)
            previous, current = current, following
        loops.append(np.array(loop))
    return sorted(loops, key=len, reverse=True)


def nearest_loop(loops: list[np.ndarray], nodes: np.ndarray) -> np.ndarray:
    """The loop sharing most nodes with ``nodes`` (e.g. the annulus among the boundary loops)."""
    shared = [len(np.intersect1d(loop, nodes)) for loop in loops]
    if not shared or max(shared) == 0:
        raise ValueError("no boundary loop contains any of the given nodes")
    return loops[int(np.argmax(shared))]


def _quad_areas(corners: np.ndarray) -> np.ndarray:
    """Areas of bilinear quads with corner coordinates (m, 4, 3), by 3 x 3 Gauss quadrature."""
    points, weights = _GAUSS3
    area = np.zeros(len(corners))
    for xi, wx in zip(points, weights, strict=True):
        for eta, we in zip(points, weights, strict=True):
            d_xi = 0.25 * np.array([-(1 - eta), 1 - eta, 1 + eta, -(1 + eta)])
            d_eta = 0.25 * np.array([-(1 - xi), -(1 + xi), 1 + xi, 1 - xi])
            tangent_xi = np.einsum("a,mak->mk", d_xi, corners)
            tangent_eta = np.einsum("a,mak->mk", d_eta, corners)
            area += wx * we * np.linalg.norm(np.cross(tangent_xi, tangent_eta), axis=1)
    return area


def face_areas(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area of each face: (m, 3) triangles or (m, 4) bilinear quads of node indices into ``points``."""
    corners = np.asarray(points, dtype=float)[np.asarray(faces)]
    if corners.ndim != 3 or corners.shape[1] not in (3, 4) or corners.shape[2] != 3:
        raise ValueError(f"faces must be (m, 3) or (m, 4) node indices, got shape {np.shape(faces)}")
    if corners.shape[1] == 3:
        return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    return _quad_areas(corners)


def surface_area(points: np.ndarray, faces: np.ndarray) -> float:
    """Total area of a triangle or quad surface mesh."""
    return float(face_areas(points, faces).sum())


def _nodal_normals(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    corners = points[faces]
    # face normal from the diagonals (exact for triangles when the last vertex repeats; quads: mean plane)
    if faces.shape[1] == 4:
        normal = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
    else:
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    nodal = np.zeros_like(points)
    for column in range(faces.shape[1]):
        np.add.at(nodal, faces[:, column], normal)
    length = np.linalg.norm(nodal, axis=1, keepdims=True)
    return np.divide(nodal, length, out=np.zeros_like(nodal), where=length > 0)


def offset_points(points: np.ndarray, faces: np.ndarray, distance: float) -> np.ndarray:
    """Nodes moved by ``distance`` along the averaged (area-weighted) nodal normals of a consistently
    oriented surface: the atrial/ventricular surfaces of a shell mid-surface at ``±thickness/2``."""
    points = np.asarray(points, dtype=float)
    return points + distance * _nodal_normals(points, np.asarray(faces))


def centre_region(points: np.ndarray, faces: np.ndarray, fraction: float = 0.1) -> np.ndarray:
    """Indices of the faces forming the centre region of a leaflet surface (definition in the module doc)."""
    if not 0 < fraction <= 1:
        raise ValueError(f"fraction must be in (0, 1], got {fraction}")
    points = np.asarray(points, dtype=float)
    faces = np.asarray(faces)
    areas = face_areas(points, faces)
    centroids = points[faces].mean(axis=1)
    mean = (areas[:, None] * centroids).sum(axis=0) / areas.sum()
    centre = centroids[np.argmin(np.linalg.norm(centroids - mean, axis=1))]
    order = np.argsort(np.linalg.norm(centroids - centre, axis=1), kind="stable")
    covered = np.cumsum(areas[order])
    count = int(np.searchsorted(covered, fraction * areas.sum())) + 1
    return np.sort(order[:count])


# ----------------------------------------------------------------------------------------------------
# The leaflet surfaces of a read Texas TriValve model (node-index faces; coordinates supplied later)

LEAFLETS = ("Anterior", "Posterior", "Septal")
SURFACES = ("ventricular", "mid", "atrial")
_S1, _S2 = list(HEX_FACE_NODES["S1"]), list(HEX_FACE_NODES["S2"])
#: S2 corners of a brick in the corner order of its S1 face (node 0 above node 4, 3 above 7, ...)
_S2_UNDER_S1 = [4, 7, 6, 5]


@dataclass
class LeafletSurfaces:
    """Faces (global node indices) of one leaflet's ventricular, mid and atrial surfaces.

    Bricks (1.0): ventricular = the pressure-loaded S1 faces, atrial = the S2 faces at the top of each
    through-thickness column of bricks, mid = the interface in the middle of the column (``mid_lower``
    and ``mid_upper`` coincide for an even number of layers; for an odd number the mid surface is the
    average of the middle brick's bottom and top faces). Shells (1.1): ``mid`` is the element surface,
    ventricular/atrial are offset by ``±thickness/2`` along the averaged nodal normals (the pressure acts
    on SPOS, the ventricular side); ``elements`` gives the input element index of each mid face, triangles
    (S3) are quads with a repeated last corner (their bilinear area is the triangle's).
    """

    name: str
    mid_lower: np.ndarray
    mid_upper: np.ndarray
    ventricular: np.ndarray | None = None
    atrial: np.ndarray | None = None
    thickness: float | None = None
    elements: np.ndarray | None = None

    def surface(self, which: str, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(points, faces) of surface ``which`` in configuration ``x`` (all node coordinates)."""
        if which not in SURFACES:
            raise ValueError(f"surface must be one of {SURFACES}, got {which!r}")
        if self.thickness is not None:
            if which == "mid":
                return x, self.mid_lower
            sign = 0.5 if which == "ventricular" else -0.5
            return offset_points(x, self.mid_lower, sign * self.thickness), self.mid_lower
        if which == "mid":
            corners = 0.5 * (x[self.mid_lower] + x[self.mid_upper])
            return corners.reshape(-1, 3), np.arange(corners.shape[0] * 4).reshape(-1, 4)
        return x, self.ventricular if which == "ventricular" else self.atrial


def _brick_connectivity(model: AbaqusModel) -> np.ndarray:
    conn = np.full((model.n_elements, 8), -1, dtype=np.int64)
    for block in model.element_blocks:
        if block.connectivity.shape[1] == 8:
            conn[block.offset:block.offset + len(block.labels)] = block.connectivity
    return conn


def _columns(conn: np.ndarray, bottom: np.ndarray) -> list[list[int]]:
    """Through-thickness columns of bricks, each starting at an element of ``bottom`` (S2 on S1)."""
    by_s1 = {tuple(sorted(row)): e for e, row in enumerate(conn[:, _S1].tolist()) if row[0] >= 0}
    columns = []
    for element in bottom.tolist():
        column = [element]
        while len(column) <= len(conn):
            above = by_s1.get(tuple(sorted(conn[column[-1], _S2].tolist())))
            if above is None:
                break
            column.append(above)
        columns.append(column)
    return columns


def _leaflet_elements(model: AbaqusModel, leaflet: str) -> np.ndarray:
    suffix = f"{leaflet}_LEAFLET_ELEMENTS".upper()
    hits = [s for key, s in model.element_sets.items()
            if key.split(".")[-1] == suffix]
    if len(hits) != 1:
        raise ValueError(f"{model.path}: expected one element set *{leaflet}_Leaflet_Elements, found {len(hits)}")
    return hits[0].indices


def _shell_faces(model: AbaqusModel, elements: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quads (triangles with the last corner repeated) of the shell ``elements`` and their element indices."""
    faces, owners = [], []
    for block in model.element_blocks:
        chosen = np.isin(block.indices, elements)
        if not chosen.any():
            continue
        if block.connectivity.shape[1] not in (3, 4):
            raise ValueError(f"{model.path}: shell elements of type {block.element_type} (not S3/S4) in a leaflet")
        connectivity = block.connectivity[chosen]
        faces.append(connectivity if connectivity.shape[1] == 4 else connectivity[:, [0, 1, 2, 2]])
        owners.append(np.asarray(block.indices)[chosen])
    return np.concatenate(faces), np.concatenate(owners)


def leaflet_surfaces(model: AbaqusModel) -> dict[str, LeafletSurfaces]:
    """Ventricular, mid and atrial faces of each leaflet of a Texas TriValve model (bricks or shells)."""
    pressured = {int(e) for step in model.steps for load in step.distributed_loads
                 for group in model.surface(load.surface).faces for e in group.elements}
    conn = _brick_connectivity(model)
    result = {}
    for leaflet in LEAFLETS:
        elements = _leaflet_elements(model, leaflet)
        sections = [s for s in model.sections if s.kind == "shell" and np.isin(elements, s.elements).all()]
        if sections:
            faces, owners = _shell_faces(model, elements)
            result[leaflet] = LeafletSurfaces(leaflet, faces, faces, thickness=sections[0].thickness, elements=owners)
            continue
        bottom = np.array(sorted(pressured.intersection(elements.tolist())), dtype=np.int64)
        if len(bottom) == 0 or np.any(conn[bottom, 0] < 0):
            raise ValueError(f"{model.path}: leaflet {leaflet} has no pressure-loaded brick faces")
        columns = _columns(conn, bottom)
        layers = {len(c) for c in columns}
        if len(layers) != 1:
            raise ValueError(f"{model.path}: leaflet {leaflet} has columns of {sorted(layers)} bricks")
        n = layers.pop()
        top = np.array([c[-1] for c in columns])
        if n % 2 == 0:
            below = np.array([c[n // 2 - 1] for c in columns])
            lower = upper = conn[below][:, _S2_UNDER_S1]
        else:
            middle = np.array([c[n // 2] for c in columns])
            lower, upper = conn[middle][:, _S1], conn[middle][:, _S2_UNDER_S1]
        result[leaflet] = LeafletSurfaces(leaflet, lower, upper, conn[bottom][:, _S1], conn[top][:, _S2])
    return result


def orifice_area(points: np.ndarray, faces: np.ndarray, annulus_points: np.ndarray) -> float:
    """Orifice area of a valve surface: :func:`loop_area` of the boundary loop that lies closest (mean
    distance of its nodes to the nearest of ``annulus_points``) to the annulus.

    The annulus must be named: in the open reference configuration the scalloped free edge, projected on
    its own best-fit plane, can enclose more area than the annulus (it does in the 1.0 diseased input).
    """
    annulus_points = np.asarray(annulus_points, dtype=float)
    loops = boundary_loops(faces)

    def distance(loop: np.ndarray) -> float:
        gaps = np.linalg.norm(points[loop][:, None, :] - annulus_points[None, :, :], axis=2)
        return float(gaps.min(axis=1).mean())

    return loop_area(points, min(loops, key=distance))


def annulus_nodes(model: AbaqusModel) -> np.ndarray:
    """Nodes of the model's annulus node set(s): the sets whose name contains ``ANNUL``."""
    sets = [s.indices for key, s in model.node_sets.items() if "ANNUL" in key.split(".")[-1]]
    if not sets:
        raise ValueError(f"{model.path}: no annulus node set (a set named *Annul*)")
    return np.unique(np.concatenate(sets))


@dataclass
class ValveAreas:
    """Orifice area and leaflet areas (mm² for the TriValve units) per surface, and the centre regions."""

    orifice: dict[str, float]
    leaflet: dict[str, dict[str, float]]
    centre_faces: dict[str, np.ndarray]
    centre_area: dict[str, float]

    def total(self, surface: str) -> float:
        return sum(areas[surface] for areas in self.leaflet.values())


def union_surface(surfaces: dict[str, LeafletSurfaces], which: str, x: np.ndarray
                  ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """One surface of all leaflets together: points and each leaflet's faces into them.

    Shell offsets use nodal normals averaged over all leaflets (so leaflets stay joined at the
    commissures); brick mid-surface corners that coincide are merged into one point.
    """
    if which not in SURFACES:
        raise ValueError(f"surface must be one of {SURFACES}, got {which!r}")
    names = list(surfaces)
    shells = [surfaces[n].thickness is not None for n in names]
    if all(shells):
        faces = {n: surfaces[n].mid_lower for n in names}
        if which == "mid":
            return x, faces
        thickness = surfaces[names[0]].thickness
        if any(surfaces[n].thickness != thickness for n in names):
            raise ValueError("leaflet shells of different thicknesses: offset each with LeafletSurfaces.surface")
        sign = 0.5 if which == "ventricular" else -0.5
        return offset_points(x, np.concatenate(list(faces.values())), sign * thickness), faces
    if any(shells):
        raise ValueError("a model mixing shell and brick leaflets is not supported")
    if which != "mid":
        return x, {n: surfaces[n].ventricular if which == "ventricular" else surfaces[n].atrial for n in names}
    pieces = [surfaces[n].surface("mid", x) for n in names]
    offsets = np.cumsum([0] + [len(points) for points, _ in pieces])
    merged, faces = _merge_coincident(np.concatenate([p for p, _ in pieces]),
                                      np.concatenate([f + o for (_, f), o in zip(pieces, offsets, strict=False)]))
    counts = np.cumsum([0] + [len(f) for _, f in pieces])
    return merged, {n: faces[counts[i]:counts[i + 1]] for i, n in enumerate(names)}


def valve_areas(surfaces: dict[str, LeafletSurfaces], x: np.ndarray, annulus: np.ndarray,
                centre_fraction: float = 0.1, centre_faces: dict[str, np.ndarray] | None = None) -> ValveAreas:
    """Orifice, leaflet and centre-region (mid-surface) areas of all surfaces in configuration ``x``.

    ``annulus``: node indices on (or next to) the annulus, e.g. :func:`annulus_nodes`; each surface's
    orifice is enclosed by its boundary loop nearest to them.
    ``centre_faces`` (mid-surface face indices per leaflet) re-uses regions chosen on another
    configuration, normally the reference one; by default they are chosen on ``x``.
    """
    orifice: dict[str, float] = {}
    leaflet: dict[str, dict[str, float]] = {name: {} for name in surfaces}
    centres, centre_area = {}, {}
    for which in SURFACES:
        points, faces = union_surface(surfaces, which, x)
        orifice[which] = orifice_area(points, np.concatenate(list(faces.values())), x[annulus])
        for name, leaflet_faces in faces.items():
            areas = face_areas(points, leaflet_faces)
            leaflet[name][which] = float(areas.sum())
            if which == "mid":
                chosen = centre_region(points, leaflet_faces, centre_fraction) if centre_faces is None \
                    else centre_faces[name]
                centres[name] = chosen
                centre_area[name] = float(areas[chosen].sum())
    return ValveAreas(orifice, leaflet, centres, centre_area)


def _merge_coincident(points: np.ndarray, faces: np.ndarray, decimals: int = 9) -> tuple[np.ndarray, np.ndarray]:
    """Join points that coincide (to ``decimals``) so that faces built from separate corners connect."""
    scale = max(float(np.abs(points).max()), 1.0)
    keys = np.round(points / scale, decimals)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    merged = np.zeros((len(unique), 3))
    merged[inverse.ravel()] = points
    return merged, inverse.ravel()[faces]
