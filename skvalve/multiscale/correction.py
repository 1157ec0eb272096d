r"""Size of the Chandran–Barocas averaging term (thomas2019 Eq. 11), which the balance here neglects.

Derivation (Chandran & Barocas 2007; the paper's Eq. 11). Let :math:`s` be the microscopic stress in an RVE of
volume :math:`V`, in equilibrium (:math:`s_{ij,i} = 0`), and :math:`\bar S = \frac1V\int_V s\,dV` its average
(Eq. 8). The RVE boundary moves with the displacement :math:`u`; differentiating the average with respect to
the macroscopic position by Leibniz' rule leaves, besides the average of :math:`s_{ij,i}` (zero), the pairing of
the boundary stress with the boundary motion:

.. math::

    \frac{\partial \bar S_{ij}}{\partial x_i} = \frac{1}{V}\oint_{\partial V}(s_{ij} - \bar S_{ij})\,
    u_{k,i}\,n_k\,dA .

Sign: the balance is :math:`\operatorname{div}\bar S = b` with :math:`b` the right-hand side, i.e. a body force
:math:`-b` in :math:`\operatorname{div}\bar S + f = 0`. Units: Pa over the length :math:`V/\partial V` of the RVE
(its edge :math:`\gamma`, Eq. 7), N/m³.

Terms that vanish or are dropped, for the paper's RVEs (affine boundary, :math:`x = FX`):

1. the :math:`\bar S` part: :math:`H = \partial u/\partial x = I - F^{-1}` is uniform on the boundary, so
   :math:`\bar S_{ij} H_{ki} \oint n_k\,dA = 0` (a closed surface) — exactly;
2. the matrix: its stress is uniform over the RVE (the paper: it "varies only on the macroscopic scale"), so
   its part vanishes the same way. Read literally, with the macroscopic :math:`S^c` and :math:`S^m` in the
   integrand, the paper's Eq. 11 is zero for this reason alone;
3. the variation of :math:`H` over the RVE (second gradients of :math:`u`): none, the boundary is affine;
4. fibers crossing an edge or a corner of the cube: a set of measure zero (every boundary cross-link of a clipped
   network lies on one face).

What remains is the fiber stress on the faces. A fiber of force :math:`f` and unit direction :math:`e` carries
:math:`s = (f/A_f)\,e\otimes e` on its cut, of area :math:`A_f/|e\cdot n|` on a face of deformed unit normal
:math:`n` (the cross-section :math:`A_f` is not deformed), so with :math:`m = H^T n`

.. math::

    b_j = \frac{1}{\gamma^3 J}\sum_{\text{boundary cross-links}} f\,e_j\,\frac{e\cdot m}{|e\cdot n|}
        = \frac{\psi}{L A_f\,\gamma\,J}\sum f\,e_j\,\frac{e\cdot m}{|e\cdot n|}
    \quad (\text{N/m}^3),

:math:`J = \det F` the deformed volume of the unit cube and :math:`\gamma^2 = L A_f/\psi` (Eqs. 6–7). Even in
:math:`e` (the fiber stress is), so the orientation of a fiber does not matter. It vanishes for a uniform
micro-stress (then :math:`\oint s\,H^T n\,dA = s\,H^T\oint n\,dA = 0`): for a network it is the part of the
boundary stress that fluctuates from crossing to crossing — zero for a network symmetric about the RVE centre
(each crossing has an opposite one with :math:`e, n, m \to -e, -n, -m`), zero on average over realisations of a
statistically homogeneous network, and weighted by :math:`1/|e\cdot n|`, large for fibers that graze a face.

Its size is reported two ways: pointwise relative to the stress it would compete with over an element of size
:math:`h`, :math:`\rho = |b|\,h/|\bar\sigma|`; and by its effect on the macro solution
(:func:`body_force_effect`): the consistent nodal forces :math:`f_a = \int N_a\,b\,J\,dV` and, to first order,
the displacement change :math:`\Delta u = -K_{ff}^{-1} f` with the converged tangent.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import spsolve

from ..networks.network import Network
from .material import RVEMaterial

__all__ = ["CorrectionEffect", "CorrectionSize", "body_force_effect", "chandran_barocas_effect",
           "chandran_barocas_size", "point_symmetric"]


def point_symmetric(network: Network) -> Network:
    """The network and its copy reflected through the RVE centre (X → −X; face −a ↔ +a), as one network.

    A known answer for Eq. 11's term: under any uniform F the two copies' equilibria mirror each other, every
    crossing has an opposite one (e, n, Hᵀn → −e, −n, −Hᵀn, same f), and the term vanishes.
    """
    face = np.where(network.face >= 0, network.face ^ 1, network.face)  # 2a <-> 2a + 1
    n = network.n_nodes
    return Network(np.concatenate([network.nodes, -network.nodes]),
                   np.concatenate([network.fibers, network.fibers + n]),
                   np.concatenate([network.boundary, network.boundary]), np.concatenate([network.face, face]))


@dataclass
class CorrectionSize:
    """Per RVE: body force b (n_rves, 3) in N/m³ and ratio ρ = ``|b| h / |σ|`` (n_rves,)."""

    body_force: np.ndarray
    ratio: np.ndarray

    def summary(self) -> dict[str, float]:
        return {"median": float(np.median(self.ratio)), "p95": float(np.percentile(self.ratio, 95)),
                "max": float(self.ratio.max())}


def chandran_barocas_size(material: RVEMaterial, element_size: float, min_cosine: float = 0.0) -> CorrectionSize:
    """Eq. 11's right-hand side from the committed RVE states of ``material`` (module docstring).

    ``min_cosine`` leaves out the crossings with :math:`|e\\cdot n|` below it (0: none), to show how much of the
    term the grazing fibers carry.
    """
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
        cosine = np.abs(np.sum(e * n, axis=1))
        weight = np.where(cosine >= min_cosine, np.sum(e * m, axis=1) / cosine, 0.0)
        np.add.at(body, r, force[:, None] * e * weight[:, None])
    area = np.pi * material.fiber_diameter**2 / 4.0 if material.fiber_diameter else material.fiber.A_f
    body *= (material.psi / (lengths * area * batch.edge_length * J))[:, None]
    sigma = material.cauchy(F.reshape(material.n_elements, material.n_points, 3, 3).transpose(2, 3, 1, 0))
    sigma_norm = np.linalg.norm(sigma.transpose(3, 2, 0, 1).reshape(n_rves, 9), axis=1)
    ratio = np.linalg.norm(body, axis=1) * element_size / np.maximum(sigma_norm, 1e-300)
    return CorrectionSize(body, ratio)


@dataclass
class CorrectionEffect:
    """Nodal forces of the Eq. 11 term, their size relative to the reactions, and Δu = −K⁻¹ f."""

    nodal_force: np.ndarray
    force_ratio: float  # |f|_max / |reaction|_max (inf where the state has no reactions)
    displacement_change: np.ndarray
    displacement_ratio: float  # |Δu|_max / |u|_max (inf where u = 0)


def body_force_effect(solid, body: np.ndarray, u: np.ndarray, t: float) -> CorrectionEffect:
    """First-order effect of a right-hand side ``b`` of div σ = b, given per quadrature point (nel, nqp, 3) in N/m³.

    Consistent nodal forces :math:`f_a = \\int N_a\\, b\\, J\\, dV` (b per deformed volume); the balance with the
    term reads R(u) + f = 0, so the first-order change of the converged state ``u`` is
    :math:`\\Delta u_f = -K_{ff}^{-1} f_f` (K the tangent at ``u``, prescribed dofs unchanged).
    """
    space = solid.space
    F = solid.deformation_gradient(u)
    J = np.linalg.det(F.transpose(2, 3, 0, 1)).T  # (nel, nqp)
    N = np.stack([np.asarray(space.basis_u.basis[a][0]) for a in range(space.nb_u)], axis=1)  # (nel, nb, nqp)
    element = np.einsum("eaq,eqi,eq->eai", N, body, J * space.dx).reshape(body.shape[0], -1)
    force = np.bincount(space.element_dofs.ravel(), element.ravel(), minlength=space.n_dofs)
    residual, tangent = solid.assemble(u, t, tangent=True)
    free, fixed = solid.pattern.free, solid.pattern.fixed
    change = np.zeros(space.n_dofs)
    change[free] = -spsolve(solid.tangent_matrix(tangent).tocsc(), force[free])
    reaction = np.abs(residual[fixed]).max() if fixed.size else 0.0
    largest_u = np.abs(u).max()
    return CorrectionEffect(force, float(np.abs(force).max() / reaction) if reaction > 0 else np.inf, change,
                            float(np.abs(change).max() / largest_u) if largest_u > 0 else np.inf)


def chandran_barocas_effect(solid, material: RVEMaterial, u: np.ndarray, t: float) -> CorrectionEffect:
    """First-order effect of the neglected term on a converged FE² state ``u`` at load factor ``t``."""
    size = chandran_barocas_size(material, element_size=1.0)
    body = size.body_force.reshape(material.n_elements, material.n_points, 3)  # RVE r = element * n_points + point
    return body_force_effect(solid, body, u, t)
