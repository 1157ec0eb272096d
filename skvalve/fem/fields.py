r"""Fields of a solution at arbitrary points or element centres.

A point :math:`x` is located in its element (``mesh.element_finder``) and mapped to local
coordinates :math:`\xi`; there the basis gives :math:`u = \sum_a N_a(\xi) u_a` and
:math:`F = I + \sum_a u_a \otimes \nabla_0 N_a(\xi)`. Derived tensors:
Green strain :math:`E = \tfrac12(F^TF - I)`, right stretch :math:`U = \sqrt{F^TF}`,
Cauchy stress :math:`\sigma = J^{-1} P F^T` with, for the mixed formulation,
:math:`P = \hat P - p\operatorname{cof}F` and :math:`p` interpolated at the point.
Tensors are returned as (3, 3, n) arrays (plane strain: :math:`F_{33} = 1`).
"""

from __future__ import annotations

import numpy as np

from ..kinematics import green_lagrange, polar_decomposition
from ..materials.base import Hyperelastic
from .loads import embed_3d

__all__ = ["PointData", "locate", "element_centres"]


class PointData:
    """Basis values and reference gradients at a set of points, each in one element."""

    def __init__(self, solid, elements: np.ndarray, local: np.ndarray) -> None:
        space = solid.space
        self.solid, self.elements = solid, elements
        mapping = space.basis_u.mapping
        fields = [space.element_u.gbasis(mapping, local, a, tind=elements)[0] for a in range(space.nb_u)]
        self.N = np.stack([np.asarray(f)[:, 0] for f in fields], axis=1)  # (npts, nb)
        self.dN = np.stack([f.grad[:, :, 0] for f in fields], axis=1).transpose(2, 1, 0)  # (npts, nb, d)
        self.dN = np.ascontiguousarray(self.dN)
        if space.basis_p is not None:
            pfields = [space.element_p.gbasis(mapping, local, a, tind=elements)[0] for a in range(space.nb_p)]
            self.Np = np.stack([np.asarray(f)[:, 0] for f in pfields], axis=1)
        else:
            self.Np = None

    def _u_elem(self, u: np.ndarray) -> np.ndarray:
        space = self.solid.space
        d, nb = space.dim, space.nb_u
        return u[space.element_dofs[self.elements, : nb * d]].reshape(-1, nb, d)

    def displacement(self, u: np.ndarray) -> np.ndarray:
        """Displacement (dim, npts)."""
        return np.einsum("na,nai->in", self.N, self._u_elem(u))

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F (3, 3, npts)."""
        return embed_3d(np.einsum("naj,nai->ijn", self.dN, self._u_elem(u)))

    def pressure(self, u: np.ndarray) -> np.ndarray | None:
        """Mixed-formulation pressure (npts,) (positive in compression), None for ``"u"``."""
        if self.Np is None:
            return None
        space = self.solid.space
        return np.einsum("na,na->n", self.Np, u[space.element_dofs[self.elements, space.nb_u * space.dim:]])

    def cauchy(self, u: np.ndarray) -> np.ndarray:
        """Cauchy stress (3, 3, npts), including the mixed pressure."""
        F = self.deformation_gradient(u)
        J = np.linalg.det(F.transpose(2, 0, 1))
        if np.any(J <= 0):
            raise ValueError("det F <= 0 at an evaluation point")
        p = self.pressure(u)
        sigma = np.empty_like(F)
        nel = self.solid.space.nel
        centres = self.elements.size == nel and np.array_equal(self.elements, np.arange(nel))
        for region in self.solid.materials.regions:
            # batch (1, n): at element centres n runs over the region's elements in their own order,
            # so per-element material data of shape (3, n_region_elements) broadcasts
            if isinstance(region.elements, slice):
                idx = np.arange(self.elements.size)
            elif centres:
                idx = np.asarray(region.elements)
            else:
                idx = np.flatnonzero(np.isin(self.elements, region.elements))
            if idx.size == 0:
                continue
            if not isinstance(region.law, Hyperelastic):
                raise ValueError(
                    f"{type(region.law).__name__} is a quadrature-point material: its stress exists only at the "
                    "Gauss points it was built for, not at arbitrary points; use its own field output "
                    "(e.g. skvalve.multiscale)"
                )
            sig = region.law.cauchy(F[:, :, idx][:, :, None, :])[:, :, 0, :]
            if p is not None:
                sig = sig - p[idx] * np.eye(3)[:, :, None]
            sigma[:, :, idx] = sig
        return sigma

    def green_strain(self, u: np.ndarray) -> np.ndarray:
        return green_lagrange(self.deformation_gradient(u))

    def stretch_tensor(self, u: np.ndarray) -> np.ndarray:
        """Right stretch tensor U of F = R U, (3, 3, npts)."""
        return polar_decomposition(self.deformation_gradient(u))[1]


def locate(solid, points: np.ndarray) -> PointData:
    """Basis data at reference-configuration points of shape (dim, npts); ``ValueError`` if outside."""
    points = np.asarray(points, dtype=float)
    space = solid.space
    if points.ndim == 1:
        points = points[:, None]
    if points.shape[0] != space.dim:
        raise ValueError(f"points must have shape ({space.dim}, n); got {points.shape}")
    mapping = space.basis_u.mapping
    try:
        elements = np.asarray(solid.mesh.element_finder(mapping=mapping)(*points))
    except NotImplementedError:
        elements = _search_elements(solid, points)
    except ValueError as err:
        raise ValueError(f"a point lies outside the mesh: {err}") from err
    if np.any(elements < 0):
        raise ValueError("a point lies outside the mesh")
    local = mapping.invF(points[:, :, None], tind=elements)
    return PointData(solid, elements, local)


def _inside_reference(space, local: np.ndarray, tol: float = 1e-8) -> bool:
    if space.family in ("hex", "quad"):
        return bool(np.all((local >= -tol) & (local <= 1 + tol)))
    return bool(np.all(local >= -tol) and local.sum() <= 1 + tol)


def _search_elements(solid, points: np.ndarray, candidates: int = 12) -> np.ndarray:
    """Brute-force location for meshes without ``element_finder`` (e.g. quadratic geometry)."""
    space = solid.space
    mapping = space.basis_u.mapping
    centroids = solid.mesh.p[:, solid.mesh.t].mean(axis=1)  # (dim, nel)
    found = np.full(points.shape[1], -1)
    for n in range(points.shape[1]):
        order = np.argsort(np.sum((centroids - points[:, n:n + 1]) ** 2, axis=0))[:candidates]
        for e in order:
            try:
                local = mapping.invF(points[:, n:n + 1, None], tind=np.array([e]))
            except Exception:  # noqa: BLE001 - scikit-fem raises a bare Exception when Newton fails
                continue
            if _inside_reference(space, local):
                found[n] = e
                break
    return found


def element_centres(solid) -> PointData:
    """Basis data at the reference centre of every element."""
    space = solid.space
    centre = space.element_u.refdom.p.mean(axis=1)
    local = np.broadcast_to(centre[:, None, None], (space.dim, space.nel, 1)).copy()
    return PointData(solid, np.arange(space.nel), local)
