r"""Total-Lagrangian hyperelastic solid on a scikit-fem mesh.

Weak form (reference configuration :math:`\Omega_0`, first Piola–Kirchhoff stress
:math:`P = \partial\psi/\partial F`): find :math:`u` with prescribed values on the
Dirichlet boundary such that for all admissible :math:`\delta u`

.. math::

    R(u;\delta u) = \int_{\Omega_0} P(F) : \nabla_0 \delta u \, dV
                  + \int_{\Gamma_p} p\,(\operatorname{cof}F\,N)\cdot\delta u\,dA
                  - \sum_n f_n\cdot\delta u(X_n) = 0,\qquad F = I + \nabla_0 u .

Its Gateaux derivative in direction :math:`\Delta u` is the tangent

.. math::

    K(u;\delta u,\Delta u) = \int_{\Omega_0} \nabla_0\delta u : \mathbb{A} : \nabla_0\Delta u\,dV
        + K_p(u;\delta u,\Delta u),\qquad \mathbb{A} = \partial P/\partial F,

with the follower-pressure load stiffness :math:`K_p` of :mod:`skvalve.fem.loads`; the
mixed u/p terms are in :mod:`skvalve.fem.constitutive`. Reactions are the residual at the
constrained dofs, :math:`r = f_\text{int} - f_\text{ext}`: the force the supports exert on
the body. Plane strain (2D meshes) gives quantities per unit width.

Assembly: the element stiffness of :mod:`skvalve.fem.kernels` is added into a CSR matrix of
the free dofs whose pattern and entry positions are built once per set of constraints.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import skfem as fem

from ..kinematics import determinant
from ..materials.base import Hyperelastic
from .constitutive import MaterialRegions
from .kernels import csr_pattern, element_forces, element_gradients, element_stiffness, scatter_add
from .loads import Dirichlet, FollowerPressure, NodalForce, embed_3d
from .space import Space

__all__ = ["Solid", "NonPositiveJacobianError", "SolverError", "ConvergenceError"]


class SolverError(RuntimeError):
    """Base of solver failures; ``last_converged`` is the :class:`Result` up to the last converged step."""

    last_converged = None


class NonPositiveJacobianError(SolverError):
    """J <= 0 (or not finite) at a quadrature point; names the elements and the load step."""

    def __init__(self, elements: np.ndarray, step: int | None, load_factor: float | None) -> None:
        self.elements = np.asarray(elements)
        self.step, self.load_factor = step, load_factor
        shown = ", ".join(str(e) for e in self.elements[:10]) + (" ..." if self.elements.size > 10 else "")
        super().__init__(
            f"det F <= 0 (or not finite) in {self.elements.size} element(s) [{shown}] "
            f"at load step {step} (load factor {load_factor})"
        )


class ConvergenceError(SolverError):
    """Newton did not converge after the allowed step cut-backs."""


class Solid:
    """Hyperelastic solid: mesh, formulation, materials, constraints and loads.

    Parameters
    ----------
    mesh : scikit-fem mesh (hex, tet; quad or triangle for plane strain).
    materials : a :class:`~skvalve.materials.base.Hyperelastic` law, a mapping
        ``{subdomain name: law}`` (``mesh.subdomains``) or a sequence of laws with ``regions``.
    formulation : ``"u"`` (displacement, order 1 or 2) or ``"up"`` (mixed Q2/Q1, P2/P1).
    order : displacement polynomial order (default 1 for ``"u"``, 2 for ``"up"``).
    regions : element -> material index array, with a sequence of ``materials``.
    intorder : quadrature order override.
    """

    def __init__(self, mesh: fem.Mesh, materials: Hyperelastic | dict | list, formulation: str = "u",
                 order: int | None = None, regions: np.ndarray | None = None, intorder: int | None = None) -> None:
        self.space = Space(mesh, formulation, order, intorder)
        self.materials = MaterialRegions(mesh, materials, regions, mixed=formulation == "up")
        self.mesh = mesh
        self.dim = self.space.dim
        self.dirichlet: list[Dirichlet] = []
        self.pressures: list[FollowerPressure] = []
        self.nodal_forces: list[NodalForce] = []
        self._pattern = None

    # ------------------------------------------------------------ definitions
    def add_dirichlet(self, where=None, value=0.0, components=None, *, nodes=None, ramp: bool = True) -> Solid:
        """Prescribe displacement components on a boundary.

        ``where``: boundary name, facet indices or ``X -> bool`` on dof locations (shape (dim, n));
        or ``nodes=`` scalar dof indices. ``value``: number or per-component array (times the
        load factor ``t`` when ``ramp``) or a callable ``value(X, t) -> (dim, n)`` array,
        e.g. a rigid rotation ``(R(theta t) - I)(X - X0)``. ``components``: indices (default all).
        """
        if (where is None) == (nodes is None):
            raise ValueError("give exactly one of where= (facets/boundary/predicate) or nodes=")
        scalar = self.space.scalar_dofs_on(where) if nodes is None else np.unique(np.asarray(nodes, dtype=int))
        if scalar.size == 0:
            raise ValueError(f"add_dirichlet: the selection {where!r} contains no dofs")
        if scalar.min() < 0 or scalar.max() >= self.space.n_scalar:
            raise ValueError(f"nodes must lie in 0..{self.space.n_scalar - 1}")
        self.dirichlet.append(Dirichlet(self.space, scalar, components, value, ramp))
        self._pattern = None
        return self

    def add_pressure(self, facets, pressure, ramp: bool = True) -> Solid:
        """Follower pressure (positive = compressive, pushes against the outward normal) on facets.

        ``pressure``: number (times ``t`` when ``ramp``) or callable ``p(t)``.
        """
        self.pressures.append(FollowerPressure(self.space, self.space.facets_of(facets), pressure, ramp))
        return self

    def add_nodal_force(self, where=None, force=0.0, *, nodes=None, ramp: bool = True) -> Solid:
        """Force vector (dim,) at each selected node; number/array times ``t`` or callable ``f(t)``."""
        if (where is None) == (nodes is None):
            raise ValueError("give exactly one of where= or nodes=")
        scalar = self.space.scalar_dofs_on(where) if nodes is None else np.asarray(nodes, dtype=int).ravel()
        self.nodal_forces.append(NodalForce(self.space, scalar, force, ramp))
        return self

    # ---------------------------------------------------------- constraints
    def constrained(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Constrained dofs (sorted, unique) and their values at load factor ``t`` (later wins)."""
        values = {}
        for bc in self.dirichlet:
            for dof, val in zip(bc.dofs.ravel(), bc.values(t).ravel(), strict=True):
                values[int(dof)] = float(val)
        dofs = np.fromiter(values.keys(), dtype=np.int64, count=len(values))
        vals = np.fromiter(values.values(), dtype=float, count=len(values))
        order = np.argsort(dofs)
        return dofs[order], vals[order]

    def _build_pattern(self) -> None:
        """Free-dof CSR pattern and the CSR position of every element-matrix entry."""
        n = self.space.n_dofs
        fixed, _ = self.constrained(0.0)
        reduced = np.full(n, -1, dtype=np.int64)
        free = np.setdiff1d(np.arange(n), fixed)
        reduced[free] = np.arange(free.size)
        edofs = reduced[self.space.element_dofs]  # (nel, ndofe)
        indptr, indices, positions = csr_pattern(np.ascontiguousarray(edofs), free.size)
        self._pattern = {
            "fixed": fixed, "free": free, "reduced": reduced, "positions": positions,
            "indices": indices.astype(np.int32), "indptr": indptr.astype(np.int32),
        }

    @property
    def pattern(self) -> dict:
        if self._pattern is None:
            self._build_pattern()
        return self._pattern

    # ------------------------------------------------------------- kinematics
    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F at the quadrature points, shape (3, 3, nqp, nel) (F33 = 1 in plane strain)."""
        sp_ = self.space
        u_elem = u[: sp_.n_u][sp_.element_dofs[:, : sp_.nb_u * sp_.dim]].reshape(sp_.nel, sp_.nb_u, sp_.dim)
        return embed_3d(element_gradients(u_elem, sp_.dN))

    def _check_jacobian(self, F: np.ndarray, step, t) -> None:
        bad = ~(determinant(F) > 0.0)
        if np.any(bad):
            raise NonPositiveJacobianError(np.flatnonzero(bad.any(axis=0)), step, t)

    # ---------------------------------------------------------------- assembly
    def assemble(self, u: np.ndarray, t: float, tangent: bool = True, step: int | None = None, reuse=None):
        """Residual (all dofs) and, if ``tangent``, the element matrices (domain, pressure list).

        ``reuse``: ``(internal_forces, element_matrices)`` of an earlier call at the same ``u``; only the
        load-dependent terms are then re-evaluated at ``t`` (the domain terms do not depend on ``t``).
        ``self.internal_forces`` and ``self.external_forces`` hold the two parts of the last residual.
        """
        if reuse is not None:
            internal, (ke, _) = reuse
            return self._add_loads(internal, ke, u, t, tangent)
        sp_ = self.space
        d, nb = sp_.dim, sp_.nb_u
        F = self.deformation_gradient(u)
        self._check_jacobian(F, step, t)
        p = None
        if sp_.formulation == "up":
            p_elem = u[sp_.element_dofs[:, nb * d:]]  # (nel, nbp)
            p = np.einsum("eqa,ea->qe", sp_.Np, p_elem)
        P, A, mixed = self.materials.evaluate(F, p, tangent)
        if not np.all(np.isfinite(P)):
            bad = np.flatnonzero(~np.isfinite(P).all(axis=(0, 1, 2)))
            raise NonPositiveJacobianError(bad, step, t)
        Pd = P[:d, :d]
        fe = np.zeros((sp_.nel, sp_.ndofe))
        fe[:, : nb * d] = element_forces(Pd, sp_.dN, sp_.dx)
        ke = None
        if tangent:
            ke = np.zeros((sp_.nel, sp_.ndofe, sp_.ndofe))
            element_stiffness(A[:, :, :d, :d, :d, :d], sp_.dN, sp_.dx, ke)
        if mixed is not None:
            Jbar, compliance, J, cof = mixed
            wN = sp_.Np * sp_.dx[:, :, None]  # (nel, nqp, nbp)
            fe[:, nb * d:] = np.einsum("eqa,qe->ea", wN, Jbar - J)
            if tangent:
                coupling = -np.einsum("ijqe,eqaj,eqb->eaib", cof[:d, :d], sp_.dN, wN).reshape(sp_.nel, nb * d, -1)
                ke[:, : nb * d, nb * d:] = coupling
                ke[:, nb * d:, : nb * d] = coupling.transpose(0, 2, 1)
                ke[:, nb * d:, nb * d:] = -np.einsum("eqa,qe,eqb->eab", wN, compliance, sp_.Np)
        internal = np.bincount(sp_.element_dofs.ravel(), fe.ravel(), minlength=sp_.n_dofs)
        return self._add_loads(internal, ke, u, t, tangent)

    def _add_loads(self, internal: np.ndarray, ke, u: np.ndarray, t: float, tangent: bool):
        sp_ = self.space
        pressure_matrices = []
        external = np.zeros(sp_.n_dofs)
        for load in self.pressures:
            fp, kp = load.assemble(u, t, tangent)
            external -= np.bincount(load.element_dofs.ravel(), fp.ravel(), minlength=sp_.n_dofs)
            pressure_matrices.append(kp)
        for force in self.nodal_forces:
            external += force.vector(sp_.n_dofs, t)
        self.internal_forces, self.external_forces = internal, external
        return internal - external, (ke, pressure_matrices)

    def tangent_matrix(self, element_matrices) -> sp.csr_matrix:
        """Free-dof tangent from the element matrices of :meth:`assemble`."""
        pat = self.pattern
        ke, pressure_matrices = element_matrices
        data = np.zeros(pat["indices"].size)
        scatter_add(ke, pat["positions"], data)
        nfree = pat["free"].size
        K = sp.csr_matrix((data, pat["indices"], pat["indptr"]), shape=(nfree, nfree))
        for load, kp in zip(self.pressures, pressure_matrices, strict=True):
            rows = pat["reduced"][load.element_dofs]
            r = np.broadcast_to(rows[:, :, None], kp.shape)
            c = np.broadcast_to(rows[:, None, :], kp.shape)
            ok = (r >= 0) & (c >= 0)
            K = K + sp.csr_matrix((kp[ok], (r[ok], c[ok])), shape=(nfree, nfree))
        return K

    def apply_elements(self, element_matrices, vector: np.ndarray) -> np.ndarray:
        """Full tangent (all dofs) times ``vector``, from the element matrices."""
        sp_ = self.space
        ke, pressure_matrices = element_matrices
        out = np.bincount(sp_.element_dofs.ravel(), np.einsum("emn,en->em", ke, vector[sp_.element_dofs]).ravel(),
                          minlength=sp_.n_dofs)
        for load, kp in zip(self.pressures, pressure_matrices, strict=True):
            local = np.einsum("emn,en->em", kp, vector[load.element_dofs])
            out += np.bincount(load.element_dofs.ravel(), local.ravel(), minlength=sp_.n_dofs)
        return out

    # ------------------------------------------------------------- solving
    def solve(self, steps=10, **options):
        """Load-controlled Newton–Raphson; see :func:`skvalve.fem.newton.solve` for options."""
        from .newton import solve

        return solve(self, steps, **options)
