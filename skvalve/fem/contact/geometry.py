r"""Geometry of a node over a triangle, with first and second derivatives (for :mod:`skvalve.fem.contact`).

A node :math:`x_s` over the triangle :math:`(x_1, x_2, x_3)`; with :math:`d = x_s - x_1`, :math:`a = x_2 - x_1`,
:math:`b = x_3 - x_1`:

* the **gap** :math:`g = d\cdot n`, :math:`n = a\times b/|a\times b|`, the signed distance from the triangle's plane
  (:func:`gap_derivatives`; its derivatives are in :mod:`skvalve.fem.contact`);
* the **barycentric coordinates** :math:`(1-\xi-\eta, \xi, \eta)` of the node's projection on that plane
  (:func:`barycentric_derivatives`). From :math:`d = \xi a + \eta b + g n`, crossing with :math:`b` and :math:`a`
  and the Binet–Cauchy identity,

  .. math::

      \xi = \frac{(d\cdot a)(b\cdot b) - (d\cdot b)(a\cdot b)}{D},\qquad
      \eta = \frac{(a\cdot a)(d\cdot b) - (a\cdot b)(d\cdot a)}{D},\qquad D = (a\cdot a)(b\cdot b) - (a\cdot b)^2,

  rational functions of the five dot products :math:`q = (a\cdot a, b\cdot b, a\cdot b, d\cdot a, d\cdot b)`.
  For :math:`f = N/D`: :math:`f_{,q} = (N_{,q} - f D_{,q})/D`,
  :math:`f_{,qq} = (N_{,qq} - f_{,q}\otimes D_{,q} - D_{,q}\otimes f_{,q} - f D_{,qq})/D`, and by the chain rule
  :math:`\nabla f = f_{,q}\nabla q`, :math:`\nabla^2 f = \nabla q^T f_{,qq}\nabla q + f_{,q_k}\nabla^2 q_k`, where
  :math:`\nabla q` is linear in the coordinates and :math:`\nabla^2 q_k` is constant.
* the **smooth step** :math:`S(t) = 6t^5 - 15t^4 + 10t^3` on :math:`[0, 1]` (0 below, 1 above; :math:`C^2`,
  :math:`S(t) + S(1-t) = 1`), used to blend pairs across triangle edges.

Derivatives are with respect to the twelve coordinates :math:`[x_s, x_1, x_2, x_3]`.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["barycentric", "barycentric_derivatives", "gap_derivatives", "near_pairs", "plane_gap", "smooth_step"]


def near_pairs(points: np.ndarray, centres: np.ndarray, radius) -> tuple[np.ndarray, np.ndarray]:
    """Every (point, centre) index pair with the point within the centre's own ``radius`` (a scalar or one per
    centre), sorted by point, then centre: a k-d tree of the points queried at the centres (one radius for all, the
    largest, listed millions of candidates on a valve surface whose triangles differ in size)."""
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (len(centres),))
    lists = cKDTree(points).query_ball_point(centres, radius)
    counts = np.fromiter((len(item) for item in lists), dtype=np.int64, count=len(lists))
    if counts.sum() == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    centre = np.repeat(np.arange(len(centres)), counts)
    point = np.concatenate([np.asarray(item, dtype=np.int64) for item in lists if item])
    order = np.lexsort((centre, point))
    return point[order], centre[order]


def plane_gap(xs: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Gap :math:`g = (x_s - x_1)\cdot n` (n,) of points ``xs`` (n, 3) over the planes of triangles ``corners``
    (n, 3, 3), and the unit normals ``n`` (n, 3); without derivatives (:func:`gap_derivatives` has them)."""
    m = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal = m / np.linalg.norm(m, axis=1, keepdims=True)
    return np.einsum("ij,ij->i", xs - corners[:, 0], normal), normal


