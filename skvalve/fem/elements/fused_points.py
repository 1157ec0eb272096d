r"""Stress and tangent at one quadrature point from the scalar derivatives a law supplies (numba).

Used by the element kernel of :mod:`skvalve.fem.elements.fused`; every function works on one point and
writes into caller-provided scratch arrays.

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

where the symmetric 3×3 matrix :math:`M` collects the coefficients (see :func:`invariant_point`).

**Principal-value laws** :math:`\psi(c_1, c_2, c_3)`, :math:`C = \sum_a c_a N_a\otimes N_a` (Ogden). With
:math:`n_a = FN_a`, :math:`S = 2\sum_a \psi_{,a}N_a\otimes N_a` and

.. math::

    \mathbb{A}_{iJkL} = \delta_{ik}S_{JL} + 4\sum_{a,b}\psi_{,ab}\,n_{ai}N_{aJ}n_{bk}N_{bL}
        + 2\sum_{a\ne b}\Theta_{ab}\,n_{ai}N_{bJ}(n_{ak}N_{bL} + n_{bk}N_{aL}),\qquad
    \Theta_{ab} = \frac{\psi_{,a} - \psi_{,b}}{c_a - c_b},

the derivative of :math:`\sum_a\psi_{,a}N_a\otimes N_a` (Daleckii–Krein); for
:math:`|c_a - c_b| \le 10^{-8}(c_a + c_b)` the limit :math:`\Theta_{ab} = \psi_{,aa} - \psi_{,ab}` is used,
which makes the result independent of the eigenvectors of a repeated eigenvalue.
"""

from __future__ import annotations

from numba import njit

__all__ = ["inverse_transpose", "invariant_point", "principal_point"]


@njit(cache=True, inline="always", error_model="numpy")
def inverse_transpose(F, H):
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
def invariant_point(F, H, J, D, a, has_direction, S, A, tangent, G, M, B):
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
def principal_point(F, D, V, S, A, tangent, c, n, theta):
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
