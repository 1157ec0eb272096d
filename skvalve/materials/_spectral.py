r"""Exact derivatives of :math:`T(C) = \operatorname{tr} C^q` for symmetric positive-definite C.

With the spectral decomposition :math:`C = \sum_a c_a N_a\otimes N_a` the trace of a
matrix power and its derivatives are

.. math::

    T = \sum_a c_a^q, \qquad \frac{\partial T}{\partial C} = q\,C^{q-1}, \qquad
    \frac{\partial (q C^{q-1})_{IJ}}{\partial C_{KL}}
        = \sum_{a,b} h[c_a, c_b]\, N_{aI} N_{bJ}\, \tfrac12 (N_{aK} N_{bL} + N_{aL} N_{bK}),

where :math:`h(x) = q x^{q-1}` and :math:`h[x, y] = (h(x) - h(y))/(x - y)` is its
divided difference, :math:`h[x, x] = h'(x)` (the Daleckii–Krein formula for the
derivative of a matrix function). Because equal eigenvalues get equal divided
differences, the sum is independent of the (arbitrary) eigenvectors of a repeated
eigenvalue, so the formula is exact at :math:`c_1 = c_2` and at :math:`C = I` too.
The divided difference of a power is evaluated without cancellation as

.. math::

    \frac{x^p - y^p}{x - y} = x^{p-1}\,\frac{\operatorname{expm1}(p t)}{\operatorname{expm1}(t)},
    \qquad t = \ln(y/x),

whose limit for :math:`t\to 0` is :math:`p\,x^{p-1}`.
"""

from __future__ import annotations

import numpy as np

from ..kinematics import Array

__all__ = ["symmetric_eigen", "power_divided_difference", "trace_power_derivatives"]


def symmetric_eigen(C: Array) -> tuple[Array, Array]:
    """Eigenvalues ``(3, *batch)`` and eigenvectors ``(3, 3, *batch)`` (column ``a`` = ``N_a``)."""
    w, v = np.linalg.eigh(np.moveaxis(C, (0, 1), (-2, -1)))
    return np.moveaxis(w, -1, 0), np.moveaxis(v, (-2, -1), (0, 1))


def power_divided_difference(x: Array, y: Array, p: float) -> Array:
    r""":math:`(x^p - y^p)/(x - y)` for positive x, y; :math:`p x^{p-1}` where x = y."""
    t = np.log(y / x)
    denom = np.expm1(t)
    same = denom == 0.0
    ratio = np.where(same, p, np.expm1(p * t) / np.where(same, 1.0, denom))
    return x ** (p - 1.0) * ratio


def trace_power_derivatives(
    eigenvalues: Array, vectors: Array, q: float, second: bool = True
) -> tuple[Array, Array, Array | None]:
    r"""``(T, dT/dC, d²T/dC²)`` for :math:`T = \operatorname{tr} C^q` (last None unless ``second``)."""
    c = eigenvalues
    T = np.sum(c**q, axis=0)
    dT = np.einsum("Ia...,a...,Ja...->IJ...", vectors, q * c ** (q - 1.0), vectors)
    if not second:
        return T, dT, None
    h = q * power_divided_difference(c[:, None], c[None, :], q - 1.0)  # (3, 3, *batch)
    half = np.einsum("ab...,Ia...,Jb...,Ka...,Lb...->IJKL...", h, vectors, vectors, vectors, vectors, optimize=True)
    d2T = 0.5 * (half + np.swapaxes(half, 2, 3))
    return T, dT, d2T
