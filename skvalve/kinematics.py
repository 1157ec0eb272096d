r"""Finite-strain kinematics, vectorised over trailing batch axes.

Every tensor here is stored with its tensor indices first and any number of batch
axes after them: a deformation gradient has shape ``(3, 3, *batch)``, e.g.
``(3, 3, n_quadrature_points, n_elements)`` inside a finite-element assembly. This
is the layout scikit-fem uses for fields at quadrature points, so no transposes are
needed between the two.

Definitions (Holzapfel 2000, ch. 2):

.. math::

    C = F^T F, \quad B = F F^T, \quad J = \det F, \quad
    I_1 = \operatorname{tr} C, \quad I_2 = \tfrac12 (I_1^2 - \operatorname{tr} C^2),
    \quad \bar I_1 = J^{-2/3} I_1,

    E = \tfrac12 (C - I), \quad F = R U, \quad U = \sqrt{C}, \quad
    h = \ln V = \tfrac12 \ln B.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]

__all__ = [
    "identity_like",
    "right_cauchy_green",
    "left_cauchy_green",
    "determinant",
    "inverse",
    "cofactor",
    "invariants",
    "isochoric_first_invariant",
    "principal_stretches",
    "polar_decomposition",
    "green_lagrange",
    "log_strain",
    "as_tensor_field",
]


def as_tensor_field(F: ArrayLike, name: str = "F") -> Array:
    """Return ``F`` as a float array of shape ``(3, 3, *batch)`` or raise ``ValueError``."""
    F = np.asarray(F, dtype=float)
    if F.ndim < 2 or F.shape[:2] != (3, 3):
        raise ValueError(f"{name} must have shape (3, 3, *batch); got {F.shape}")
    return F


def identity_like(F: Array) -> Array:
    """Identity tensors with the batch shape of ``F`` (shape ``(3, 3, *batch)``)."""
    eye = np.eye(3).reshape((3, 3) + (1,) * (F.ndim - 2))
    return np.broadcast_to(eye, F.shape).copy()


def _batch_last_to_first(A: Array) -> Array:
    """(3, 3, *batch) -> (*batch, 3, 3), the layout numpy.linalg expects."""
    return np.moveaxis(A, (0, 1), (-2, -1))


def _batch_first_to_last(A: Array) -> Array:
    return np.moveaxis(A, (-2, -1), (0, 1))


def right_cauchy_green(F: ArrayLike) -> Array:
    """Right Cauchy–Green tensor :math:`C = F^T F`."""
    F = as_tensor_field(F)
    return np.einsum("kI...,kJ...->IJ...", F, F)


def left_cauchy_green(F: ArrayLike) -> Array:
    """Left Cauchy–Green tensor :math:`B = F F^T`."""
    F = as_tensor_field(F)
    return np.einsum("iK...,jK...->ij...", F, F)


def determinant(A: ArrayLike) -> Array:
    """Determinant of 3x3 tensors by the rule of Sarrus (exact, vectorised)."""
    A = as_tensor_field(A, "A")
    return (
        A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
        - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
        + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0])
    )


def cofactor(A: ArrayLike) -> Array:
    r"""Cofactor tensor :math:`\operatorname{cof} A = \det(A) A^{-T}` (exists for singular A)."""
    A = as_tensor_field(A, "A")
    cof = np.empty_like(A)
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            cof[i, j] = A[i1, j1] * A[i2, j2] - A[i1, j2] * A[i2, j1]
    return cof


def inverse(A: ArrayLike) -> Array:
    """Inverse of 3x3 tensors via the cofactor; raises ``ValueError`` where singular or not finite."""
    A = as_tensor_field(A, "A")
    det = determinant(A)
    bad = ~np.isfinite(det) | (det == 0.0)
    if np.any(bad):
        where = tuple(int(i) for i in np.argwhere(np.atleast_1d(bad))[0])
        raise ValueError(
            f"inverse: singular or non-finite tensor (det = {float(np.atleast_1d(det)[where])!r}) "
            f"at batch index {where}"
        )
    return np.swapaxes(cofactor(A), 0, 1) / det


def _require_positive_det(F: Array, who: str) -> None:
    """``ValueError`` unless F is finite with det F > 0 everywhere."""
    if not np.all(np.isfinite(F)):
        raise ValueError(f"{who} needs a finite F; got NaN or inf")
    if np.any(determinant(F) <= 0.0):
        raise ValueError(f"{who} needs det F > 0 everywhere")


def invariants(F: ArrayLike) -> tuple[Array, Array, Array]:
    r"""Principal invariants :math:`(I_1, I_2, I_3)` of :math:`C = F^T F`; :math:`I_3 = J^2`."""
    C = right_cauchy_green(F)
    I1 = np.trace(C)
    I2 = 0.5 * (I1**2 - np.einsum("IJ...,JI...->...", C, C))
    I3 = determinant(C)
    return I1, I2, I3


def isochoric_first_invariant(F: ArrayLike) -> Array:
    r"""Isochoric first invariant :math:`\bar I_1 = J^{-2/3} \operatorname{tr} C`."""
    F = as_tensor_field(F)
    J = determinant(F)
    return J ** (-2.0 / 3.0) * np.einsum("kI...,kI...->...", F, F)


def principal_stretches(F: ArrayLike) -> Array:
    """Principal stretches (ascending) with shape ``(3, *batch)``: square roots of eig(C)."""
    C = right_cauchy_green(F)
    eig = np.linalg.eigvalsh(_batch_last_to_first(C))
    return np.sqrt(np.moveaxis(eig, -1, 0))


def _symmetric_function(A: Array, fun) -> Array:
    """Apply a scalar function to a symmetric tensor field through its eigenpairs."""
    w, v = np.linalg.eigh(_batch_last_to_first(A))
    out = np.einsum("...ik,...k,...jk->...ij", v, fun(w), v)
    return _batch_first_to_last(out)


def polar_decomposition(F: ArrayLike) -> tuple[Array, Array]:
    r"""Right polar decomposition :math:`F = R U`, returns ``(R, U)``.

    :math:`U = \sqrt{C}` from the eigenpairs of :math:`C`, then :math:`R = F U^{-1}`.
    Requires :math:`\det F > 0`.
    """
    F = as_tensor_field(F)
    _require_positive_det(F, "polar_decomposition")
    U = _symmetric_function(right_cauchy_green(F), np.sqrt)
    R = np.einsum("iK...,KJ...->iJ...", F, inverse(U))
    return R, U


def green_lagrange(F: ArrayLike) -> Array:
    r"""Green–Lagrange strain :math:`E = \tfrac12 (C - I)`."""
    C = right_cauchy_green(F)
    return 0.5 * (C - identity_like(C))


def log_strain(F: ArrayLike, spatial: bool = True) -> Array:
    r"""True (Hencky) strain: :math:`\ln V = \tfrac12 \ln B` (spatial) or :math:`\ln U`.

    For a uniaxial stretch :math:`\lambda` along :math:`e_1` both give
    :math:`\ln \lambda` in the 11 component.
    """
    F = as_tensor_field(F)
    _require_positive_det(F, "log_strain")
    G = left_cauchy_green(F) if spatial else right_cauchy_green(F)
    return _symmetric_function(G, lambda w: 0.5 * np.log(w))
