r"""Discrete spaces: scikit-fem bases for displacement (and pressure) plus the dof layout.

Displacement components are interleaved per scalar dof, ``dof = d * s + i`` for scalar dof
``s`` of the displacement basis and component ``i`` (``d`` the mesh dimension); pressure
dofs of a mixed element follow after all displacement dofs. Element dof arrays are
node-major, ``[u_0x, u_0y, (u_0z), u_1x, ..., p_0, p_1, ...]``, matching
:mod:`skvalve.fem.kernels`. Shape-function gradients :math:`\partial N_a/\partial X_J`,
values and the integration weights ``dx`` are evaluated once and stored contiguously.

Element families (quadrature: Gauss rules exact for the degree of the integrand of a
linear problem on affine cells):

==========  ===========================  ===========================
mesh        ``"u"`` order 1 / 2           ``"up"`` (order 2 only)
==========  ===========================  ===========================
hexahedra   Q1 (2³ pts) / Q2 (3³ pts)    Q2/Q1 (3³ points)
tetrahedra  P1 (1 pt) / P2 (4 pts)       P2/P1 (4 points)
quads (2D)  Q1 (2² pts) / Q2 (3² pts)    Q2/Q1 (3² points)
triangles   P1 (1 pt) / P2 (3 pts)       P2/P1 (3 points)
==========  ===========================  ===========================

Two-dimensional meshes are plane strain (:math:`F_{33} = 1`), quantities per unit width.
"""

from __future__ import annotations

import numpy as np
import skfem as fem

from .errors import TangledMeshError

__all__ = ["Space", "element_family", "node_dofs"]

_FAMILIES = {
    "hex": (fem.ElementHex1, fem.ElementHex2, (3, 5)),
    "tet": (fem.ElementTetP1, fem.ElementTetP2, (1, 2)),
    "quad": (fem.ElementQuad1, fem.ElementQuad2, (3, 5)),
    "tri": (fem.ElementTriP1, fem.ElementTriP2, (1, 2)),
}


def node_dofs(nodes: np.ndarray, dim: int = 3) -> np.ndarray:
    """The displacement dofs of ``nodes`` (node-major, ``dim`` per node), in the nodes' order."""
    return (dim * np.asarray(nodes, dtype=np.int64)[:, None] + np.arange(dim)).ravel()


def element_family(mesh: fem.Mesh) -> str:
    """``"hex"``, ``"tet"``, ``"quad"`` or ``"tri"`` for a scikit-fem mesh, else ``ValueError``."""
    for name, cls in (("hex", fem.MeshHex1), ("tet", fem.MeshTet1), ("quad", fem.MeshQuad1), ("tri", fem.MeshTri1)):
        if isinstance(mesh, cls):
            return name
    raise ValueError(f"unsupported mesh type {type(mesh).__name__}: use a hex, tet, quad or triangle mesh")


