"""Envelope (skyline) Cholesky kernels for the RVE stiffness (numba; ~100–150 unknowns per RVE).

The matrix is stored dense, but only its lower *envelope* is read or written: row i from
column ``first[i]`` to the diagonal.  Cholesky keeps the envelope (no fill outside it), so with
a bandwidth-reducing numbering of the interior cross-links (reverse Cuthill–McKee, computed
once per network in ``rve.py``) a factorisation costs Σ_i Σ_j (j − max(first_i, first_j))
multiply-adds instead of n³/6 — about 5× fewer for the paper's 450-fiber networks — and the
triangular solves half of the dense ones.  ``first = 0`` everywhere is the dense algorithm.

Row-oriented ("up-looking") factorisation:

    L_ij = (A_ij − Σ_{k = max(first_i, first_j)}^{j−1} L_ik L_jk) / L_jj,
    L_ii = √(A_ii − Σ_{k = first_i}^{i−1} L_ik²),

reading rows contiguously.  Written out instead of calling LAPACK so that the kernels run
inside a numba ``prange`` over RVEs without nested BLAS threads and without exceptions:
failure is a return value.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# IEEE-safe fast math: lets the dot-product reductions vectorise, keeps NaN/inf semantics
FAST = {"reassoc", "contract", "nsz", "arcp"}


@njit(cache=True, fastmath=FAST)
def cholesky_in_place(a: np.ndarray, n: int, first: np.ndarray) -> bool:
    """Lower Cholesky factor of the envelope of a[:n, :n], in place; False if not SPD."""
    for i in range(n):
        fi = first[i]
        for j in range(fi, i + 1):
            t = a[i, j]
            for k in range(max(fi, first[j]), j):
                t -= a[i, k] * a[j, k]
            if j < i:
                a[i, j] = t / a[j, j]
            elif t > 0.0:
                a[i, i] = math.sqrt(t)
            else:
                return False
    return True


@njit(cache=True, fastmath=FAST)
def cholesky_solve(factor: np.ndarray, n: int, first: np.ndarray, b: np.ndarray) -> None:
    """Solve L Lᵀ Y = B in place for all columns of B (n, r) in one blocked sweep.

    Each factor entry is read once for all r right-hand sides (the row of B is contiguous).
    """
    r = b.shape[1]
    for i in range(n):
        for k in range(first[i], i):
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
        for i in range(first[k], k):
            c = factor[k, i]
            for j in range(r):
                b[i, j] -= c * b[k, j]


@njit(cache=True, fastmath=FAST)
def cholesky_solve_vector(factor: np.ndarray, n: int, first: np.ndarray, b: np.ndarray) -> None:
    """Solve L Lᵀ y = b in place for one right-hand side b (n,).

    Forward sweep as dot products over the envelope of row i, backward sweep as axpys over the
    envelope of row k: both read L and b contiguously (faster than ``cholesky_solve`` with r = 1).
    """
    for i in range(n):
        t = 0.0
        for k in range(first[i], i):
            t += factor[i, k] * b[k]
        b[i] = (b[i] - t) / factor[i, i]
    for k in range(n - 1, -1, -1):
        c = b[k] / factor[k, k]
        b[k] = c
        for i in range(first[k], k):
            b[i] -= factor[k, i] * c


@njit(cache=True)
def factor_with_shift(matrix, work, n, first):
    """Cholesky of K; on failure K + τ·max(diag) I with τ = 1e-10, 1e-8, ... (Levenberg step).

    Reads the lower envelope of ``matrix``, writes the factor into ``work``.  Returns True if K
    itself was positive definite.
    """
    scale = 0.0
    for i in range(n):
        scale = max(scale, abs(matrix[i, i]))
    shift = 0.0
    while True:
        for i in range(n):
            for j in range(first[i], i + 1):
                work[i, j] = matrix[i, j]
            work[i, i] += shift * scale
        if cholesky_in_place(work, n, first):
            return shift == 0.0
        shift = 1e-10 if shift == 0.0 else 100.0 * shift
        if shift > 1e3:
            return False


def dense_envelope(n: int) -> np.ndarray:
    """``first`` for a dense matrix (every row starts at column 0)."""
    return np.zeros(n, dtype=np.int64)
