r"""Size of the Chandran–Barocas averaging term (thomas2019 Eq. 11), which the balance here neglects.

Volume-averaging the microscopic equilibrium over an RVE whose boundary deforms with the displacement
gradient :math:`H = \partial u/\partial x` gives (Chandran & Barocas 2007; the paper's Eq. 11)

.. math::

    \frac{\partial \bar S_{ij}}{\partial x_i} = \frac{1}{V}\oint_{\partial V}(s_{ij} - \bar S_{ij})\,
    u_{k,i}\,n_k\,dA ,

:math:`s` the microscopic stress on the RVE boundary, :math:`\bar S` its volume average (Eq. 8). Like the
open FE² codes, skvalve solves :math:`\operatorname{div}\bar S = 0` without the right-hand side; this module
measures what the right-hand side would be from converged RVEs. With an affine boundary H is uniform, so
the :math:`\bar S` part vanishes (:math:`\oint n\,dA = 0`), and the microscopic stress on the boundary is
carried by the fibers crossing it: a fiber with unit direction :math:`e` (pointing out of the RVE) and force
:math:`f` crossing a face of normal :math:`n` contributes :math:`f e_j (e\cdot m)/(e\cdot n)` with
:math:`m = H^T n` (its stress :math:`f e\otimes e/A_f` integrated over its cut :math:`A_f/|e\cdot n|`).
With the scaling of Eqs. 6–8 (RVE edge γ) the term is the body force

.. math::

    b_j = \frac{\psi}{L A_f\,\gamma\,V}\sum_{\text{boundary cross-links}} f\,e_j\,\frac{e\cdot m}{e\cdot n}
    \quad (\text{N/m}^3).

Its size is reported two ways: pointwise relative to the stress it would compete with in an element of
size h, :math:`\rho = |b|\,h/|\bar\sigma|`; and by its effect on the macro solution
(:func:`chandran_barocas_effect`): the consistent nodal forces :math:`f_a = \int N_a\, b\, J\, dV` of the
body force (signs of b fluctuate from RVE to RVE, so neighbouring Gauss points largely cancel) and the
first-order displacement change :math:`\Delta u = K_{ff}^{-1} f` with the converged tangent, compared
with the displacement itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import spsolve

from .material import RVEMaterial

__all__ = ["CorrectionEffect", "CorrectionSize", "chandran_barocas_effect", "chandran_barocas_size"]


@dataclass
class CorrectionSize:
    """Per RVE: body force b (n_rves, 3) in N/m³ and ratio ρ = ``|b| h / |σ|`` (n_rves,)."""

    body_force: np.ndarray
    ratio: np.ndarray

    def summary(self) -> dict[str, float]:
        return {"median": float(np.median(self.ratio)), "p95": float(np.percentile(self.ratio, 95)),
                "max": float(self.ratio.max())}


def chandran_barocas_size(material: RVEMaterial, element_size: float) -> CorrectionSize:
    """Eq. 11's right-hand side from the committed RVE states of ``material`` (module docstring)."""
    batch = material.batch
    n_rves = material.n_rves
    per_rve = [net for net in material.networks for _ in range(material.n_points)]
    face = np.concatenate([net.face for net in per_rve])
    lengths = np.array([net.total_length for net in per_rve])
    rve_of_fiber = np.repeat(np.arange(n_rves), np.diff(batch.fiber_start))
    ends = batch.fibers + batch.node_start[rve_of_fiber][:, None]
    x = batch.positions
    F = batch.F_state
    F_inv = np.linalg.inv(F)
    J = np.linalg.det(F)
    H = np.eye(3) - F_inv  # spatial displacement gradient ∂u/∂x, uniform on the affine boundary
    body = np.zeros((n_rves, 3))
    for boundary_end in (0, 1):
        b, other = ends[:, boundary_end], ends[:, 1 - boundary_end]
        cut = face[b] >= 0
        r = rve_of_fiber[cut]
        d = x[b[cut]] - x[other[cut]]
        ell = np.linalg.norm(d, axis=1)
        e = d / ell[:, None]
        force = material.fiber.force(ell / batch.rest_length[cut])
        axis, sign = face[b[cut]] // 2, np.where(face[b[cut]] % 2 == 1, 1.0, -1.0)
        N = np.zeros((r.size, 3))
        N[np.arange(r.size), axis] = sign
        n = np.einsum("rji,rj->ri", F_inv[r], N)  # deformed normal ∝ F^{-T} N
        n /= np.linalg.norm(n, axis=1)[:, None]
        m = np.einsum("rki,rk->ri", H[r], n)
        contribution = force[:, None] * e * (np.sum(e * m, axis=1) / np.sum(e * n, axis=1))[:, None]
        np.add.at(body, r, contribution)
    area = np.pi * material.fiber_diameter**2 / 4.0 if material.fiber_diameter else material.fiber.A_f
    body *= (material.psi / (lengths * area * batch.edge_length * J))[:, None]
    sigma = material.cauchy(F.reshape(material.n_elements, material.n_points, 3, 3).transpose(2, 3, 1, 0))
    sigma_norm = np.linalg.norm(sigma.transpose(3, 2, 0, 1).reshape(n_rves, 9), axis=1)
    ratio = np.linalg.norm(body, axis=1) * element_size / np.maximum(sigma_norm, 1e-300)
    return CorrectionSize(body, ratio)


@dataclass
class CorrectionEffect:
    """Nodal forces of the Eq. 11 body force, their size relative to the reactions, and Δu = K⁻¹ f."""

    nodal_force: np.ndarray
    force_ratio: float  # |f|_max / |reaction|_max
    displacement_change: np.ndarray
    displacement_ratio: float  # |Δu|_max / |u|_max


def chandran_barocas_effect(solid, material: RVEMaterial, u: np.ndarray, t: float) -> CorrectionEffect:
    """First-order effect of the neglected term on a converged FE² state ``u`` at load factor ``t``."""
    size = chandran_barocas_size(material, element_size=1.0)
    space = solid.space
    nqp, nel = material.n_points, material.n_elements
    body = size.body_force.reshape(nel, nqp, 3)  # RVE r = element * n_points + point
    F = solid.deformation_gradient(u)
    J = np.linalg.det(F.transpose(2, 3, 0, 1)).T  # (nel, nqp)
    N = np.stack([np.asarray(space.basis_u.basis[a][0]) for a in range(space.nb_u)], axis=1)  # (nel, nb, nqp)
    element = np.einsum("eaq,eqi,eq->eai", N, body, J * space.dx).reshape(nel, -1)
    force = np.bincount(space.element_dofs.ravel(), element.ravel(), minlength=space.n_dofs)
    residual, tangent = solid.assemble(u, t, tangent=True)
    free = solid.pattern.free
    K = solid.tangent_matrix(tangent)
    change = np.zeros(space.n_dofs)
    change[free] = _sparse_solve(K, force[free])
    fixed = solid.pattern.fixed
    reaction = np.abs(residual[fixed]).max() if fixed.size else 1.0
    return CorrectionEffect(force, float(np.abs(force).max() / reaction), change,
                            float(np.abs(change).max() / np.abs(u).max()))


def _sparse_solve(K, rhs: np.ndarray) -> np.ndarray:
    return spsolve(K.tocsc(), rhs)
