r"""Marker-based transmural strain mapping (buchanan2014 Appendix 1, Eqs. 5–7).

Markers on the specimen edge have reference positions :math:`(X_1, X_2)` and deformed
positions :math:`(x_1, x_2)`. The displacements :math:`u = x_1 - X_1`, :math:`v = x_2 - X_2`
are fitted by least squares with the quadratic surface of Eq. 5,

.. math::  u \approx a_0 + a_1 X_1 + a_2 X_2 + a_3 X_1 X_2 + a_4 X_1^2 + a_5 X_2^2

(and the same with :math:`b_i` for :math:`v`), whose gradient gives Eq. 6,
:math:`F = I + \partial(u, v)/\partial(X_1, X_2)`, e.g.
:math:`F_{11} = 1 + a_1 + a_3 X_2 + 2 a_4 X_1`, :math:`F_{12} = a_2 + a_3 X_1 + 2 a_5 X_2`.

The polar decomposition :math:`F = RU` (Eq. 7) of a 2×2 :math:`F` with :math:`\det F > 0`
has a closed form: :math:`R` is the rotation by :math:`\alpha = \operatorname{atan2}(F_{21}
- F_{12}, F_{11} + F_{22})` — the angle that makes :math:`R^T F` symmetric — and
:math:`U = R^T F` (positive definite because :math:`\operatorname{tr} U = \sqrt{(F_{11}+F_{22})^2
+ (F_{21}-F_{12})^2} > 0` and :math:`\det U = \det F > 0`). :math:`\alpha` is the rigid
rotation angle of the appendix, the axial stretch is :math:`\Lambda_1 = \sqrt{U_{11}^2 + U_{12}^2}`
(Sect. 2.3), and the neutral axis is the :math:`X_2` where :math:`U_{11} = 1` along a
transverse line :math:`X_1 = \text{const}`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

__all__ = ["QuadraticStrainMap", "fit_strain_map", "polar_2d"]

Array = NDArray[np.float64]


def _design_matrix(X1: Array, X2: Array) -> Array:
    """Columns of Eq. 5: 1, X1, X2, X1·X2, X1², X2²."""
    return np.stack([np.ones_like(X1), X1, X2, X1 * X2, X1**2, X2**2], axis=-1)


def polar_2d(F: ArrayLike) -> tuple[Array, Array, Array]:
    """Closed-form polar decomposition of 2×2 tensors ``F`` (shape ``(2, 2, *batch)``): ``(R, U, alpha)``."""
    F = np.asarray(F, dtype=float)
    if F.ndim < 2 or F.shape[:2] != (2, 2):
        raise ValueError(f"polar_2d: F must have shape (2, 2, *batch); got {F.shape}")
    det = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    if np.any(~(det > 0.0)):
        raise ValueError("polar_2d: det F must be positive at every point")
    alpha = np.arctan2(F[1, 0] - F[0, 1], F[0, 0] + F[1, 1])
    cos, sin = np.cos(alpha), np.sin(alpha)
    R = np.array([[cos, -sin], [sin, cos]])
    U = np.einsum("ki...,kj...->ij...", R, F)
    U = 0.5 * (U + np.swapaxes(U, 0, 1))  # symmetric up to round-off; remove it
    return R, U, alpha


@dataclass(frozen=True)
class QuadraticStrainMap:
    """Fitted Eq. 5 surfaces: ``a`` for u, ``b`` for v, with their coefficients of determination."""

    a: Array
    b: Array
    r2_u: float
    r2_v: float
    X_min: Array
    X_max: Array

    def deformation_gradient(self, X1: ArrayLike, X2: ArrayLike) -> Array:
        """F of Eq. 6 at reference points, shape ``(2, 2, *batch)``."""
        X1, X2 = np.broadcast_arrays(np.asarray(X1, dtype=float), np.asarray(X2, dtype=float))
        F = np.empty((2, 2) + X1.shape)
        for row, c in enumerate((self.a, self.b)):
            F[row, 0] = c[1] + c[3] * X2 + 2 * c[4] * X1
            F[row, 1] = c[2] + c[3] * X1 + 2 * c[5] * X2
        F[0, 0] += 1.0
        F[1, 1] += 1.0
        return F

    def stretch(self, X1: ArrayLike, X2: ArrayLike) -> tuple[Array, Array]:
        """``(U, alpha)``: right stretch tensor (Eq. 7) and rigid rotation angle in radians."""
        _, U, alpha = polar_2d(self.deformation_gradient(X1, X2))
        return U, alpha

    def axial_stretch(self, X1: ArrayLike, X2: ArrayLike) -> Array:
        r""":math:`\Lambda_1 = \sqrt{U_{11}^2 + U_{12}^2}` (buchanan2014 Sect. 2.3)."""
        U, _ = self.stretch(X1, X2)
        return np.hypot(U[0, 0], U[0, 1])

    def neutral_axis(self, X1: float) -> float:
        """X₂ where U₁₁ = 1 on the line X₁ = const, searched inside the markers' X₂ range."""
        lo, hi = float(self.X_min[1]), float(self.X_max[1])
        f = lambda x2: float(self.stretch(X1, x2)[0][0, 0]) - 1.0
        f_lo, f_hi = f(lo), f(hi)
        if f_lo * f_hi > 0.0:
            raise ValueError(
                f"neutral_axis: U11 - 1 does not change sign for X2 in [{lo:.4g}, {hi:.4g}] at X1={X1!r} "
                f"(U11 = {f_lo + 1:.5f} .. {f_hi + 1:.5f})"
            )
        return brentq(f, lo, hi, xtol=1e-14)


