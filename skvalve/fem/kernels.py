r"""Compiled kernels of the total-Lagrangian assembly (numba).

With scalar shape functions :math:`N_a` and their reference gradients
:math:`N_{a,J} = \partial N_a/\partial X_J` at the quadrature points, a vector field has
element values :math:`u_{ai}` (node-major: local dof :math:`a\,d + i`) and

.. math::

    F_{iJ} = \delta_{iJ} + \sum_a u_{ai} N_{a,J}, \qquad
    f_{ai} = \sum_q w_q\, P_{iJ} N_{a,J}, \qquad
    K_{ai,bk} = \sum_q w_q\, N_{a,J}\, \mathbb{A}_{iJkL}\, N_{b,L},

where :math:`w_q` is the quadrature weight times the Jacobian of the reference map
(``dx`` of scikit-fem). The stiffness is formed per quadrature point in two contractions,
first :math:`G_{aikL} = N_{a,J}\mathbb{A}_{iJkL}` and then :math:`G_{aikL} N_{b,L}`,
which costs :math:`n_b d^4 + n_b^2 d^3` multiply-adds instead of :math:`n_b^2 d^4`.
Element matrices are added into a CSR array whose sparsity pattern and entry positions
were computed once (:func:`scatter_add`).
"""

from __future__ import annotations

import os

import numpy as np
from numba import njit, prange

# Numba's OpenMP workers and MKL's (PARDISO) spin-wait after each parallel region by default; the two
# runtimes then take the cores from each other between assembly and solve (measured on 2 cores: 40 % less
# CPU for a Newton solve, 10x faster assembly of small problems when passive). Read by the OpenMP
# runtimes when they start (first parallel call), so set at import; an explicit user setting wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__all__ = ["element_gradients", "element_stiffness", "element_forces", "scatter_add", "csr_pattern", "csr_structure",
           "csr_positions", "psd_blocks"]


@njit(parallel=True, cache=True)
def element_gradients(u_elem: np.ndarray, dN: np.ndarray) -> np.ndarray:
    """Displacement gradient ``H[i, J, q, e]`` from ``u_elem[e, a, i]`` and ``dN[e, q, a, J]``."""
    nel, nqp, nb, dim = dN.shape
    ncomp = u_elem.shape[2]
    H = np.zeros((ncomp, dim, nqp, nel))
    for e in prange(nel):
        for q in range(nqp):
            for a in range(nb):
                for i in range(ncomp):
                    uai = u_elem[e, a, i]
                    for J in range(dim):
                        H[i, J, q, e] += uai * dN[e, q, a, J]
    return H


@njit(parallel=True, cache=True)
def element_forces(P: np.ndarray, dN: np.ndarray, dx: np.ndarray) -> np.ndarray:
    """Internal nodal forces ``f[e, a*d + i] = sum_q dx P[i, J, q, e] dN[e, q, a, J]``."""
    nel, nqp, nb, dim = dN.shape
    f = np.zeros((nel, nb * dim))
    for e in prange(nel):
        for q in range(nqp):
            w = dx[e, q]
            for a in range(nb):
                for i in range(dim):
                    s = 0.0
                    for J in range(dim):
                        s += P[i, J, q, e] * dN[e, q, a, J]
                    f[e, a * dim + i] += w * s
    return f


@njit(cache=True)
def add_point_stiffness(ke: np.ndarray, dNq: np.ndarray, A: np.ndarray, w: float, G: np.ndarray) -> None:
    r"""Add :math:`w\,\partial_J N_a\,\mathbb{A}_{iJkL}\,\partial_L N_b` into the upper triangle of ``ke``.

    One quadrature point of an element: ``ke`` (at least nb*d square) indexed ``[a*d+i, b*d+k]``,
    ``dNq`` (nb, d) the shape-function gradients, ``A`` (>= d)^4 the tangent dP/dF, ``w`` the weight,
    ``G`` an (nb, d, d, d) scratch array. Shared by :func:`element_stiffness` and the fused kernels.
    """
    nb, dim = dNq.shape
    for a in range(nb):
        for i in range(dim):
            for k in range(dim):
                for L in range(dim):
                    s = 0.0
                    for J in range(dim):
                        s += dNq[a, J] * A[i, J, k, L]
                    G[a, i, k, L] = w * s
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
                        s += G[a, i, k, L] * dNq[b, L]
                    ke[row, col] += s


@njit(parallel=True, cache=True)
def element_stiffness(A: np.ndarray, dN: np.ndarray, dx: np.ndarray, ke: np.ndarray) -> None:
    r"""Add ``sum_q dx dN[a,J] A[e,q,i,J,k,L] dN[b,L]`` into ``ke[e, a*d+i, b*d+k]``.

    ``A`` is indexed ``[e, q, i, J, k, L]`` (any strides) and must have the major symmetry
    :math:`\mathbb{A}_{iJkL} = \mathbb{A}_{kLiJ}` of a hyperelastic tangent: only the upper
    triangle is integrated and then mirrored. ``ke`` may be larger than the displacement
    block (mixed elements); only its leading ``nb*d`` square is touched.
    """
    nel, nqp, nb, dim = dN.shape
    for e in prange(nel):
        G = np.empty((nb, dim, dim, dim))
        for q in range(nqp):
            add_point_stiffness(ke[e], dN[e, q], A[e, q], dx[e, q], G)
        # major symmetry of A makes the block symmetric: mirror the upper triangle
        for row in range(nb * dim):
            for col in range(row + 1, nb * dim):
                ke[e, col, row] = ke[e, row, col]


