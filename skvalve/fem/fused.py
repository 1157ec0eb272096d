r"""Stress, tangent and element matrices in one compiled pass per element, for every law.

A law hands over scalar derivatives of its energy (:mod:`skvalve.materials.derivatives`); the
tensor algebra is written once here. Per quadrature point the kernel forms
:math:`P = \partial\psi/\partial F` and :math:`\mathbb{A} = \partial P/\partial F` and adds them into
the element forces and stiffness of :mod:`skvalve.fem.kernels` (same layout, node-major local dofs):
:math:`f_{ai} \mathrel{+}= w\,P_{iJ}N_{a,J}`, :math:`K_{ai,bk} \mathrel{+}= w\,N_{a,J}\mathbb{A}_{iJkL}N_{b,L}`.

**Invariant laws** :math:`\psi(\bar I_1, J, I_4)`. With :math:`G = C^{-1}`, :math:`H = FG = F^{-T}`,
:math:`E_1 = \partial\bar I_1/\partial C = J^{-2/3}(I - \tfrac{I_1}{3}G)`,
:math:`E_J = \partial J/\partial C = \tfrac J2 G`,
:math:`E_4 = a\otimes a` (:mod:`skvalve.materials.isotropic`):

.. math::

    S = 2(\psi_{,1}E_1 + \psi_{,J}E_J + \psi_{,4}E_4),\qquad
    \mathbb{A}_{iJkL} = \delta_{ik}S_{JL} + F_{iI}F_{kK}\mathbb{C}_{IJKL}.

The push-forward of :math:`\mathbb{C}/4 = \sum \psi_{,xy}E_x\otimes E_y + \psi_{,1}\partial^2\bar I_1/\partial C^2
+ \psi_{,J}\partial^2 J/\partial C^2` is evaluated in closed form: :math:`F E_1 = J^{-2/3}(F - \tfrac{I_1}{3}H)`,
:math:`F E_J = \tfrac J2 H`, :math:`F E_4 = (Fa)\otimes a`, and the only non-dyadic term,
:math:`\mathbb{G}_{IJKL} = \tfrac12(G_{IK}G_{JL} + G_{IL}G_{JK})`, pushes to
:math:`\tfrac12(\delta_{ik}G_{JL} + H_{iL}H_{kJ})` because :math:`FGF^T = I`. Hence, with the dyads
:math:`b \in \{F, H, (Fa)\otimes a\}`,

.. math::

    \mathbb{A}_{iJkL} = \delta_{ik}(S_{JL} + 2\gamma G_{JL}) + 4\sum_{m,n} M_{mn}\,b^m_{iJ}b^n_{kL}
                        + 2\gamma H_{iL}H_{kJ},\qquad
    \gamma = \tfrac{\bar I_1}{3}\psi_{,1} - \tfrac J2\psi_{,J},

where the symmetric 3×3 matrix :math:`M` collects the coefficients (see :func:`_invariant_point`).

**Principal-value laws** :math:`\psi(c_1, c_2, c_3)`, :math:`C = \sum_a c_a N_a\otimes N_a` (Ogden). With
:math:`n_a = FN_a`, :math:`S = 2\sum_a \psi_{,a}N_a\otimes N_a` and

.. math::

    \mathbb{A}_{iJkL} = \delta_{ik}S_{JL} + 4\sum_{a,b}\psi_{,ab}\,n_{ai}N_{aJ}n_{bk}N_{bL}
        + 2\sum_{a\ne b}\Theta_{ab}\,n_{ai}N_{bJ}(n_{ak}N_{bL} + n_{bk}N_{aL}),\qquad
    \Theta_{ab} = \frac{\psi_{,a} - \psi_{,b}}{c_a - c_b},

the derivative of :math:`\sum_a\psi_{,a}N_a\otimes N_a` (Daleckii–Krein); for
:math:`|c_a - c_b| \le 10^{-8}(c_a + c_b)` the limit :math:`\Theta_{ab} = \psi_{,aa} - \psi_{,ab}` is used,
which makes the result independent of the eigenvectors of a repeated eigenvalue.

**Mixed u/p** (:mod:`skvalve.fem.constitutive`): with the pressure :math:`p` at the points,
:math:`P \mathrel{-}= p\operatorname{cof}F`, :math:`\mathbb{A} \mathrel{-}= pJ(H_{iJ}H_{kL} - H_{iL}H_{kJ})`,
:math:`K_{up} = -\int N_{a,J}(\operatorname{cof}F)_{iJ}N^p_\beta`, and when :math:`\bar J` and the compliance
:math:`1/U''(\bar J)` are given, :math:`f_p = \int N^p_\alpha(\bar J - J)` and
:math:`K_{pp} = -\int N^p_\alpha\,U''^{-1}N^p_\beta`.

Verified against the generic path (``law.pk1_and_tangent`` + :mod:`skvalve.fem.kernels`) in
``tests/test_fem_fused.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from ..kinematics import determinant
from ..materials.base import Hyperelastic
from ..materials.derivatives import InvariantDerivatives, PrincipalDerivatives
from .constitutive import MaterialRegions, invert_volumetric

__all__ = ["FusedLaw", "FusedResponse", "MixedFields", "fused_response", "assemble_regions"]

_INVARIANT, _PRINCIPAL = 0, 1


@dataclass(frozen=True)
class MixedFields:
    """Pressure-field data of a mixed u/p element at the quadrature points.

    ``pressure`` (nqp, nel); ``Np`` (nel, nqp, nbp) pressure shape functions; ``Jbar`` and
    ``compliance`` (nqp, nel), :math:`\\bar J(p)` and :math:`1/U''(\\bar J)` (zero when incompressible),
    or ``None`` to leave the pressure rows of forces and stiffness to the caller.
    """

    pressure: np.ndarray
    Np: np.ndarray
    Jbar: np.ndarray | None = None
    compliance: np.ndarray | None = None


@dataclass(frozen=True)
class FusedResponse:
    """``P`` (3,3,nqp,nel) total PK1 stress; ``forces`` (nel, ndofe); ``stiffness`` (nel, ndofe, ndofe) or None."""

    P: np.ndarray
    forces: np.ndarray
    stiffness: np.ndarray | None


# ----------------------------------------------------------------------------- kernel


@njit(cache=True, inline="always", error_model="numpy")
def _inverse_transpose(F, H):
    """H = F^{-T}; returns det F."""
    a, b, c = F[0, 0], F[0, 1], F[0, 2]
    d, f, g = F[1, 0], F[1, 1], F[1, 2]
    h, k, m = F[2, 0], F[2, 1], F[2, 2]
    J = a * (f * m - g * k) - b * (d * m - g * h) + c * (d * k - f * h)
    H[0, 0], H[1, 0], H[2, 0] = (f * m - g * k) / J, (c * k - b * m) / J, (b * g - c * f) / J
    H[0, 1], H[1, 1], H[2, 1] = (g * h - d * m) / J, (a * m - c * h) / J, (c * d - a * g) / J
    H[0, 2], H[1, 2], H[2, 2] = (d * k - f * h) / J, (b * h - a * k) / J, (a * f - b * d) / J
    return J


@njit(cache=True, error_model="numpy")
def _invariant_point(F, H, J, D, a, has_direction, S, A, tangent, G, M, B):
    """S and A at one point of a law psi(I1bar, J, I4); D = (d1, dJ, d11, d1J, dJJ, d4, d14, dJ4, d44).

    G (3,3), M (3,3), B (3,3,3) are scratch arrays: C^{-1} = H^T H, the dyad coefficients and the dyads.
    """
    d1, dJ, d11, d1J, dJJ, d4, d14, dJ4, d44 = D[0], D[1], D[2], D[3], D[4], D[5], D[6], D[7], D[8]
    I1 = 0.0
    for I in range(3):
        for K in range(3):
            s = 0.0
            t = 0.0
            for i in range(3):
                s += H[i, I] * H[i, K]
                t += F[i, I] * F[i, K]
            G[I, K] = s
            if I == K:
                I1 += t
    Jm23 = J ** (-2.0 / 3.0)
    I1bar = Jm23 * I1
    for I in range(3):
        for K in range(3):
            S[I, K] = 2.0 * d1 * Jm23 * ((1.0 if I == K else 0.0) - I1 / 3.0 * G[I, K]) + dJ * J * G[I, K]
            if has_direction:
                S[I, K] += 2.0 * d4 * a[I] * a[K]
    if not tangent:
        return
    # F E1 = alpha1 F + beta1 H, F EJ = betaJ H, F E4 = (F a) x a
    alpha1, beta1, betaJ = Jm23, -Jm23 * I1 / 3.0, 0.5 * J
    M[:] = 0.0  # coefficients of b_m (x) b_n, b = (F, H, (Fa) x a)
    M[0, 0] = d11 * alpha1 * alpha1
    M[0, 1] = d11 * alpha1 * beta1 + d1J * alpha1 * betaJ - d1 * Jm23 / 3.0
    M[1, 1] = (d11 * beta1 * beta1 + 2.0 * d1J * beta1 * betaJ + dJJ * betaJ * betaJ + d1 * I1bar / 9.0
               + dJ * J / 4.0)
    gamma = d1 * I1bar / 3.0 - dJ * J / 2.0
    nb = 2
    for i in range(3):
        for j in range(3):
            B[0, i, j] = F[i, j]
            B[1, i, j] = H[i, j]
    if has_direction:
        nb = 3
        M[0, 2] = d14 * alpha1
        M[1, 2] = d14 * beta1 + dJ4 * betaJ
        M[2, 2] = d44
        for i in range(3):
            Fa = F[i, 0] * a[0] + F[i, 1] * a[1] + F[i, 2] * a[2]
            for j in range(3):
                B[2, i, j] = Fa * a[j]
    for m in range(nb):
        for n in range(m):
            M[m, n] = M[n, m]
    for i in range(3):
        for j in range(3):
            # y_kL = 4 sum_mn M_mn b^m_ij b^n_kL: first contract m
            c0 = 0.0
            c1 = 0.0
            c2 = 0.0
            for m in range(nb):
                bm = B[m, i, j]
                c0 += M[m, 0] * bm
                c1 += M[m, 1] * bm
                c2 += M[m, 2] * bm
            for k in range(3):
                for L in range(3):
                    v = 4.0 * (c0 * B[0, k, L] + c1 * B[1, k, L])
                    if nb == 3:
                        v += 4.0 * c2 * B[2, k, L]
                    v += 2.0 * gamma * H[i, L] * H[k, j]
                    if i == k:
                        v += S[j, L] + 2.0 * gamma * G[j, L]
                    A[i, j, k, L] = v


@njit(cache=True, error_model="numpy")
def _principal_point(F, D, V, S, A, tangent, c, n, theta):
    """S and A at one point of a law psi(c1, c2, c3); D = (psi_a (3), psi_ab (9)), V[:, a] = N_a.

    c (3), n (3,3), theta (3,3) are scratch arrays: eigenvalues, n[:, a] = F N_a, divided differences.
    """
    for a in range(3):
        s = 0.0
        for i in range(3):
            v = F[i, 0] * V[0, a] + F[i, 1] * V[1, a] + F[i, 2] * V[2, a]
            n[i, a] = v
            s += v * v
        c[a] = s
    for I in range(3):
        for K in range(3):
            s = 0.0
            for a in range(3):
                s += D[a] * V[I, a] * V[K, a]
            S[I, K] = 2.0 * s
    if not tangent:
        return
    for a in range(3):
        theta[a, a] = 0.0
        for b in range(3):
            if a != b:
                if abs(c[a] - c[b]) <= 1e-8 * (c[a] + c[b]):
                    theta[a, b] = D[3 + 3 * a + a] - D[3 + 3 * a + b]
                else:
                    theta[a, b] = (D[a] - D[b]) / (c[a] - c[b])
    for i in range(3):
        for j in range(3):
            for k in range(3):
                for L in range(3):
                    v = S[j, L] if i == k else 0.0
                    for a in range(3):
                        for b in range(3):
                            v += 4.0 * D[3 + 3 * a + b] * n[i, a] * V[j, a] * n[k, b] * V[L, b]
                            if a != b:
                                v += 2.0 * theta[a, b] * n[i, a] * V[j, b] * (n[k, a] * V[L, b] + n[k, b] * V[L, a])
                    A[i, j, k, L] = v


@njit(parallel=True, cache=True, error_model="numpy")
def _fused_kernel(kind, F, D, aux, has_direction, dN, dx, tangent, pressure, Np, Jbar, compliance, ndofe):
    nel, nqp, nb, dim = dN.shape
    nbp = Np.shape[2]
    mixed = pressure.shape[0] > 0
    volumetric = Jbar.shape[0] > 0
    nu = nb * dim
    P = np.empty((3, 3, nqp, nel))
    fe = np.zeros((nel, ndofe))
    ke = np.zeros((nel if tangent else 0, ndofe, ndofe))
    for e in prange(nel):
        Fq = np.empty((3, 3))
        H = np.empty((3, 3))
        S = np.empty((3, 3))
        Pq = np.empty((3, 3))
        A = np.zeros((3, 3, 3, 3))
        Gw = np.empty((nb, dim, dim, dim))
        Dq = np.empty(D.shape[0])
        Vq = np.empty((3, 3))
        aq = np.zeros(3)
        G3 = np.empty((3, 3))
        M3 = np.empty((3, 3))
        B3 = np.empty((3, 3, 3))
        c3 = np.empty(3)
        for q in range(nqp):
            for i in range(3):
                for j in range(3):
                    Fq[i, j] = F[i, j, q, e]
            for r in range(D.shape[0]):
                Dq[r] = D[r, q, e]
            J = _inverse_transpose(Fq, H)
            if kind == _INVARIANT:
                if has_direction:
                    for i in range(3):
                        aq[i] = aux[i, 0, q, e]
                _invariant_point(Fq, H, J, Dq, aq, has_direction, S, A, tangent, G3, M3, B3)
            else:
                for i in range(3):
                    for j in range(3):
                        Vq[i, j] = aux[i, j, q, e]
                _principal_point(Fq, Dq, Vq, S, A, tangent, c3, M3, G3)
            for i in range(3):
                for j in range(3):
                    s = 0.0
                    for K in range(3):
                        s += Fq[i, K] * S[K, j]
                    Pq[i, j] = s
            if mixed:
                p = pressure[q, e]
                for i in range(3):
                    for j in range(3):
                        Pq[i, j] -= p * J * H[i, j]
                if tangent:
                    pJ = p * J
                    for i in range(3):
                        for j in range(3):
                            for k in range(3):
                                for L in range(3):
                                    A[i, j, k, L] -= pJ * (H[i, j] * H[k, L] - H[i, L] * H[k, j])
            for i in range(3):
                for j in range(3):
                    P[i, j, q, e] = Pq[i, j]
            w = dx[e, q]
            for a in range(nb):
                for i in range(dim):
                    s = 0.0
                    for J_ in range(dim):
                        s += Pq[i, J_] * dN[e, q, a, J_]
                    fe[e, a * dim + i] += w * s
            if mixed:
                for al in range(nbp):
                    if volumetric:
                        fe[e, nu + al] += w * Np[e, q, al] * (Jbar[q, e] - J)
            if not tangent:
                continue
            # G[a,i,k,L] = w dN[a,J] A[i,J,k,L]; K[ai,bk] += G[a,i,k,L] dN[b,L] (upper triangle)
            for a in range(nb):
                for i in range(dim):
                    for k in range(dim):
                        for L in range(dim):
                            s = 0.0
                            for J_ in range(dim):
                                s += dN[e, q, a, J_] * A[i, J_, k, L]
                            Gw[a, i, k, L] = w * s
            for a in range(nb):
                for i in range(dim):
                    row = a * dim + i
                    for b in range(a, nb):
                        for k in range(dim):
                            col = b * dim + k
                            if col < row:
                                continue
                            s = 0.0
                            for L in range(dim):
                                s += Gw[a, i, k, L] * dN[e, q, b, L]
                            ke[e, row, col] += s
            if mixed:
                for a in range(nb):
                    for i in range(dim):
                        s = 0.0
                        for J_ in range(dim):
                            s += J * H[i, J_] * dN[e, q, a, J_]
                        for al in range(nbp):
                            ke[e, a * dim + i, nu + al] -= w * s * Np[e, q, al]
                if volumetric:
                    for al in range(nbp):
                        for be in range(al, nbp):
                            ke[e, nu + al, nu + be] -= w * compliance[q, e] * Np[e, q, al] * Np[e, q, be]
        if tangent:
            for row in range(ndofe):
                for col in range(row + 1, ndofe):
                    ke[e, col, row] = ke[e, row, col]
    return P, fe, ke


# ------------------------------------------------------------------------- interface


def _defines_before(cls: type, method: str, other: str) -> bool:
    """True when ``method`` is defined on ``cls`` at least as deep as ``other`` in its MRO."""
    mro = cls.__mro__
    owner = next((k for k in mro if method in vars(k)), None)
    other_owner = next((k for k in mro if other in vars(k)), None)
    return owner is not None and (other_owner is None or mro.index(owner) <= mro.index(other_owner))


class FusedLaw:
    """Compiled stress/tangent/element assembly for one law (see :func:`fused_response`)."""

    def __init__(self, law: Hyperelastic, kind: int) -> None:
        self.law = law
        self.kind = kind

    def _derivatives(self, F: np.ndarray):
        law = self.law
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        batch = F.shape[2:]
        if self.kind == _INVARIANT:
            J = determinant(F)
            I1bar = J ** (-2.0 / 3.0) * (C[0, 0] + C[1, 1] + C[2, 2])
            d: InvariantDerivatives = law.invariant_derivatives(I1bar, J, C)
            values = (d.d_1, d.d_J, d.d_11, d.d_1J, d.d_JJ, d.d_4, d.d_14, d.d_J4, d.d_44)
            D = np.stack([np.broadcast_to(np.asarray(v, dtype=float), batch) for v in values])
            if d.direction is None:
                return D, np.zeros((3, 1, 1, 1)), False
            direction = np.broadcast_to(np.asarray(d.direction, dtype=float), (3,) + batch)
            return D, np.ascontiguousarray(direction[:, None]), True
        w, v = np.linalg.eigh(np.moveaxis(C, (0, 1), (-2, -1)))
        c = np.moveaxis(w, -1, 0)
        vectors = np.ascontiguousarray(np.moveaxis(v, (-2, -1), (0, 1)))
        d: PrincipalDerivatives = law.principal_derivatives(c)
        D = np.concatenate([np.broadcast_to(d.first, (3,) + batch),
                            np.broadcast_to(d.second, (3, 3) + batch).reshape((9,) + batch)])
        return np.ascontiguousarray(D), vectors, False

    def __call__(self, F: np.ndarray, dN: np.ndarray, dx: np.ndarray, tangent: bool = True,
                 mixed: MixedFields | None = None, ndofe: int | None = None) -> FusedResponse:
        """Element forces and stiffness for ``F`` (3,3,nqp,nel) on a displacement space ``dN``, ``dx``.

        ``dN`` (nel, nqp, nb, dim) reference shape-function gradients, ``dx`` (nel, nqp) weights
        (quadrature weight times reference Jacobian). Local dofs are node-major (``a*dim + i``),
        pressure dofs of ``mixed`` after them; ``ndofe`` defaults to ``nb*dim + nbp``.
        """
        F = np.ascontiguousarray(F, dtype=float)
        nel, nqp, nb, dim = dN.shape
        if F.shape != (3, 3, nqp, nel) or dx.shape != (nel, nqp):
            raise ValueError(f"F must have shape (3, 3, {nqp}, {nel}) and dx ({nel}, {nqp}); got {F.shape}, "
                             f"{dx.shape}")
        D, aux, has_direction = self._derivatives(F)
        empty2 = np.zeros((0, 0))
        if mixed is None:
            pressure, Np, Jbar, compliance = empty2, np.zeros((nel, nqp, 0)), empty2, empty2
        else:
            pressure, Np = np.ascontiguousarray(mixed.pressure, float), np.ascontiguousarray(mixed.Np, float)
            volumetric = mixed.Jbar is not None
            Jbar = np.ascontiguousarray(mixed.Jbar, float) if volumetric else empty2
            compliance = np.ascontiguousarray(mixed.compliance, float) if volumetric else empty2
        if ndofe is None:
            ndofe = nb * dim + Np.shape[2]
        P, fe, ke = _fused_kernel(self.kind, F, np.ascontiguousarray(D), aux, has_direction,
                                  np.ascontiguousarray(dN, float), np.ascontiguousarray(dx, float), bool(tangent),
                                  pressure, Np, Jbar, compliance, int(ndofe))
        return FusedResponse(P, fe, ke if tangent else None)


def fused_response(law) -> FusedLaw | None:
    """The compiled evaluator of ``law``, or ``None`` when the law has no fused form (use the generic path).

    A law qualifies when it supplies ``invariant_derivatives`` (laws of :math:`\\bar I_1, J, I_4`) or
    ``principal_derivatives`` (laws of the principal values of C) at least as specific as its stress
    (a subclass that overrides ``response_C`` without them falls back to the generic path).
    """
    cls = type(law)
    if not isinstance(law, Hyperelastic):
        return None
    if hasattr(law, "invariant_derivatives") and _defines_before(cls, "invariant_derivatives", "response_C") \
            and _defines_before(cls, "invariant_derivatives", "stress_C"):
        return FusedLaw(law, _INVARIANT)
    if hasattr(law, "principal_derivatives") and _defines_before(cls, "principal_derivatives", "response_C"):
        return FusedLaw(law, _PRINCIPAL)
    return None


def assemble_regions(materials: MaterialRegions, F: np.ndarray, space, tangent: bool,
                     pressure: np.ndarray | None = None) -> FusedResponse | None:
    """Every material region of ``materials`` through the fused kernel, or ``None`` if one region has no fused form.

    ``space`` provides ``dN``, ``dx``, ``nel``, ``ndofe`` and, for the mixed formulation (``pressure``
    (nqp, nel) given), ``Np``; the result holds the full element forces and stiffness of the solid
    term including the pressure rows (:math:`\bar J - J` and :math:`-1/U''` blocks).
    """
    fused = [fused_response(region.law) for region in materials.regions]
    if any(f is None for f in fused):
        return None
    nel, nqp = space.nel, space.dx.shape[1]
    single = len(materials.regions) == 1 and isinstance(materials.regions[0].elements, slice)
    P = None if single else np.empty((3, 3, nqp, nel))
    forces = None if single else np.empty((nel, space.ndofe))
    stiffness = None if single or not tangent else np.empty((nel, space.ndofe, space.ndofe))
    for region, evaluate in zip(materials.regions, fused, strict=True):
        els = region.elements
        mixed = None
        if pressure is not None:
            p = pressure[:, els]
            if region.volumetric is not None:
                Jbar, compliance = invert_volumetric(region.volumetric, p)
            else:
                Jbar, compliance = np.ones_like(p), np.zeros_like(p)
            mixed = MixedFields(p, space.Np[els], Jbar, compliance)
        response = evaluate(F[:, :, :, els], space.dN[els], space.dx[els], tangent, mixed, space.ndofe)
        if single:
            return response
        P[:, :, :, els] = response.P
        forces[els] = response.forces
        if tangent:
            stiffness[els] = response.stiffness
    return FusedResponse(P, forces, stiffness)