def gap_derivatives(xs: np.ndarray, x1: np.ndarray, x2: np.ndarray, x3: np.ndarray, hessian: bool = True):
    """Gap ``g`` (n,), gradient (n, 12) and Hessian (n, 12, 12) w.r.t. ``[xs, x1, x2, x3]``
    (:mod:`skvalve.fem.contact` docstring)."""
    d, a, b = xs - x1, x2 - x1, x3 - x1
    m = np.cross(a, b)
    mu = np.linalg.norm(m, axis=1)
    n = m / mu[:, None]
    g = np.einsum("ij,ij->i", d, n)
    Pd = d - g[:, None] * n
    w = Pd / mu[:, None]
    grad_dab = np.hstack([n, np.cross(b, w), np.cross(w, a)])  # w.r.t. (d, a, b)
    grad = grad_dab @ _CHAIN
    if not hessian:
        return g, grad, None
    eye = np.eye(3)
    P = eye - n[:, :, None] * n[:, None, :]
    H_mm = -(g[:, None, None] * P + n[:, :, None] * Pd[:, None, :] + Pd[:, :, None] * n[:, None, :]) \
        / (mu**2)[:, None, None]
    J_m = np.concatenate([-_skew(b), _skew(a)], axis=2)  # (n, 3, 6): dm/d(a, b)
    H = np.zeros((xs.shape[0], 9, 9))
    H[:, :3, 3:] = (P / mu[:, None, None]) @ J_m
    H[:, 3:, :3] = H[:, :3, 3:].transpose(0, 2, 1)
    H[:, 3:, 3:] = J_m.transpose(0, 2, 1) @ H_mm @ J_m
    M = np.einsum("ijk,nk->nij", _LEVI_CIVITA, w)  # d2g/da_i db_j from the bilinear m = a x b
    H[:, 3:6, 6:] += M
    H[:, 6:, 3:6] += M.transpose(0, 2, 1)
    return g, grad, _CHAIN.T @ H @ _CHAIN


