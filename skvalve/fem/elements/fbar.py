r"""F-bar trilinear hexahedron (Q1) with the element's mean dilatation: a non-locking solid term.

**Choice.** The F-bar idea of de Souza Neto et al. (1996, Int. J. Solids Struct. 33:3277) with the
volume change taken as the element's mean dilatation (Simo, Taylor & Pister 1985, Comput. Methods
Appl. Mech. Eng. 51:177), in variational form. At every quadrature point

.. math::

    \bar F = \alpha F, \qquad \alpha = \Big(\frac{\theta}{J}\Big)^{1/3}, \qquad
    \theta = \frac{1}{V_e}\int_{\Omega_e} J\,dV = \frac{v_e}{V_e},

and the stored energy is :math:`\Pi = \sum_e\sum_q w_q\,\psi(\bar F_q)`. Because
:math:`\det\bar F = \theta` the volume constraint acts once per element while the isochoric part of
:math:`\bar F` is that of :math:`F`. For a law split as :math:`\psi = \hat\psi(J^{-1/3}F) + U(J)`
(``LeeSacks`` with its :math:`(J-1)^2/D`, Ogden with one :math:`D`) the energy is
:math:`\int\hat\psi(F)\,dV + V_e U(\theta)`: exactly Q1/P0 mean dilatation. Any other compressible law
works too. The mean dilatation (rather than :math:`\det F` at the centroid, de Souza Neto's choice)
makes the variational form pass the patch test on distorted hexes; the energy form has a symmetric
tangent.

**Residual and tangent.** With :math:`G = F^{-T}`, :math:`\bar P = P(\bar F)`, :math:`s = \bar P:F`,
the element vector :math:`g = \partial\ln\theta/\partial u = \sum_q \beta_q\,G_q:B_q`
(:math:`\beta_q = w_qJ_q/\sum_q w_qJ_q`, :math:`B_q = \partial F_q/\partial u`) and
:math:`c_q = \tfrac13(g - G_q:B_q) = \partial\ln\alpha_q/\partial u`,

.. math::

    \bar B_q = \partial\bar F_q/\partial u = \alpha_q(B_q + F_q\otimes c_q), \qquad
    f = \sum_q w_q\,\bar B_q^T\bar P_q,

    K = \sum_q w_q\Big[\bar B_q^T\bar{\mathbb A}_q\bar B_q
        + \alpha_q\big(c_q\otimes p_q + p_q\otimes c_q + s_q\,c_q\otimes c_q\big)
        + \tfrac{\alpha_q s_q}{3}\,B_q^T T_q B_q\Big]
        + \Big(\sum_q \tfrac{w_q\alpha_q s_q}{3}\Big)\,\frac{\partial^2\ln\theta}{\partial u^2},

with :math:`p_q = \bar P_q:B_q`, :math:`(T_q)_{iJkL} = G_{iL}G_{kJ}` (from
:math:`\partial G_{iJ}/\partial F_{kL} = -G_{iL}G_{kJ}`), :math:`\bar{\mathbb A} = \partial P/\partial F`
at :math:`\bar F`, and
:math:`\partial^2\ln\theta/\partial u^2 = \sum_q\beta_q\big[(G_q:B_q)\otimes(G_q:B_q) - B_q^TT_qB_q\big]
- g\otimes g`. Compiled per element below.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ...kinematics import determinant
from ..errors import NonPositiveJacobianError
from ..kernels import add_point_stiffness, element_gradients
from ..space import Space
from ..terms import Blocks, Contribution, Term
from .constitutive import MaterialRegions
from .fused import point_response_regions
from .fused_points import inverse_transpose

__all__ = ["FBarTerm", "mean_dilatation", "fbar_deformation", "fbar_element_response"]


def mean_dilatation(F: np.ndarray, dx: np.ndarray) -> np.ndarray:
    r""":math:`\theta_e = \sum_q w_q J_q / \sum_q w_q` for F (3, 3, nqp, nel) and weights dx (nel, nqp)."""
    return np.einsum("qe,eq->e", determinant(F), dx) / dx.sum(axis=1)


def fbar_deformation(F: np.ndarray, dx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""``(F_bar, alpha)``: :math:`\bar F = (\theta/J)^{1/3}F` at every quadrature point."""
    alpha = np.cbrt(mean_dilatation(F, dx)[None, :] / determinant(F))
    return alpha * F, alpha