class Space:
    """Bases, precomputed gradients and dof layout of a ``"u"`` or ``"up"`` discretisation."""

    def __init__(self, mesh: fem.Mesh, formulation: str = "u", order: int | None = None,
                 intorder: int | None = None) -> None:
        if formulation not in ("u", "up"):
            raise ValueError(f"formulation must be 'u' or 'up'; got {formulation!r}")
        if order is None:
            order = 2 if formulation == "up" else 1
        if order not in (1, 2):
            raise ValueError(f"order must be 1 or 2; got {order!r}")
        if formulation == "up" and order != 2:
            raise ValueError("the mixed 'up' formulation uses quadratic displacement (order=2) and linear pressure")
        self.mesh = mesh
        self.family = element_family(mesh)
        self.dim = mesh.dim()
        self.formulation = formulation
        self.order = order
        linear, quadratic, orders = _FAMILIES[self.family]
        self.intorder = orders[order - 1] if intorder is None else int(intorder)
        self.element_u = quadratic() if order == 2 else linear()
        self.basis_u = fem.CellBasis(mesh, self.element_u, intorder=self.intorder)
        check_reference_jacobian(mesh, self.basis_u)
        self.basis_p = None
        if formulation == "up":
            self.element_p = linear()
            self.basis_p = fem.CellBasis(mesh, self.element_p, quadrature=self.basis_u.quadrature)
        self.nel = mesh.nelements
        self.n_scalar = self.basis_u.N
        self.n_u = self.dim * self.n_scalar
        self.n_p = 0 if self.basis_p is None else self.basis_p.N
        self.n_dofs = self.n_u + self.n_p
        self.nb_u = self.basis_u.Nbfun
        self.nb_p = 0 if self.basis_p is None else self.basis_p.Nbfun

        # dN[e, q, a, J] and dx[e, q], contiguous for the kernels
        grads = np.stack([self.basis_u.basis[a][0].grad for a in range(self.nb_u)])  # (nb, d, nel, nqp)
        self.dN = np.ascontiguousarray(grads.transpose(2, 3, 0, 1))
        self.dx = np.ascontiguousarray(self.basis_u.dx)
        self.nqp = self.dx.shape[1]
        if self.basis_p is not None:
            values = np.stack([np.asarray(self.basis_p.basis[a][0]) for a in range(self.nb_p)])  # (nbp, nel, nqp)
            self.Np = np.ascontiguousarray(values.transpose(1, 2, 0))
        else:
            self.Np = np.zeros((self.nel, self.nqp, 0))

        scalar = self.basis_u.element_dofs.T  # (nel, nb)
        udofs = (self.dim * scalar[:, :, None] + np.arange(self.dim)).reshape(self.nel, -1)
        if self.basis_p is not None:
            pdofs = self.n_u + self.basis_p.element_dofs.T
            self.element_dofs = np.ascontiguousarray(np.hstack([udofs, pdofs]))
        else:
            self.element_dofs = np.ascontiguousarray(udofs)
        self.ndofe = self.element_dofs.shape[1]

    # -------------------------------------------------------------- dof helpers
    @property
    def dof_coordinates(self) -> np.ndarray:
        """Reference coordinates of the scalar displacement dofs, shape (dim, n_scalar).

        The first ``mesh.nvertices`` dofs are the vertices (Lagrange elements); their coordinates
        come from the mesh, so vertices used by no cell (e.g. nodes of trusses only) are placed right.
        """
        coordinates = np.array(self.basis_u.doflocs, dtype=float)
        nv = self.mesh.nvertices
        coordinates[:, :nv] = self.mesh.p[:, :nv]
        return coordinates

    def displacement_dofs(self, scalar_dofs: np.ndarray, components=None) -> np.ndarray:
        """Global dof numbers of the given scalar dofs and components, shape (ncomp, n)."""
        comps = range(self.dim) if components is None else components
        comps = np.atleast_1d(np.asarray(comps, dtype=int))
        if np.any((comps < 0) | (comps >= self.dim)):
            raise ValueError(f"displacement components must lie in 0..{self.dim - 1}; got {comps.tolist()}")
        return self.dim * np.asarray(scalar_dofs, dtype=int)[None, :] + comps[:, None]

    def scalar_dofs_on(self, where) -> np.ndarray:
        """Scalar displacement dofs selected by a boundary name, facet indices or ``X -> bool``."""
        mesh = self.mesh
        if isinstance(where, str):
            if mesh.boundaries is None or where not in mesh.boundaries:
                names = [] if mesh.boundaries is None else sorted(mesh.boundaries)
                raise ValueError(f"unknown boundary {where!r}; mesh has {names}")
            where = mesh.boundaries[where]
        if callable(where):
            mask = np.asarray(where(self.dof_coordinates), dtype=bool)
            if mask.shape != (self.n_scalar,):
                raise ValueError("a dof selector X -> bool must return one boolean per dof location")
            return np.flatnonzero(mask)
        facets = np.asarray(where, dtype=int).ravel()
        if facets.size and (facets.min() < 0 or facets.max() >= mesh.nfacets):
            raise ValueError(f"facet indices must lie in 0..{mesh.nfacets - 1}")
        return np.unique(self.basis_u.get_dofs(facets).all())

    def facets_of(self, where) -> np.ndarray:
        """Facet indices from a boundary name, an index array or a predicate on facet midpoints."""
        mesh = self.mesh
        if isinstance(where, str):
            if mesh.boundaries is None or where not in mesh.boundaries:
                raise ValueError(f"unknown boundary {where!r}")
            return np.asarray(mesh.boundaries[where])
        if callable(where):
            return mesh.facets_satisfying(where, boundaries_only=True)
        facets = np.asarray(where, dtype=int).ravel()
        if facets.size and (facets.min() < 0 or facets.max() >= mesh.nfacets):
            raise ValueError(f"facet indices must lie in 0..{mesh.nfacets - 1}")
        return facets


def check_reference_jacobian(mesh: fem.Mesh, basis: fem.CellBasis) -> None:
    r"""Raise :class:`TangledMeshError` unless det(dX/dxi) has one sign over the mesh.

    scikit-fem integrates with :math:`|\det J|`, so an element with a scrambled node order or a
    node pushed past its neighbours would otherwise run and give wrong results silently. The sign
    is checked at the quadrature points and at the reference element's corners; a mesh whose
    elements are all negatively oriented is consistent and accepted. Simplices (affine maps) may be
    oriented either way element by element (scikit-fem does not order their nodes); only degenerate
    ones are rejected.
    """
    mapping = basis.mapping
    corners = basis.elem.refdom.p
    points = np.hstack([basis.quadrature[0], corners])
    det = mapping.detDF(points)  # (nel, npoints)
    det = np.broadcast_to(det, (mesh.nelements, points.shape[1])) if np.ndim(det) == 2 else \
        np.broadcast_to(np.asarray(det).reshape(-1, 1), (mesh.nelements, points.shape[1]))
    scale = np.abs(det).max()
    if not np.all(np.isfinite(det)) or scale == 0:
        raise TangledMeshError(np.flatnonzero(~np.isfinite(det).all(axis=1)), " (degenerate or non-finite)")
    if isinstance(mesh, fem.MeshTet1 | fem.MeshTri1):
        bad = np.flatnonzero(~(np.abs(det) > 1e-12 * scale).all(axis=1))
        if bad.size:
            raise TangledMeshError(bad, " (degenerate simplices)")
        return
    positive = (det > 1e-12 * scale).sum()
    sign = 1.0 if positive >= det.size / 2 else -1.0
    bad = np.flatnonzero(~(sign * det > 1e-12 * scale).all(axis=1))
    if bad.size:
        raise TangledMeshError(bad)
