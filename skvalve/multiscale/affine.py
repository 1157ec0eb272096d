r"""Affine fiber-network model: every fiber follows the macroscopic deformation, d = F D.

The classical structural model the paper contrasts with its non-affine RVEs (§1): with no
force balance to solve, the network is a hyperelastic solid with the stored energy per unit
reference volume (Eq. 9 integrated, scaled as in Eqs. 6–8)

.. math::

    \Psi(F) = \frac{\psi}{L A_f} \sum_k L_k\, W(\lambda_k), \qquad
    \lambda_k = \frac{|F D_k|}{L_k},\quad W(\lambda) = \int_1^\lambda f\,d\lambda',

so that, with :math:`d = F D`, :math:`\ell = |d|`, :math:`g(\ell) = f/\ell`,

.. math::

    P_{iJ} = \frac{\psi}{L A_f}\sum_k g\, d_i D_J, \qquad
    \frac{\partial P_{iJ}}{\partial F_{kL}} = \frac{\psi}{L A_f}\sum
        \Big[\frac{g'(\ell)}{\ell}\, d_i D_J\, d_k D_L + g\,\delta_{ik} D_J D_L\Big],
    \quad g'(\ell) = \frac{f'(\lambda)/L - f/\ell}{\ell} .

It is written in the first Piola–Kirchhoff form (the RVE solver works with Cauchy stress and
dσ/dF), so it is an independent check of both the RVE stress of a network whose cross-links all
lie on the boundary and of the Cauchy→Piola conversion of :mod:`skvalve.multiscale.material`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..kinematics import as_tensor_field, determinant
from ..materials.exponential_fiber import ExponentialFiber
from ..networks.network import Network

__all__ = ["AffineFiberModel"]


class AffineFiberModel:
    """Fiber stress of affinely deforming networks, one network per element (reference model).

    Parameters
    ----------
    networks : one network per element; every fiber is deformed by the point's F.
    fiber : Eq. 9 force law.
    n_points : quadrature points per element.
    psi, fiber_diameter : as in :func:`skvalve.networks.solve_rve` (diameter None: ``fiber.A_f``).
    """

    incompressible = False

    def __init__(
        self,
        networks: Sequence[Network],
        fiber: ExponentialFiber,
        n_points: int = 8,
        psi: float = 0.43,
        fiber_diameter: float | None = 450e-9,
    ) -> None:
        self.networks = list(networks)
        self.fiber, self.n_points = fiber, int(n_points)
        area = fiber.A_f if fiber_diameter is None else math.pi * float(fiber_diameter) ** 2 / 4.0
        self.scales = [psi / (net.total_length * area) for net in self.networks]

    def _check(self, F) -> np.ndarray:
        F = as_tensor_field(F)
        if F.shape[2:] != (self.n_points, len(self.networks)):
            raise ValueError(f"AffineFiberModel: F must have shape (3, 3, {self.n_points}, {len(self.networks)})")
        return F

    def pk1_and_tangent(self, F) -> tuple[np.ndarray, np.ndarray]:
        """P (3,3,nqp,nel) and dP/dF (3,3,3,3,nqp,nel)."""
        F = self._check(F)
        P = np.zeros_like(F)
        A = np.zeros((3, 3) + F.shape)
        for e, (net, scale) in enumerate(zip(self.networks, self.scales, strict=True)):
            D = net.fiber_vectors()  # (m, 3)
            rest = np.linalg.norm(D, axis=1)
            d = np.einsum("iJq,mJ->mqi", F[:, :, :, e], D)  # (m, nqp, 3)
            ell = np.linalg.norm(d, axis=2)
            stretch = ell / rest[:, None]
            f = self.fiber.force(stretch)
            g = f / ell
            dg = (self.fiber.stiffness(stretch) / rest[:, None] - g) / ell
            P[:, :, :, e] = scale * np.einsum("mq,mqi,mJ->iJq", g, d, D)
            A[:, :, :, :, :, e] = scale * (
                np.einsum("mq,mqi,mJ,mqk,mL->iJkLq", dg / ell, d, D, d, D)
                + np.einsum("ik,mq,mJ,mL->iJkLq", np.eye(3), g, D, D)
            )
        return P, A

    def pk1(self, F) -> np.ndarray:
        return self.pk1_and_tangent(F)[0]

    def cauchy(self, F) -> np.ndarray:
        """σ = P Fᵀ / J."""
        F = self._check(F)
        return np.einsum("iJ...,jJ...->ij...", self.pk1(F), F) / determinant(F)
