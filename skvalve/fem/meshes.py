"""Small structured meshes for tests, examples and benchmarks (scikit-fem meshes with named boundaries).

Boundary names follow scikit-fem's ``with_defaults``: ``left``/``right`` (x = min/max),
``bottom``/``top`` (y), ``front``/``back`` (z).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import skfem as fem

__all__ = ["box", "rectangle", "annulus_sector", "spherical_shell_octant", "distort"]


def _named(mesh: fem.Mesh, lengths) -> fem.Mesh:
    names = (("left", "right"), ("bottom", "top"), ("front", "back"))
    tol = 1e-9 * max(lengths)
    boundaries = {}
    for axis in range(mesh.dim()):
        lo, hi = names[axis]
        boundaries[lo] = mesh.facets_satisfying(lambda x, a=axis: np.abs(x[a]) < tol, boundaries_only=True)
        boundaries[hi] = mesh.facets_satisfying(
            lambda x, a=axis: np.abs(x[a] - lengths[a]) < tol, boundaries_only=True)
    return mesh.with_boundaries(boundaries)


def box(n, lengths=(1.0, 1.0, 1.0), kind: str = "hex") -> fem.Mesh:
    """[0, Lx] x [0, Ly] x [0, Lz] with ``n = (nx, ny, nz)`` cells (int: same in all); hex or tet."""
    n = (n,) * 3 if np.isscalar(n) else tuple(n)
    axes = [np.linspace(0.0, L, k + 1) for L, k in zip(lengths, n, strict=True)]
    mesh = fem.MeshHex.init_tensor(*axes)
    if kind == "tet":
        mesh = fem.MeshTet.init_tensor(*axes)
    elif kind != "hex":
        raise ValueError(f"kind must be 'hex' or 'tet'; got {kind!r}")
    return _named(mesh, lengths)


def rectangle(n, lengths=(1.0, 1.0), kind: str = "quad") -> fem.Mesh:
    """[0, Lx] x [0, Ly] with ``n = (nx, ny)`` cells; quads or triangles."""
    n = (n,) * 2 if np.isscalar(n) else tuple(n)
    axes = [np.linspace(0.0, L, k + 1) for L, k in zip(lengths, n, strict=True)]
    if kind == "quad":
        mesh = fem.MeshQuad.init_tensor(*axes)
    elif kind == "tri":
        mesh = fem.MeshTri.init_tensor(*axes)
    else:
        raise ValueError(f"kind must be 'quad' or 'tri'; got {kind!r}")
    return _named(mesh, lengths)


def annulus_sector(inner: float, outer: float, n_radial: int, n_angular: int,
                   angle: float = np.pi / 2) -> fem.MeshQuad2:
    """Quadratic (curved) quad mesh of ``inner <= r <= outer``, ``0 <= theta <= angle``; boundaries ``inner``,
    ``outer``, ``theta0`` (on the x axis) and ``theta1``. Radial spacing is geometric."""
    if not 0 < inner < outer:
        raise ValueError("need 0 < inner < outer")
    r = inner * (outer / inner) ** np.linspace(0.0, 1.0, n_radial + 1)
    theta = np.linspace(0.0, angle, n_angular + 1)
    base = fem.MeshQuad.init_tensor(r, theta).with_defaults()
    quadratic = fem.MeshQuad2.from_mesh(base)
    R, T = quadratic.doflocs
    # isoparametric: the mid-side nodes lie on the circles too, so the geometry is exact to O(h^3)
    mesh = dataclasses.replace(quadratic, doflocs=np.vstack([R * np.cos(T), R * np.sin(T)]))
    # same connectivity, so the facets of the (r, theta) rectangle keep their indices
    b = base.boundaries
    return mesh.with_boundaries({"inner": b["left"], "outer": b["right"], "theta0": b["bottom"], "theta1": b["top"]})


def spherical_shell_octant(inner: float, outer: float, n_tangential: int, n_radial: int) -> fem.MeshHex2:
    """Curved (quadratic) hexahedral mesh of ``inner <= |x| <= outer``, ``x, y, z >= 0``.

    Three cube-sphere patches (the faces x = 1, y = 1, z = 1 of the unit cube projected radially)
    with ``n_tangential**2`` cells each and ``n_radial`` layers. Every node of a Q2 cell is placed
    at the mean radius of the cell entity it belongs to, along the direction of its centroid, so
    the inner and outer surfaces are exact spheres at all nodes. Boundaries: ``inner``, ``outer``,
    ``x0``, ``y0``, ``z0`` (the symmetry planes).
    """
    if not 0 < inner < outer:
        raise ValueError("need 0 < inner < outer")
    u = np.linspace(0.0, 1.0, n_tangential + 1)
    radial = np.linspace(0.0, 1.0, n_radial + 1)
    points, cells, offset = [], [], 0
    for axis in range(3):
        unit = fem.MeshHex.init_tensor(radial, u, u)
        s_, a_, b_ = unit.p
        direction = np.empty((3, s_.size))
        others = [(axis + 1) % 3, (axis + 2) % 3]  # cyclic: positively oriented cells
        direction[axis], direction[others[0]], direction[others[1]] = 1.0, a_, b_
        direction /= np.linalg.norm(direction, axis=0)
        points.append((inner + (outer - inner) * s_) * direction)
        cells.append(unit.t + offset)
        offset += s_.size
    p = np.hstack(points)
    t = np.hstack(cells)
    key = np.round(p / outer, 10)
    _, first, inverse = np.unique(key.T, axis=0, return_index=True, return_inverse=True)
    linear = fem.MeshHex(p[:, first], inverse.ravel()[t])
    quadratic = fem.MeshHex2.from_mesh(linear)
    nv, ne, nf = linear.nvertices, linear.edges.shape[1], linear.facets.shape[1]
    groups = [linear.edges, linear.facets, linear.t]
    vertex_radius = np.linalg.norm(linear.p, axis=0)
    doflocs, centroids = [linear.p], [linear.p]
    for group in groups:
        centroid = linear.p[:, group].mean(axis=1)
        radius = vertex_radius[group].mean(axis=0)
        centroids.append(centroid)
        doflocs.append(centroid / np.linalg.norm(centroid, axis=0) * radius)
    doflocs = np.hstack(doflocs)
    # MeshHex2 numbers its nodes: vertices, edges, facets, cells (checked, not assumed)
    if nv + ne + nf + linear.nelements != quadratic.doflocs.shape[1] or not np.allclose(
            np.hstack(centroids), quadratic.doflocs):
        raise RuntimeError("unexpected node layout of MeshHex2")
    mesh = dataclasses.replace(quadratic, doflocs=doflocs)
    tol = 1e-8 * outer

    def on_radius(r):
        return np.flatnonzero(np.all(np.abs(vertex_radius[linear.facets] - r) < tol, axis=0))

    bnd = linear.boundary_facets()
    boundaries = {"inner": np.intersect1d(on_radius(inner), bnd), "outer": np.intersect1d(on_radius(outer), bnd)}
    for k, name in enumerate(("x0", "y0", "z0")):
        boundaries[name] = np.intersect1d(np.flatnonzero(np.all(np.abs(linear.p[k, linear.facets]) < tol, axis=0)), bnd)
    return mesh.with_boundaries(boundaries)


def distort(mesh: fem.Mesh, amount: float = 0.2, seed: int = 0) -> fem.Mesh:
    """Move vertices randomly by up to ``amount`` x the smallest cell size along each axis,
    keeping every coordinate that lies on the bounding box (faces stay planar)."""
    rng = np.random.default_rng(seed)
    p = mesh.p.copy()
    lo, hi = p.min(axis=1, keepdims=True), p.max(axis=1, keepdims=True)
    h = min(np.min(np.diff(np.unique(np.round(c, 12)))) for c in p)
    on_box = np.isclose(p, lo) | np.isclose(p, hi)
    p = np.where(on_box, p, p + amount * h * rng.uniform(-1.0, 1.0, p.shape))
    return type(mesh)(p, mesh.t, _boundaries=mesh.boundaries, _subdomains=mesh.subdomains)
