r"""Loads and constraints: prescribed displacements, follower pressure, nodal forces.

**Follower pressure.** A pressure :math:`p` acting on the deformed surface does the virtual
work :math:`-\int_\gamma p\,n\cdot\delta u\,da`. By Nanson's formula
:math:`n\,da = \operatorname{cof}F\,N\,dA` it is an integral over the reference facets,
and its contribution to the residual (internal minus external forces) and its
linearisation are

.. math::

    R_{ai} \mathrel{+}= \int_{\Gamma_0} p\,N_a\,(\operatorname{cof}F)_{iJ} N_J\,dA, \qquad
    K_{ai,bk} \mathrel{+}= \int_{\Gamma_0} p\,N_a\,\varepsilon_{ikm}\varepsilon_{JLM}F_{mM}N_J\,
    \frac{\partial N_b}{\partial X_L}\,dA,

from :math:`\partial(\operatorname{cof}F)_{iJ}/\partial F_{kL} = \varepsilon_{ikm}\varepsilon_{JLM}F_{mM}`
(polynomial, no division by :math:`J`). The load stiffness is not symmetric in general
(it is for closed surfaces and pressure fixed). Plane strain uses the same formula with
:math:`F_{33} = 1` and :math:`N_3 = 0`. Only tangential derivatives enter
:math:`\operatorname{cof}F\,N`, so the cell gradients evaluated on the facet are exact.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import skfem as fem

from ..materials.base import check_array
from .errors import LoadError
from .kernels import element_gradients
from .space import Space
from .terms import Blocks, Contribution, Term

__all__ = ["Dirichlet", "FollowerPressure", "NodalForce", "load_function", "evaluated_load", "embed_3d"]

_LEVI_CIVITA = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_i, _j, _k], _LEVI_CIVITA[_i, _k, _j] = 1.0, -1.0


def load_function(value, ramp: bool = True, name: str = "load") -> Callable[[float], np.ndarray]:
    """``t -> value * t`` (ramped), ``t -> value`` (fixed) or the callable itself.

    A value that is not a number or an array of numbers is a ``TypeError`` naming ``name`` (its values are checked
    when the callable is evaluated, :func:`evaluated_load`); a non-finite value is a ``ValueError``.
    """
    if callable(value):
        return value
    array = check_array(name, value, finite=False)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite; got {value!r}")
    return (lambda t: array * t) if ramp else (lambda t: array)


def evaluated_load(value, term: str, load, t: float, shape: tuple[int, ...] | None = None,
                   where: str = "") -> np.ndarray:
    """``value``, what ``load`` gave at load factor ``t``, as a finite float array (reshaped to ``shape``).

    Raises :class:`~skvalve.fem.errors.LoadError` naming the load, its ``term`` (and ``where`` it acts) and ``t``
    for anything that is not finite numbers of that shape: the solvers then stop at once instead of cutting the
    step back on a NaN residual.
    """
    try:
        array = check_array(term, value, finite=False)
    except (TypeError, ValueError):
        raise LoadError(term, load, t, f"returned {value!r}, not numbers", where) from None
    if shape is not None:
        try:
            array = array.reshape(shape)
        except ValueError:
            raise LoadError(term, load, t, f"returned an array of shape {array.shape}, expected "
                            f"{'one number' if shape == () else shape}", where) from None
    if not np.all(np.isfinite(array)):
        bad = np.flatnonzero(~np.isfinite(array.ravel()))
        raise LoadError(term, load, t, f"returned non-finite values ({array.ravel()[bad[0]]} at entry "
                        f"{int(bad[0])}, {bad.size} of {array.size} entries)", where)
    return array


def embed_3d(H: np.ndarray) -> np.ndarray:
    """Deformation gradient (3, 3, ...) from a displacement gradient (d, d, ...), F33 = 1 in 2D."""
    dim = H.shape[0]
    F = np.zeros((3, 3) + H.shape[2:])
    F[:dim, :dim] = H
    for i in range(3):
        F[i, i] += 1.0
    return F


class Dirichlet:
    """Prescribed displacement components on a set of scalar dofs (nodes)."""

    def __init__(self, space: Space, scalar_dofs: np.ndarray, components, value, ramp: bool) -> None:
        self.components = np.atleast_1d(np.arange(space.dim) if components is None else np.asarray(components))
        self.dofs = space.displacement_dofs(scalar_dofs, self.components)  # (ncomp, n)
        self.coordinates = space.dof_coordinates[:, scalar_dofs]
        self.dim = space.dim
        self.value, self.ramp = value, ramp
        if not callable(value):
            array = np.asarray(value, dtype=float)
            if not np.all(np.isfinite(array)):
                raise ValueError(f"prescribed displacement must be finite; got {value!r}")
            try:
                np.broadcast_to(array.reshape(array.shape + (1,) * (array.ndim == 1)), self.dofs.shape)
            except ValueError as err:
                raise ValueError(
                    f"prescribed value of shape {array.shape} does not fit {len(self.components)} components"
                ) from err

    def values(self, t: float) -> np.ndarray:
        """Prescribed values at load factor ``t``, shape (ncomp, n).

        Raises :class:`~skvalve.fem.errors.LoadError` (naming the value, its components and nodes and ``t``) when
        a callable value does not give finite numbers of the shape ``(dim, n)``, ``(dim,)`` or ``(dim, 1)``.
        """
        term = "prescribed displacement"
        where = f"components {self.components.tolist()} of {self.dofs.shape[1]} node(s)"
        if callable(self.value):
            full = evaluated_load(self.value(self.coordinates, t), term, self.value, t, where=where)
            try:
                full = np.broadcast_to(full if full.ndim == 2 else full.reshape(-1, 1),
                                       (self.dim, self.dofs.shape[1]))
            except ValueError:
                raise LoadError(term, self.value, t, f"returned an array of shape {full.shape}, expected "
                                f"({self.dim}, {self.dofs.shape[1]}) or ({self.dim},)", where) from None
            out = full[self.components]
        else:
            array = np.asarray(self.value, dtype=float)
            array = array.reshape(array.shape + (1,) * (array.ndim == 1))
            out = evaluated_load(np.broadcast_to(array * (t if self.ramp else 1.0), self.dofs.shape), term,
                                 self.value, t, where=where)
        return out


class NodalForce(Term):
    """A force vector applied at each selected node (scalar dof): an external, dead load."""

    load_dependent = True
    name = "nodal force"

    def __init__(self, space: Space, scalar_dofs: np.ndarray, force, ramp: bool) -> None:
        self.dofs = space.displacement_dofs(scalar_dofs)
        self.source = force
        self.force = load_function(force, ramp, "force")
        self.dim = space.dim
        self.n_dofs = space.n_dofs

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        return Contribution(external=self.vector(self.n_dofs, t))

    def vector(self, n_dofs: int, t: float) -> np.ndarray:
        f = np.zeros(n_dofs)
        where = f"on {self.dofs.shape[1]} node(s)"
        value = evaluated_load(self.force(t), self.name, self.source, t, where=where)
        if value.size not in (self.dim, self.dofs.size):
            raise LoadError(self.name, self.source, t, f"returned an array of shape {value.shape}, expected "
                            f"({self.dim},) or ({self.dim}, {self.dofs.shape[1]})", where)
        np.add.at(f, self.dofs, np.broadcast_to(value.reshape(self.dim, -1), self.dofs.shape))
        return f


class FollowerPressure(Term):
    """Pressure on reference facets that follows the deformed surface (positive pushes inward)."""

    load_dependent = True
    symmetric = False
    name = "follower pressure"

    def __init__(self, space: Space, facets: np.ndarray, pressure, ramp: bool = True) -> None:
        if facets.size == 0:
            raise ValueError("pressure load on an empty facet set")
        interior = np.setdiff1d(facets, space.mesh.boundary_facets())
        if interior.size:
            raise ValueError(
                f"pressure on {interior.size} interior facet(s) [{', '.join(map(str, interior[:10]))}]: "
                "a follower pressure acts on boundary facets only"
            )
        self.n_dofs = space.n_dofs
        self.source = pressure
        self.pressure = load_function(pressure, ramp, "pressure")
        if not callable(pressure) and np.size(pressure) != 1:
            raise ValueError(f"parameter pressure must be one number (or a callable p(t)); got shape "
                             f"{np.shape(pressure)}")
        self.n_facets = facets.size
        self.dim = space.dim
        basis = fem.FacetBasis(space.mesh, space.element_u, facets=facets, intorder=space.intorder)
        nb = basis.Nbfun
        self.dN = np.ascontiguousarray(np.stack([basis.basis[a][0].grad for a in range(nb)]).transpose(2, 3, 0, 1))
        self.N = np.stack([np.asarray(basis.basis[a][0]) for a in range(nb)]).transpose(1, 2, 0)  # (nf, nqp, nb)
        normals = np.zeros((3,) + basis.normals.shape[1:])
        normals[: self.dim] = basis.normals
        self.normals = normals  # (3, nf, nqp)
        self.dx = basis.dx
        scalar = basis.element_dofs.T
        self.element_dofs = (self.dim * scalar[:, :, None] + np.arange(self.dim)).reshape(scalar.shape[0], -1)

    def connectivity(self) -> list[np.ndarray]:
        return [self.element_dofs]

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None = None) -> Contribution:
        """External forces (a follower pressure does work against the normal) and the load stiffness."""
        forces, ke = self.element_terms(u, t, tangent)
        external = -np.bincount(self.element_dofs.ravel(), forces.ravel(), minlength=self.n_dofs)
        return Contribution(external=external, blocks=[Blocks(self.element_dofs, ke)])

    def energy(self, u: np.ndarray, t: float) -> float | None:
        """0 while the pressure is off at ``t``; otherwise ``None``: a follower pressure on an open surface has no
        potential (the incremental solver then takes the residual norm as its merit)."""
        p = float(evaluated_load(self.pressure(t), self.name, self.source, t, shape=(),
                                 where=f"on {self.n_facets} facet(s)"))
        return 0.0 if p == 0.0 else None

    def element_terms(self, u: np.ndarray, t: float, tangent: bool):
        """Residual contributions (nf, nb*d) and load stiffness (nf, nb*d, nb*d) or None."""
        p = float(evaluated_load(self.pressure(t), self.name, self.source, t, shape=(),
                                 where=f"on {self.n_facets} facet(s)"))
        d = self.dim
        nf, nqp, nb = self.N.shape
        u_elem = u[self.element_dofs].reshape(nf, nb, d)
        F = embed_3d(element_gradients(u_elem, self.dN))  # (3, 3, nqp, nf)
        F = F.transpose(0, 1, 3, 2)  # (3, 3, nf, nqp)
        # cof_iJ = 1/2 eps_ikm eps_JLM F_kL F_mM
        cofF = 0.5 * np.einsum("ikm,JLM,kLfq,mMfq->iJfq", _LEVI_CIVITA, _LEVI_CIVITA, F, F, optimize=True)
        weight = p * self.dx  # (nf, nqp)
        traction = np.einsum("iJfq,Jfq->fqi", cofF, self.normals)[:, :, :d]
        forces = np.einsum("fq,fqa,fqi->fai", weight, self.N, traction).reshape(nf, nb * d)
        if not tangent:
            return forces, None
        D = np.einsum("ikm,JLM,mMfq,Jfq->fqikL", _LEVI_CIVITA, _LEVI_CIVITA, F, self.normals, optimize=True)
        D = D[:, :, :d, :d, :d]
        ke = np.einsum("fq,fqa,fqikL,fqbL->faibk", weight, self.N, D, self.dN, optimize=True)
        ke = ke.reshape(nf, nb * d, nb * d)
        return forces, ke
