"""The solver's CSR pattern kernels against SciPy's own triangle extraction."""

import numpy as np
import pytest
import scipy.sparse as sp

from skvalve.fem.solvers.sparse_patterns import rows_sorted_unique, upper_triangle


def _pattern(n: int, density: float, seed: int, drop_diagonal: bool) -> sp.csr_matrix:
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=density, random_state=rng, format="csr")
    A = (A + A.T + sp.eye(n)).tocsr()
    if drop_diagonal:  # some rows without a stored diagonal, one row empty
        keep = ~((A.tocoo().row == A.tocoo().col) & (A.tocoo().row % 3 == 0))
        coo = A.tocoo()
        A = sp.csr_matrix((coo.data[keep], (coo.row[keep], coo.col[keep])), shape=A.shape)
        A = A.tolil()
        A[n // 2, :] = 0
        A = A.tocsr()
        A.eliminate_zeros()
    A.sort_indices()
    A.data = np.arange(1.0, A.nnz + 1.0)  # each entry's value names its position
    return A


@pytest.mark.parametrize("n, density, seed, drop", [(1, 1.0, 0, False), (7, 0.3, 1, True), (60, 0.05, 2, False),
                                                    (200, 0.02, 3, True)])
def test_upper_triangle_is_scipys_triu_with_the_diagonal_inserted(n, density, seed, drop):
    A = _pattern(n, density, seed, drop)
    indptr, indices, source = upper_triangle(A.indptr.astype(np.int64), A.indices.astype(np.int64))
    values = np.where(source >= 0, A.data[np.maximum(source, 0)], 0.0)
    upper = sp.csr_matrix((values, indices, indptr), shape=A.shape)
    expected = sp.triu(A).tocsr()
    expected.sort_indices()
    assert np.array_equal(upper.toarray(), expected.toarray())  # every upper value from its own entry
    assert np.all(np.diff(indptr) >= 1) and np.array_equal(upper.diagonal() != 0, A.diagonal() != 0)
    for row in range(n):  # each row: its diagonal first, then its columns increasing
        columns = indices[indptr[row]: indptr[row + 1]]
        assert columns[0] == row and np.all(np.diff(columns) > 0)
    inserted = np.flatnonzero(source < 0)
    assert np.array_equal(np.sort(indices[inserted]), np.flatnonzero(A.diagonal() == 0))


def test_rows_sorted_unique_finds_an_unsorted_and_a_repeated_column():
    indptr = np.array([0, 2, 4])
    assert rows_sorted_unique(indptr, np.array([0, 1, 0, 1]))
    assert not rows_sorted_unique(indptr, np.array([1, 0, 0, 1]))
    assert not rows_sorted_unique(indptr, np.array([0, 1, 1, 1]))
    assert rows_sorted_unique(np.array([0, 2, 2]), np.array([0, 1]))  # an empty row
