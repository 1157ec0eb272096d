"""The tangent's growing CSR pattern: the same matrix as SciPy's sums, one pattern while the extra entries stay in
it, so the direct solver analyses once (skvalve.fem.sparse_layout)."""

import numpy as np
import pytest
import scipy.sparse as sp

from skvalve.fem.solvers import linsolve
from skvalve.fem.sparse_layout import RESET_FACTOR, GrowingPattern


def _element_matrix(n: int, seed: int) -> sp.csr_matrix:
    """A symmetric, diagonally dominant banded matrix (the element part), stored with sorted indices."""
    rng = np.random.default_rng(seed)
    band = sp.diags([rng.uniform(0.1, 1.0, n - k) for k in (1, 2)], [1, 2], shape=(n, n))
    K = (band + band.T + sp.diags(np.full(n, 10.0))).tocsr()
    K.sort_indices()
    return K


def _extra(n: int, pairs: list[tuple[int, int]], seed: int) -> sp.coo_matrix:
    """A symmetric extra matrix coupling the given far-apart dof pairs (a contact stencil's entries)."""
    rng = np.random.default_rng(seed)
    rows, cols, vals = [], [], []
    for i, j in pairs:
        v = rng.uniform(0.1, 0.5)
        rows += [i, j, i, j]
        cols += [j, i, i, j]
        vals += [-v, -v, v, v]
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n))


def test_matrix_equals_scipy_sum_and_pattern_stays_while_entries_stay_inside():
    n = 40
    K = _element_matrix(n, 0)
    layout = GrowingPattern(K.indptr, K.indices, n)
    first = _extra(n, [(0, 30), (5, 25), (7, 33)], 1)
    mass = np.linspace(1.0, 2.0, n)
    A = layout.matrix(K.data, first.row, first.col, first.data, diagonal=mass)
    assert abs(A - (K + first + sp.diags(mass))).max() == 0.0
    assert layout.growths == 1
    indptr, indices = A.indptr.copy(), A.indices.copy()
    # a subset of the entries seen (one pair gone, so its entries are explicit zeros now): the same pattern
    second = _extra(n, [(5, 25)], 2)
    B = layout.matrix(K.data, second.row, second.col, second.data)
    assert abs(B - (K + second)).max() == 0.0
    assert layout.growths == 1 and np.array_equal(B.indptr, indptr) and np.array_equal(B.indices, indices)
    # a new pair: the pattern grows and keeps the old pairs
    third = _extra(n, [(2, 38)], 3)
    C = layout.matrix(K.data, third.row, third.col, third.data)
    assert abs(C - (K + third)).max() == 0.0 and layout.growths == 2
    assert layout.nnz == indices.size + 2  # (2, 38) and (38, 2); the diagonal is always in


def test_pattern_resets_when_it_holds_far_more_than_in_use():
    n = 200
    K = _element_matrix(n, 4)
    layout = GrowingPattern(K.indptr, K.indices, n)
    base = layout.nnz
    many = _extra(n, [(i, i + 100) for i in range(0, 60)], 5)
    layout.matrix(K.data, many.row, many.col, many.data)
    assert layout.nnz == base + 2 * 60
    few = _extra(n, [(150, 10)], 6)  # new entries while 60 pairs are held and 1 is in use
    assert 2 * 60 > RESET_FACTOR * 4
    M = layout.matrix(K.data, few.row, few.col, few.data)
    assert layout.nnz == base + 2 and abs(M - (K + few)).max() == 0.0


def test_diagonal_and_symmetric_part_on_the_pattern_and_off_it():
    n = 30
    K = _element_matrix(n, 7)
    layout = GrowingPattern(K.indptr, K.indices, n)
    rng = np.random.default_rng(8)
    skew = sp.coo_matrix((rng.normal(size=4), ([0, 20, 3, 3], [20, 0, 29, 3])), shape=(n, n))  # not symmetric
    A = layout.matrix(K.data, skew.row, skew.col, skew.data)
    d = rng.uniform(1.0, 2.0, n)
    dense = A.toarray()
    assert layout.holds(A) and layout.holds(sp.csr_matrix(A)) and not layout.holds(A.copy())
    assert np.array_equal(layout.add_diagonal(A, d).toarray(), dense + np.diag(d))
    assert np.allclose(layout.symmetric_part(A, d).toarray(), 0.5 * (dense + dense.T) + np.diag(d), rtol=0, atol=1e-15)
    # a matrix on another pattern: SciPy's sums, same values
    other = sp.csr_matrix(dense)
    assert np.allclose(layout.symmetric_part(other).toarray(), 0.5 * (dense + dense.T), rtol=0, atol=1e-15)
    assert np.array_equal(layout.add_diagonal(other, d).toarray(), dense + np.diag(d))


@pytest.mark.parametrize("symmetric", [False, True])
def test_solver_analyses_once_while_contact_entries_come_and_go(symmetric):
    n = 60
    K = _element_matrix(n, 9)
    layout = GrowingPattern(K.indptr, K.indices, n)
    solver = linsolve.LinearSolver(symmetric=symmetric, definite=False)
    b = np.ones(n)
    pairs = [(0, 40), (10, 50), (20, 45)]
    for k in range(6):  # pairs switching on and off among those seen in the first call
        extra = _extra(n, pairs if k == 0 else pairs[k % 3: k % 3 + 1], 10 + k)
        A = layout.matrix(K.data, extra.row, extra.col, extra.data)
        x = solver.analyse(A).factorize(A).solve(b)
        assert np.allclose((K + extra) @ x, b, rtol=1e-10, atol=0.0)
    assert layout.growths == 1
    assert solver.statistics.analyses == 1