def barycentric(p: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Barycentric coordinates (n, 3) of points ``p`` (n, 3) projected on the planes of triangles ``c`` (n, 3, 3)."""
    q = _dot_products(p - c[:, 0], c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    xi, eta, _ = _ratio_values(q)
    return np.column_stack([1.0 - xi - eta, xi, eta])


def barycentric_derivatives(xs: np.ndarray, x1: np.ndarray, x2: np.ndarray, x3: np.ndarray, hessian: bool = True):
    """Barycentric coordinates ``lam`` (n, 3) of the projection of ``xs`` on the triangle's plane, their gradients
    (n, 3, 12) and Hessians (n, 3, 12, 12, ``None`` without ``hessian``) w.r.t. ``[xs, x1, x2, x3]`` (module
    docstring)."""
    d, a, b = xs - x1, x2 - x1, x3 - x1
    q = _dot_products(d, a, b)
    n = q.shape[0]
    zero = np.zeros(n)
    one = np.ones(n)
    # derivatives of the numerators and of D w.r.t. q = (aa, bb, ab, da, db)
    N1_q = np.column_stack([zero, q[:, 3], -q[:, 4], q[:, 1], -q[:, 2]])
    N2_q = np.column_stack([q[:, 4], zero, -q[:, 3], -q[:, 2], q[:, 0]])
    D_q = np.column_stack([q[:, 1], q[:, 0], -2.0 * q[:, 2], zero, zero])
    xi, eta, D = _ratio_values(q)
    # dq/dz (n, 5, 9), z = (d, a, b)
    dq = np.zeros((n, 5, 9))
    dq[:, 0, 3:6] = 2.0 * a
    dq[:, 1, 6:9] = 2.0 * b
    dq[:, 2, 3:6], dq[:, 2, 6:9] = b, a
    dq[:, 3, 0:3], dq[:, 3, 3:6] = a, d
    dq[:, 4, 0:3], dq[:, 4, 6:9] = b, d
    lam = np.column_stack([one - xi - eta, xi, eta])
    grad = np.zeros((n, 3, 12))
    hess = np.zeros((n, 3, 12, 12)) if hessian else None
    for k, (f, N_q, N_qq) in enumerate(((xi, N1_q, _N1_QQ), (eta, N2_q, _N2_QQ)), start=1):
        f_q = (N_q - f[:, None] * D_q) / D[:, None]
        grad[:, k] = np.einsum("nk,nkj->nj", f_q, dq) @ _CHAIN
        if hessian:
            f_qq = (N_qq[None] - f_q[:, :, None] * D_q[:, None, :] - D_q[:, :, None] * f_q[:, None, :]
                    - f[:, None, None] * _D_QQ[None]) / D[:, None, None]
            h9 = np.einsum("nki,nkl,nlj->nij", dq, f_qq, dq) + np.einsum("nk,kij->nij", f_q, _Q_HESSIAN)
            hess[:, k] = _CHAIN.T @ h9 @ _CHAIN
    grad[:, 0] = -grad[:, 1] - grad[:, 2]
    if hessian:
        hess[:, 0] = -hess[:, 1] - hess[:, 2]
    return lam, grad, hess


def smooth_step(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:math:`S(t) = 6t^5 - 15t^4 + 10t^3` clipped to [0, 1], with :math:`S'` and :math:`S''`."""
    t = np.clip(t, 0.0, 1.0)
    value = t**3 * (10.0 + t * (-15.0 + 6.0 * t))
    first = 30.0 * t**2 * (1.0 - t) ** 2
    second = 60.0 * t * (1.0 - t) * (1.0 - 2.0 * t)
    return value, first, second


def _dot_products(d: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """q = (a.a, b.b, a.b, d.a, d.b), shape (n, 5)."""
    return np.column_stack([np.einsum("ij,ij->i", u, v) for u, v in ((a, a), (b, b), (a, b), (d, a), (d, b))])


def _ratio_values(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """xi, eta and their denominator D from the dot products q (module docstring)."""
    D = q[:, 0] * q[:, 1] - q[:, 2] ** 2
    return (q[:, 3] * q[:, 1] - q[:, 4] * q[:, 2]) / D, (q[:, 0] * q[:, 4] - q[:, 2] * q[:, 3]) / D, D


def _symmetric_5(entries: dict[tuple[int, int], float]) -> np.ndarray:
    H = np.zeros((5, 5))
    for (i, j), value in entries.items():
        H[i, j] = H[j, i] = value
    return H


# second derivatives w.r.t. q of N1 = da bb - db ab, N2 = aa db - ab da and D = aa bb - ab^2
_N1_QQ = _symmetric_5({(1, 3): 1.0, (2, 4): -1.0})
_N2_QQ = _symmetric_5({(0, 4): 1.0, (2, 3): -1.0})
_D_QQ = _symmetric_5({(0, 1): 1.0, (2, 2): -2.0})


def _q_hessians() -> np.ndarray:
    """(5, 9, 9) constant Hessians of q w.r.t. z = (d, a, b)."""
    eye = np.eye(3)
    d, a, b = slice(0, 3), slice(3, 6), slice(6, 9)
    H = np.zeros((5, 9, 9))
    H[0, a, a] = 2.0 * eye
    H[1, b, b] = 2.0 * eye
    H[2, a, b] = H[2, b, a] = eye
    H[3, d, a] = H[3, a, d] = eye
    H[4, d, b] = H[4, b, d] = eye
    return H


_Q_HESSIAN = _q_hessians()

_LEVI_CIVITA = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_i, _j, _k], _LEVI_CIVITA[_i, _k, _j] = 1.0, -1.0


def _skew(v: np.ndarray) -> np.ndarray:
    """[v]_x with [v]_x y = v x y, shape (n, 3, 3)."""
    return -np.einsum("ijk,nk->nij", _LEVI_CIVITA, v)


def _chain_matrix() -> np.ndarray:
    """(9, 12) map from node coordinates [xs, x1, x2, x3] to (d, a, b) = (xs - x1, x2 - x1, x3 - x1)."""
    eye = np.eye(3)
    T = np.zeros((9, 12))
    T[0:3, 0:3], T[0:3, 3:6] = eye, -eye
    T[3:6, 6:9], T[3:6, 3:6] = eye, -eye
    T[6:9, 9:12], T[6:9, 3:6] = eye, -eye
    return T


_CHAIN = _chain_matrix()
