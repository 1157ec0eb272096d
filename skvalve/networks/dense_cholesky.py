"""Dense Cholesky kernels for the RVE stiffness (numba; ~100–150 unknowns per RVE).

Written out instead of calling LAPACK so that they run inside a numba ``prange`` over RVEs
without nested BLAS threads and without exceptions: failure is a return value.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# IEEE-safe fast math: lets the dot-product reductions vectorise, keeps NaN/inf semantics
FAST = {"reassoc", "contract", "nsz", "arcp"}


@njit(cache=True, fastmath=FAST)
def cholesky_in_place(a: np.ndarray, n: int) -> bool:
    """Lower Cholesky factor of a[:n, :n] overwriting its lower triangle; False if not SPD."""
    for j in range(n):
        s = a[j, j]
        for k in range(j):
            s -= a[j, k] * a[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        a[j, j] = d
        for i in range(j + 1, n):
            t = a[i, j]
            for k in range(j):
                t -= a[i, k] * a[j, k]
            a[i, j] = t / d
    return True


@njit(cache=True, fastmath=FAST)
def cholesky_solve(factor: np.ndarray, n: int, b: np.ndarray) -> None:
    """Solve L Lᵀ Y = B in place, B of shape (n, r); factor rows are read contiguously."""
    r = b.shape[1]
    for i in range(n):
        for k in range(i):
            c = factor[i, k]
            for j in range(r):
                b[i, j] -= c * b[k, j]
        c = 1.0 / factor[i, i]
        for j in range(r):
            b[i, j] *= c
    for k in range(n - 1, -1, -1):
        c = 1.0 / factor[k, k]
        for j in range(r):
            b[k, j] *= c
        for i in range(k):
            c = factor[k, i]
            for j in range(r):
                b[i, j] -= c * b[k, j]


@njit(cache=True)
def factor_with_shift(matrix, work, n):
    """Cholesky of K; on failure K + τ·max(diag) I with τ = 1e-10, 1e-8, ... (Levenberg step).

    Returns True if K itself was positive definite.
    """
    scale = 0.0
    for i in range(n):
        scale = max(scale, abs(matrix[i, i]))
    shift = 0.0
    while True:
        for i in range(n):
            for j in range(i + 1):
                work[i, j] = matrix[i, j]
            work[i, i] += shift * scale
        if cholesky_in_place(work, n):
            return shift == 0.0
        shift = 1e-10 if shift == 0.0 else 100.0 * shift
        if shift > 1e3:
            return False