@njit(parallel=True, cache=True)
def fbar_element_response(F, Pbar, A, dN, dx, tangent):
    """Element forces (nel, 3 nb) and, if ``tangent``, matrices (nel, 3 nb, 3 nb) (module docstring).

    ``F``, ``Pbar``: (3, 3, nqp, nel); ``A[e, q, i, J, k, L]`` = dP/dF at F_bar (ignored unless ``tangent``), with
    the major symmetry of a hyperelastic tangent; ``dN``: (nel, nqp, nb, 3); ``dx``: (nel, nqp).

    With :math:`\\bar B = \\alpha(B + F\\otimes c)`: :math:`\\bar B^T\\bar P = \\alpha(p + s\\,c)` and
    :math:`\\bar B^T\\bar{\\mathbb A}\\bar B = \\alpha^2\\big(B^T\\bar{\\mathbb A}B + u\\otimes c + c\\otimes u
    + (F:\\bar{\\mathbb A}:F)\\,c\\otimes c\\big)`, :math:`u = B^T(\\bar{\\mathbb A}:F)`; the rank-one terms of
    all points and the :math:`B^T T B` terms (a weighted Gram matrix of :math:`G:B`) are summed after the point
    loop, on the upper triangle, and mirrored."""
    nel, nqp, nb, _ = dN.shape
    m = 3 * nb
    f = np.zeros((nel, m))
    K = np.zeros((nel if tangent else 0, m, m))
    for e in prange(nel):
        G = np.empty((nqp, 3, 3))
        J = np.empty(nqp)
        GB = np.zeros((nqp, m))  # G_q : B_q
        volume, deformed = 0.0, 0.0
        for q in range(nqp):
            J[q] = inverse_transpose(F[:, :, q, e], G[q])
            volume += dx[e, q]
            deformed += dx[e, q] * J[q]
            for a in range(nb):
                for k in range(3):
                    acc = 0.0
                    for L in range(3):
                        acc += G[q, k, L] * dN[e, q, a, L]
                    GB[q, 3 * a + k] = acc
        theta = deformed / volume
        g = np.zeros(m)
        for q in range(nqp):
            beta = dx[e, q] * J[q] / deformed
            for n in range(m):
                g[n] += beta * GB[q, n]
        c = np.empty((nqp, m))
        y = np.empty((nqp, m))  # K += c_q (x) y_q + y_q (x) c_q
        p = np.empty(m)
        geometric = np.empty(nqp)
        AF = np.empty((3, 3))
        Gw = np.empty((nb, 3, 3, 3))
        Ke = np.zeros((m, m))
        S = 0.0
        for q in range(nqp):
            w = dx[e, q]
            alpha = (theta / J[q]) ** (1.0 / 3.0)
            wa = w * alpha
            s = 0.0
            for i in range(3):
                for jj in range(3):
                    s += Pbar[i, jj, q, e] * F[i, jj, q, e]
            for n in range(m):
                c[q, n] = (g[n] - GB[q, n]) / 3.0
            for a in range(nb):
                for k in range(3):
                    acc = 0.0
                    for L in range(3):
                        acc += Pbar[k, L, q, e] * dN[e, q, a, L]
                    p[3 * a + k] = acc
            for n in range(m):
                f[e, n] += wa * (p[n] + s * c[q, n])
            if not tangent:
                continue
            FAF = 0.0
            for i in range(3):
                for jj in range(3):
                    acc = 0.0
                    for k in range(3):
                        for L in range(3):
                            acc += A[e, q, i, jj, k, L] * F[k, L, q, e]
                    AF[i, jj] = acc
                    FAF += F[i, jj, q, e] * acc
            wa2 = wa * alpha
            half = 0.5 * (wa2 * FAF + wa * s)
            for a in range(nb):  # y = w alpha^2 u + w alpha p + (w alpha^2 F:A:F + w alpha s) c / 2
                for i in range(3):
                    acc = 0.0
                    for jj in range(3):
                        acc += dN[e, q, a, jj] * AF[i, jj]
                    n = 3 * a + i
                    y[q, n] = wa2 * acc + wa * p[n] + half * c[q, n]
            add_point_stiffness(Ke, dN[e, q], A[e, q], wa2, Gw)
            geometric[q] = wa * s / 3.0
            S += geometric[q]
        if not tangent:
            continue
        # T[n, n'] = sum_q (w alpha s/3 - S beta)_q (G:B)_q[n] (G:B)_q[n']; S d2 ln(theta)/du2 holds the rest
        T = np.zeros((m, m))
        for q in range(nqp):
            Sbeta = S * dx[e, q] * J[q] / deformed
            for n1 in range(m):
                c1, y1, gb1 = c[q, n1], y[q, n1], Sbeta * GB[q, n1]
                for n2 in range(n1, m):
                    Ke[n1, n2] += c1 * y[q, n2] + y1 * c[q, n2] + gb1 * GB[q, n2]
                t1 = (geometric[q] - Sbeta) * GB[q, n1]
                for n2 in range(m):
                    T[n1, n2] += t1 * GB[q, n2]
        for a1 in range(nb):
            for i1 in range(3):
                n1 = 3 * a1 + i1
                for a2 in range(a1, nb):
                    for i2 in range(3):
                        n2 = 3 * a2 + i2
                        if n2 < n1:
                            continue
                        # B^T T B [(a1,i1),(a2,i2)] = (G:B)[a1, i2] (G:B)[a2, i1]
                        v = Ke[n1, n2] + T[3 * a1 + i2, 3 * a2 + i1] - S * g[n1] * g[n2]
                        K[e, n1, n2] = v
                        K[e, n2, n1] = v
    return f, K


