r"""The solid term: the domain integral of a total-Lagrangian hyperelastic body (u or mixed u/p).

Residual and tangent (reference configuration :math:`\Omega_0`, :math:`P = \partial\psi/\partial F`,
:math:`F = I + \nabla_0 u`):

.. math::

    f^\text{int}_{ai} = \int_{\Omega_0} P_{iJ}\,\frac{\partial N_a}{\partial X_J}\,dV, \qquad
    K_{ai,bk} = \int_{\Omega_0} \frac{\partial N_a}{\partial X_J}\,\mathbb{A}_{iJkL}\,
                \frac{\partial N_b}{\partial X_L}\,dV,\qquad \mathbb{A} = \partial P/\partial F,

plus, for the mixed formulation, the pressure rows of :mod:`skvalve.fem.elements.constitutive`. Element
forces and stiffness come from the compiled kernels of :mod:`skvalve.fem.kernels`.
"""

from __future__ import annotations

import numpy as np

from ...kinematics import determinant
from ..errors import NonPositiveJacobianError
from ..kernels import element_forces, element_gradients, element_stiffness
from ..loads import embed_3d
from ..space import Space
from ..terms import Blocks, Contribution, Term
from .constitutive import MaterialRegions
from .fused import assemble_regions

__all__ = ["HyperelasticTerm"]


class HyperelasticTerm(Term):
    """Hyperelastic (or quadrature-point) materials on the elements of ``space``.

    Parameters
    ----------
    space : the field's :class:`~skvalve.fem.space.Space`.
    materials : the :class:`~skvalve.fem.elements.constitutive.MaterialRegions` assigning laws to elements.
    fused : evaluate stress, tangent and element matrices in one compiled pass
        (:mod:`skvalve.fem.elements.fused`) when every law supplies its invariant or principal derivatives;
        otherwise (and with ``False``) each law's ``pk1_and_tangent`` and the generic kernels.
    """

    name = "solid"

    def __init__(self, space: Space, materials: MaterialRegions, fused: bool = True) -> None:
        self.space = space
        self.materials = materials
        #: use the compiled stress-tangent-assembly kernel when every law has one (False: the laws' generic path)
        self.fused = fused

    def connectivity(self) -> list[np.ndarray]:
        return [self.space.element_dofs]

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F at the quadrature points, shape (3, 3, nqp, nel) (F33 = 1 in plane strain)."""
        sp_ = self.space
        u_elem = u[: sp_.n_u][sp_.element_dofs[:, : sp_.nb_u * sp_.dim]].reshape(sp_.nel, sp_.nb_u, sp_.dim)
        return embed_3d(element_gradients(u_elem, sp_.dN))

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        sp_ = self.space
        d, nb = sp_.dim, sp_.nb_u
        F = self.deformation_gradient(u)
        bad = ~(determinant(F) > 0.0)
        if np.any(bad):
            raise NonPositiveJacobianError(np.flatnonzero(bad.any(axis=0)), step, t, self.name)
        p = None
        if sp_.formulation == "up":
            p_elem = u[sp_.element_dofs[:, nb * d:]]  # (nel, nbp)
            p = np.einsum("eqa,ea->qe", sp_.Np, p_elem)
        fused = assemble_regions(self.materials, F, sp_, tangent, p) if self.fused else None
        if fused is not None:  # every law compiled with its element assembly (skvalve.fem.elements.fused)
            P, fe, ke = fused.P, fused.forces, fused.stiffness
        else:
            P, fe, ke = self._generic(F, p, tangent)
        if not np.all(np.isfinite(P)):
            bad_elements = np.flatnonzero(~np.isfinite(P).all(axis=(0, 1, 2)))
            raise NonPositiveJacobianError(bad_elements, step, t, self.name)
        internal = np.bincount(sp_.element_dofs.ravel(), fe.ravel(), minlength=sp_.n_dofs)
        return Contribution(internal=internal, blocks=[Blocks(sp_.element_dofs, ke)])

    def energy(self, u: np.ndarray, t: float) -> float | None:
        r""":math:`\int_{\Omega_0}\psi\,dV` (``None`` for the mixed formulation or laws without an energy)."""
        if self.space.formulation != "u":
            return None
        F = self.deformation_gradient(u)
        if not np.all(determinant(F) > 0.0):
            return float("inf")
        W = self.materials.energy_density(F)
        return None if W is None else float(np.sum(W.T * self.space.dx))

    def _generic(self, F: np.ndarray, p: np.ndarray | None, tangent: bool):
        """P, element forces and stiffness through the laws' own ``pk1_and_tangent`` (any material)."""
        sp_ = self.space
        d, nb = sp_.dim, sp_.nb_u
        P, A, mixed = self.materials.evaluate(F, p, tangent)
        fe = np.zeros((sp_.nel, sp_.ndofe))
        if not np.all(np.isfinite(P)):
            return P, fe, None
        fe[:, : nb * d] = element_forces(P[:d, :d], sp_.dN, sp_.dx)
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
        return P, fe, ke

    def commit(self) -> None:
        for region in self.materials.regions:
            commit = getattr(region.material, "commit", None)
            if commit is not None:
                commit()

    def rewind(self) -> None:
        for region in self.materials.regions:
            rewind = getattr(region.material, "rewind", None)
            if rewind is not None:
                rewind()

    def state(self) -> dict[str, np.ndarray]:
        """Committed state of the regions' materials that have one (``material.checkpoint_arrays()``)."""
        out = {}
        for k, region in enumerate(self.materials.regions):
            getter = getattr(region.material, "checkpoint_arrays", None)
            if getter is not None:
                out.update({f"region{k}.{name}": value for name, value in getter().items()})
        return out

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        """Hand each region's material its arrays from :meth:`state` (``material.restore_arrays``)."""
        for k, region in enumerate(self.materials.regions):
            prefix = f"region{k}."
            mine = {key[len(prefix):]: value for key, value in arrays.items() if key.startswith(prefix)}
            restore = getattr(region.material, "restore_arrays", None)
            if restore is not None:
                restore(mine)
            elif mine:
                raise ValueError(f"material of region {k} has saved state but no restore_arrays()")