@njit(cache=True)
def scatter_add(ke: np.ndarray, positions: np.ndarray, data: np.ndarray) -> None:
    """``data[positions[e, m, n]] += ke[e, m, n]`` for every non-negative position."""
    nel, nrow, ncol = positions.shape
    for e in range(nel):
        for m in range(nrow):
            for n in range(ncol):
                pos = positions[e, m, n]
                if pos >= 0:
                    data[pos] += ke[e, m, n]


@njit(cache=True)
def csr_structure(element_dofs: np.ndarray, n: int):
    """Sparsity pattern (``indptr``, sorted ``indices``) of the matrix assembled from element blocks.

    ``element_dofs[e, m]`` are (reduced) dof numbers, negative for dofs left out (constraints, or padding of
    connectivities narrower than the array).
    """
    nel, ndofe = element_dofs.shape
    start = np.zeros(n + 1, dtype=np.int64)
    for e in range(nel):
        valid = 0
        for m in range(ndofe):
            if element_dofs[e, m] >= 0:
                valid += 1
        for m in range(ndofe):
            r = element_dofs[e, m]
            if r >= 0:
                start[r + 1] += valid
    for r in range(n):
        start[r + 1] += start[r]
    buffer = np.empty(start[n], dtype=np.int64)
    fill = start[:-1].copy()
    for e in range(nel):
        for m in range(ndofe):
            r = element_dofs[e, m]
            if r < 0:
                continue
            for k in range(ndofe):
                c = element_dofs[e, k]
                if c >= 0:
                    buffer[fill[r]] = c
                    fill[r] += 1
    indptr = np.zeros(n + 1, dtype=np.int64)
    for r in range(n):
        segment = np.sort(buffer[start[r]:start[r + 1]])
        unique, last = 0, -1
        for v in segment:
            if v != last:
                buffer[start[r] + unique] = v
                unique += 1
                last = v
        indptr[r + 1] = indptr[r] + unique
    indices = np.empty(indptr[n], dtype=np.int64)
    for r in range(n):
        length = indptr[r + 1] - indptr[r]
        indices[indptr[r]:indptr[r + 1]] = buffer[start[r]:start[r] + length]
    return indptr, indices


@njit(cache=True)
def csr_positions(element_dofs: np.ndarray, indptr: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The CSR position ``positions[e, m, k]`` of every element entry in a pattern that holds it (-1 where a dof is
    left out). Called per group of blocks of one width, so that no block is padded to the widest one's size."""
    nel, ndofe = element_dofs.shape
    positions = np.full((nel, ndofe, ndofe), -1, dtype=np.int64)
    for e in range(nel):
        for m in range(ndofe):
            r = element_dofs[e, m]
            if r < 0:
                continue
            for k in range(ndofe):
                c = element_dofs[e, k]
                if c < 0:
                    continue
                lo, hi = indptr[r], indptr[r + 1]
                while lo < hi:
                    mid = (lo + hi) // 2
                    if indices[mid] < c:
                        lo = mid + 1
                    else:
                        hi = mid
                positions[e, m, k] = lo
    return positions


def csr_pattern(element_dofs: np.ndarray, n: int):
    """:func:`csr_structure` and :func:`csr_positions` of one block array: ``indptr``, ``indices``, ``positions``."""
    indptr, indices = csr_structure(element_dofs, n)
    return indptr, indices, csr_positions(element_dofs, indptr, indices)


@njit(parallel=True, cache=True)
def psd_blocks(matrices):
    r"""Each (m, m) block's symmetric part :math:`S = \tfrac12 (B + B^T)` with its negative eigenvalues set to zero,
    :math:`\sum_{\lambda_k > 0} \lambda_k v_k v_k^T` (the nearest positive semidefinite matrix in the Frobenius norm);
    a block with no negative eigenvalue is returned as :math:`S` itself. One pass per block, in parallel over the
    blocks (the batched NumPy version loops over them on one thread); on one thread 5000 random 24 x 24 blocks took
    0.27 s against NumPy's 0.30 s, most of it in the eigensolver."""
    n, m = matrices.shape[0], matrices.shape[1]
    out = np.empty_like(matrices)
    for e in prange(n):
        S = 0.5 * (matrices[e] + matrices[e].T)
        values, vectors = np.linalg.eigh(S)
        if values[0] >= 0.0:
            out[e] = S
            continue
        for i in range(m):
            for j in range(i, m):
                acc = 0.0
                for k in range(m):
                    if values[k] > 0.0:
                        acc += vectors[i, k] * values[k] * vectors[j, k]
                out[e, i, j] = acc
                out[e, j, i] = acc
    return out