class FBarTerm(Term):
    """F-bar (mean dilatation) Q1 hexahedra: compressible law(s) on a ``"u"``, order-1 hex ``space``.

    Parameters
    ----------
    space : the field's :class:`~skvalve.fem.space.Space` (hex mesh, ``formulation="u"``, ``order=1``).
    materials : a law, ``{subdomain: law}`` or a sequence of laws with ``regions`` (as for ``Solid``), or
        a ready :class:`~skvalve.fem.elements.constitutive.MaterialRegions`.
    regions : element -> material index, with a sequence of laws.
    fused : evaluate P and dP/dF at F_bar with the compiled laws of
        :mod:`skvalve.fem.elements.fused` (:func:`~skvalve.fem.elements.fused.point_response_regions`) when every law
        has one; otherwise, or with ``False``, through
        :meth:`~skvalve.fem.elements.constitutive.MaterialRegions.evaluate`.
    """

    name = "F-bar solid"

    def __init__(self, space: Space, materials, regions: np.ndarray | None = None, fused: bool = True) -> None:
        if space.family != "hex" or space.order != 1 or space.formulation != "u":
            raise ValueError("F-bar needs trilinear hexahedra: a hex mesh with formulation='u', order=1")
        self.space = space
        self.materials = materials if isinstance(materials, MaterialRegions) else MaterialRegions(
            space.mesh, materials, regions, mixed=False)
        self.fused = fused

    def connectivity(self) -> list[np.ndarray]:
        return [self.space.element_dofs]

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F at the quadrature points, shape (3, 3, nqp, nel)."""
        sp_ = self.space
        u_elem = u[: sp_.n_u][sp_.element_dofs].reshape(sp_.nel, sp_.nb_u, 3)
        return np.eye(3)[:, :, None, None] + element_gradients(u_elem, sp_.dN)

    def modified_deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """:math:`\\bar F` at the quadrature points (what the law sees; for stress output)."""
        return fbar_deformation(self.deformation_gradient(u), self.space.dx)[0]

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        sp_ = self.space
        F = self.deformation_gradient(u)
        bad = ~(determinant(F) > 0.0)
        if np.any(bad):
            raise NonPositiveJacobianError(np.flatnonzero(bad.any(axis=0)), step, t, self.name)
        Fbar, _ = fbar_deformation(F, sp_.dx)
        response = point_response_regions(self.materials, Fbar, tangent) if self.fused else None
        Pbar, A = response if response is not None else self.materials.evaluate(Fbar, None, tangent)[:2]
        if not np.all(np.isfinite(Pbar)):
            raise NonPositiveJacobianError(np.flatnonzero(~np.isfinite(Pbar).all(axis=(0, 1, 2))), step, t, self.name)
        # one compiled signature: contiguous arrays throughout
        A = np.zeros((0, 0, 3, 3, 3, 3)) if A is None else np.ascontiguousarray(A)
        fe, ke = fbar_element_response(np.ascontiguousarray(F), np.ascontiguousarray(Pbar), A, sp_.dN, sp_.dx,
                                       tangent)
        internal = np.bincount(sp_.element_dofs.ravel(), fe.ravel(), minlength=sp_.n_dofs)
        return Contribution(internal=internal, blocks=[Blocks(sp_.element_dofs, ke if tangent else None)])

    def energy(self, u: np.ndarray, t: float) -> float | None:
        r""":math:`\Pi = \sum_e\sum_q w_q\,\psi(\bar F_q)` (module docstring), whose gradient is :meth:`assemble`'s
        internal force; ``inf`` where a Jacobian is not positive, ``None`` when a law has no energy."""
        F = self.deformation_gradient(u)
        if not np.all(determinant(F) > 0.0):
            return float("inf")
        W = self.materials.energy_density(fbar_deformation(F, self.space.dx)[0])
        return None if W is None else float(np.sum(W.T * self.space.dx))

    def commit(self) -> None:
        for region in self.materials.regions:
            getattr(region.material, "commit", lambda: None)()

    def rewind(self) -> None:
        for region in self.materials.regions:
            getattr(region.material, "rewind", lambda: None)()
