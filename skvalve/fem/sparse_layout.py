r"""One CSR pattern for a tangent whose contact entries come and go, so the direct solver's analysis is kept.

The element blocks of a :class:`~skvalve.fem.problem.Problem` fill a pattern fixed by the connectivities; a term
with a state-dependent stencil (IPC contact: the vertex pairs within reach change with every iterate) adds a sparse
matrix whose entries change from one iterate to the next. Added with SciPy, each sum is a new pattern (and SciPy
drops the entries that sum to zero), so PARDISO's reordering ran again at almost every factorisation, and the sum
itself rewrote all the matrix's entries: on the 1.0 diseased valve's closure (5.5 million entries, 90 000 of them
contact) 907 of the 1949 factorisations reordered (380 s) and the sums took 0.11 s each.

:class:`GrowingPattern` keeps one pattern: the element pattern, the whole diagonal, and every extra entry it has seen
(with its transpose, so the pattern stays structurally symmetric). A matrix on it is the element values gathered to
their places plus the extra entries scattered in (explicit zeros where an entry is absent now); the pattern grows
only when an entry outside it appears, and shrinks back to the element pattern plus the current entries when the
entries it holds for terms that no longer use them outnumber ``RESET_FACTOR`` times those in use. The diagonal and
the symmetric part are then formed on the same pattern (:meth:`GrowingPattern.add_diagonal`,
:meth:`GrowingPattern.symmetric_part`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["GrowingPattern", "RESET_FACTOR"]

#: the pattern falls back to the element pattern plus the current extra entries when the extra entries it holds
#: outnumber this many times those in use
RESET_FACTOR = 4.0


def _keys(indptr: np.ndarray, indices: np.ndarray, n: int) -> np.ndarray:
    """Row-major keys ``row * n + column`` of a CSR pattern's entries (sorted where the rows' columns are)."""
    rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
    return rows * n + np.asarray(indices, dtype=np.int64)


def _lookup(sorted_keys: np.ndarray, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(where, found)``: the positions of ``keys`` in ``sorted_keys`` (valid where ``found``)."""
    where = np.minimum(np.searchsorted(sorted_keys, keys), sorted_keys.size - 1)
    return where, sorted_keys[where] == keys


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """True when ``a`` is ``b`` or a view of all of it (SciPy's constructor keeps the index arrays as views)."""
    return (a.dtype == b.dtype and a.shape == b.shape and a.flags.c_contiguous and b.flags.c_contiguous
            and a.__array_interface__["data"][0] == b.__array_interface__["data"][0])