def fit_strain_map(reference: ArrayLike, deformed: ArrayLike) -> QuadraticStrainMap:
    """Least-squares fit of Eq. 5 to markers ``reference`` (n, 2) → ``deformed`` (n, 2)."""
    X = np.asarray(reference, dtype=float)
    x = np.asarray(deformed, dtype=float)
    if X.ndim != 2 or X.shape[1] != 2:
        raise ValueError(f"fit_strain_map: reference must have shape (n, 2); got {X.shape}")
    if x.shape != X.shape:
        raise ValueError(f"fit_strain_map: deformed must have the shape of reference {X.shape}; got {x.shape}")
    if not (np.all(np.isfinite(X)) and np.all(np.isfinite(x))):
        raise ValueError("fit_strain_map: marker coordinates must be finite")
    if X.shape[0] < 6:
        raise ValueError(f"fit_strain_map: Eq. 5 has 6 coefficients per component; got {X.shape[0]} markers")
    # Centre and scale for conditioning, then map the coefficients back.
    centre = X.mean(axis=0)
    scale = np.ptp(X, axis=0)
    if np.any(scale == 0.0):
        raise ValueError("fit_strain_map: markers must spread in both X1 and X2")
    Xn = (X - centre) / scale
    A = _design_matrix(Xn[:, 0], Xn[:, 1])
    if np.linalg.matrix_rank(A) < 6:
        raise ValueError("fit_strain_map: marker layout cannot determine the quadratic surface (rank < 6)")
    disp = x - X
    coef_n, *_ = np.linalg.lstsq(A, disp, rcond=None)
    r2 = []
    for k in range(2):
        resid = disp[:, k] - A @ coef_n[:, k]
        total = np.sum((disp[:, k] - disp[:, k].mean()) ** 2)
        r2.append(1.0 - np.sum(resid**2) / total if total > 0 else 1.0)
    a, b = (_unscale(coef_n[:, k], centre, scale) for k in range(2))
    return QuadraticStrainMap(a, b, float(r2[0]), float(r2[1]), X.min(axis=0), X.max(axis=0))


def _unscale(cn: Array, centre: Array, scale: Array) -> Array:
    """Coefficients in (X − centre)/scale → coefficients in X (expand the quadratic)."""
    c1, c2 = centre
    s1, s2 = scale
    p0, p1, p2, p3, p4, p5 = cn
    # u = p0 + p1 ξ + p2 η + p3 ξη + p4 ξ² + p5 η²,  ξ = (X1 − c1)/s1,  η = (X2 − c2)/s2
    q1, q2, q3, q4, q5 = p1 / s1, p2 / s2, p3 / (s1 * s2), p4 / s1**2, p5 / s2**2
    return np.array(
        [
            p0 - q1 * c1 - q2 * c2 + q3 * c1 * c2 + q4 * c1**2 + q5 * c2**2,
            q1 - q3 * c2 - 2 * q4 * c1,
            q2 - q3 * c1 - 2 * q5 * c2,
            q3,
            q4,
            q5,
        ]
    )