class GrowingPattern:
    """The tangent's CSR pattern: the element pattern ``(indptr, indices)`` of an ``n x n`` matrix (sorted rows), the
    diagonal, and the extra entries seen so far (module docstring). ``growths`` counts the times the pattern changed.

    New entries are merged into the sorted entry keys (``row * n + column``) and every kept map (element entries,
    diagonal, transposes) is shifted by the count of entries inserted before it: a whole re-sort of the 5.5 million
    keys (NumPy's ``union1d``) took 6 s a growth on the 1.0 diseased valve."""

    def __init__(self, indptr: np.ndarray, indices: np.ndarray, n: int) -> None:
        self.n = int(n)
        keys = _keys(indptr, indices, self.n)
        if keys.size > 1 and not np.all(keys[1:] > keys[:-1]):
            raise ValueError("GrowingPattern: the element pattern's rows must be sorted and unique")
        self.keys = keys
        self.indptr = np.asarray(indptr, dtype=np.int32).copy()
        self.indices = np.asarray(indices, dtype=np.int32).copy()
        self._element = np.arange(keys.size)
        self._diagonal = np.zeros(0, dtype=np.int64)
        self._transpose = np.zeros(0, dtype=np.int64)
        self._insert(np.arange(self.n, dtype=np.int64) * (self.n + 1))  # the whole diagonal
        rows = self.keys // self.n
        self._diagonal = np.searchsorted(self.keys, np.arange(self.n, dtype=np.int64) * (self.n + 1))
        self._transpose = np.searchsorted(self.keys, (self.keys - rows * self.n) * self.n + rows)
        if not np.array_equal(self.keys[self._transpose] // self.n, self.keys - rows * self.n):
            raise ValueError("GrowingPattern: the element pattern must be structurally symmetric")
        self._base = (self.keys, self.indptr, self.indices, self._element, self._diagonal, self._transpose)
        self.growths = 0

    @property
    def nnz(self) -> int:
        return int(self.keys.size)

    def _insert(self, keys: np.ndarray) -> None:
        """Merge the entries ``keys`` (with their transposes once the pattern is symmetric) into the pattern."""
        keys = np.unique(keys)
        keys = keys[~_lookup(self.keys, keys)[1]]
        if keys.size == 0:
            return
        n = self.n
        at = np.searchsorted(self.keys, keys)  # each new key goes before this old entry
        old = np.arange(self.keys.size)
        moved = old + np.searchsorted(at, old, side="right")  # old entry -> its new position
        added = at + np.arange(keys.size)  # the new entries' positions
        self.keys = np.insert(self.keys, at, keys)
        rows, cols = keys // n, keys % n
        self.indices = np.insert(self.indices, at, cols.astype(np.int32))
        self.indptr = self.indptr + np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))]).astype(np.int32)
        self._element = moved[self._element]
        self._diagonal = moved[self._diagonal]
        if self._transpose.size:
            transpose = np.empty(self.keys.size, dtype=np.int64)
            transpose[moved] = moved[self._transpose]
            transpose[added] = np.searchsorted(self.keys, cols * n + rows)
            self._transpose = transpose

    def _positions(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """The pattern positions of the entries ``(rows, cols)``, the pattern grown (or reset) first where needed."""
        n = self.n
        rows, cols = rows.astype(np.int64), cols.astype(np.int64)
        keys = rows * n + cols
        where, found = _lookup(self.keys, keys)
        if not found.all():
            held = self.keys.size - self._base[0].size
            current = np.concatenate([keys, cols * n + rows])
            if held > RESET_FACTOR * np.unique(current).size:
                (self.keys, self.indptr, self.indices, self._element, self._diagonal,
                 self._transpose) = self._base
            self._insert(current)
            self.growths += 1
            where = np.searchsorted(self.keys, keys)
        return where

    def matrix(self, element_values: np.ndarray, rows: np.ndarray | None = None, cols: np.ndarray | None = None,
               values: np.ndarray | None = None, diagonal: np.ndarray | None = None) -> sp.csr_matrix:
        """The matrix of the element pattern's ``element_values`` plus the extra entries ``(rows, cols, values)``
        (duplicates summed) plus ``diagonal``, on this pattern."""
        positions = self._positions(rows, cols) if rows is not None and rows.size else None  # may grow the pattern
        data = np.zeros(self.keys.size)
        data[self._element] = element_values
        if positions is not None:
            np.add.at(data, positions, values)
        if diagonal is not None:
            data[self._diagonal] += diagonal
        return self._on_pattern(data)

    def _on_pattern(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix of ``data`` on this pattern (its index arrays shared, not copied)."""
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))

    def holds(self, matrix: sp.spmatrix) -> bool:
        """True when ``matrix`` is a CSR matrix on this pattern (as :meth:`matrix` made it)."""
        return (sp.issparse(matrix) and matrix.format == "csr" and _same(matrix.indptr, self.indptr)
                and _same(matrix.indices, self.indices))

    def add_diagonal(self, matrix: sp.spmatrix, diagonal: np.ndarray) -> sp.csr_matrix:
        """``matrix + diag(diagonal)``, on this pattern where ``matrix`` is on it (else SciPy's sum)."""
        if not self.holds(matrix):
            return sp.csr_matrix(matrix + sp.diags(diagonal))
        data = matrix.data.copy()
        data[self._diagonal] += diagonal
        return self._on_pattern(data)

    def symmetric_part(self, matrix: sp.spmatrix, diagonal: np.ndarray | None = None) -> sp.csr_matrix:
        r""":math:`\tfrac12(K + K^T)` (plus ``diagonal``), on this pattern where ``matrix`` is on it (the pattern is
        structurally symmetric, so the transpose of each entry is an entry); else SciPy's sum."""
        if not self.holds(matrix):
            symmetric = 0.5 * (matrix + matrix.T)
            return sp.csr_matrix(symmetric if diagonal is None else symmetric + sp.diags(diagonal))
        data = 0.5 * (matrix.data + matrix.data[self._transpose])
        if diagonal is not None:
            data[self._diagonal] += diagonal
        return self._on_pattern(data)
