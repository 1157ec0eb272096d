r"""Sparse direct solves that keep the symbolic analysis across Newton iterations and load steps.

A direct solve of :math:`K x = b` has three phases: the *analysis* (fill-reducing reordering and
symbolic factorisation, which depend only on the sparsity pattern), the *numerical
factorisation* (which depends on the values) and the *triangular solves* (per right-hand side).
A Newton solve of a finite-element problem keeps one pattern for its whole life, so
:class:`LinearSolver` analyses a pattern once (:meth:`~LinearSolver.analyse`), refactorises for new
values (:meth:`~LinearSolver.factorize`, a no-op when the values are those already factorised, e.g.
the predictor of a retried step) and solves (:meth:`~LinearSolver.solve`).

Backends, fastest first:

* ``"pardiso"`` — Intel MKL PARDISO through ``pypardiso`` (installed by default where MKL wheels
  exist). Phases 11 (analysis, once per pattern), 22 (factorisation), 33 (solve). A symmetric
  matrix (``symmetric=True``: the caller promises :math:`K = K^T`, true for a hyperelastic tangent
  without follower loads, possibly indefinite as in mixed u/p) is factorised from its upper
  triangle with symmetric Bunch–Kaufman pivoting (matrix type −2), about a third faster than the
  general LU (type 11) that a non-symmetric tangent (follower pressure) needs. PARDISO runs in its
  conditional numerical reproducibility mode (``iparm[33]`` = :data:`PARDISO_CNR_THREADS`): its parallel
  factorisation otherwise sums in an order set by the number of OpenMP threads, which numba's
  ``NUMBA_NUM_THREADS`` also sets, and differed in the last bits between 1 and 2 threads (and from run to run
  on larger systems); measured cost on 2 cores: about 5 % of the factorisation time at 20 600 dofs
  (1.85 -> 1.95 s for 8 factorisations and solves), within the noise at 15 000.
* ``"umfpack"`` — ``scikit-umfpack`` when installed.
* ``"scipy"`` — SciPy's SuperLU, always available, much slower on large 3D problems. The
  fill-reducing ordering of the first factorisation (minimum degree on :math:`A^T + A` when
  symmetric, COLAMD otherwise) is kept and reused with ``permc_spec="NATURAL"`` on the permuted
  matrix (:math:`PAP^T`, resp. :math:`AP^T`), the SuperLU analogue of keeping the analysis.

Choosing: ``solver=None`` takes the fastest available backend and warns once per process when
that is SciPy; an explicitly requested backend that is not installed raises
:class:`SolverUnavailableError` instead of silently falling back.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
import sys
import threading
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .sparse_patterns import rows_sorted_unique, upper_triangle

__all__ = [
    "LinearSolver", "NotPositiveDefiniteError", "SolverStatistics", "SolverUnavailableError", "SlowSolverWarning",
    "solve", "solver_name",
    "available_solvers", "cached_solver", "clear_cache", "solve_if_definite",
]

#: PARDISO's ``iparm[33]``: the thread count whose reduction order every factorisation follows, whatever the
#: number of threads it runs on, so that a solve is bitwise the same for any ``NUMBA_NUM_THREADS`` /
#: ``MKL_NUM_THREADS`` on one machine.
PARDISO_CNR_THREADS = max(os.cpu_count() or 1, 1)
_BACKENDS = (("pardiso", "pypardiso"), ("umfpack", "scikits.umfpack"))


class NotPositiveDefiniteError(np.linalg.LinAlgError):
    """A :class:`LinearSolver` with ``definite=True`` met a non-positive pivot: the matrix is not positive definite."""


class SolverUnavailableError(ImportError):
    """An explicitly requested sparse solver backend is not installed."""


class SlowSolverWarning(UserWarning):
    """The fast direct solver (PARDISO) is not installed; SciPy's SuperLU is used instead."""


def _has(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # pragma: no cover - broken installs
        return False


def available_solvers() -> list[str]:
    """Backends importable here, fastest first (``"scipy"`` is always last)."""
    return [name for name, module in _BACKENDS if _has(module)] + ["scipy"]


_warned_fallback = False


def solver_name(preferred: str | None = None) -> str:
    """The backend a solve uses: ``preferred``, or the fastest available one when ``None``.

    Raises ``ValueError`` for an unknown name and :class:`SolverUnavailableError` when ``preferred``
    is not installed. Warns once per process (:class:`SlowSolverWarning`) when ``None`` resolves to
    SciPy's SuperLU because PARDISO is missing.
    """
    global _warned_fallback
    names = available_solvers()
    if preferred is None:
        if names[0] == "scipy" and not _warned_fallback:
            _warned_fallback = True
            warnings.warn(
                "pypardiso (Intel MKL PARDISO) is not installed: sparse solves use SciPy's SuperLU, which is "
                "10-20x slower on large 3D problems; `pip install pypardiso` where MKL wheels exist "
                "(Linux/Windows x86-64)", SlowSolverWarning, stacklevel=2,
            )
        return names[0]
    if preferred not in ("pardiso", "umfpack", "scipy"):
        raise ValueError(f"unknown sparse solver {preferred!r}; choose pardiso, umfpack or scipy")
    if preferred not in names:
        module = dict(_BACKENDS)[preferred]
        raise SolverUnavailableError(
            f"sparse solver {preferred!r} was requested but its package {module!r} is not installed "
            f"(available: {', '.join(names)}); install it or pass solver=None for the fastest available one"
        )
    return preferred


@dataclass
class SolverStatistics:
    """How often each phase ran (the analysis should run once per pattern)."""

    analyses: int = 0
    factorizations: int = 0
    reused_factorizations: int = 0
    solves: int = 0


class _Pardiso:
    """Thin ctypes driver of MKL PARDISO (zero-based CSR, phases called explicitly)."""

    _function = None  # the ctypes ``pardiso`` of mkl_rt, located once per process (pypardiso globs for it)

    def __init__(self, mtype: int) -> None:
        if _Pardiso._function is None:
            import pypardiso  # optional dependency, loaded only when this backend is used

            _Pardiso._function = pypardiso.PyPardisoSolver(mtype=mtype)._mkl_pardiso
        self._pardiso = _Pardiso._function
        self.mtype = mtype
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        self.iparm[0] = 1  # iparm given explicitly (entries left 0 take MKL defaults)
        self.iparm[1] = 2  # nested dissection (METIS) reordering
        self.iparm[7] = 20  # up to 20 iterative refinement steps, stopping once the backward error is small: with CNR
        # (iparm[33]) the weighted matching of the LU left 6e-5 relative residual on a mixed u/p plate strip after 2
        self.iparm[9] = 13 if mtype == 11 else 8  # pivot perturbation 1e-13 / 1e-8 (MKL defaults)
        self.iparm[10] = 1 if mtype == 11 else 0  # scaling (non-symmetric only)
        self.iparm[12] = 1 if mtype == 11 else 0  # weighted matching (non-symmetric only)
        self.iparm[33] = PARDISO_CNR_THREADS  # reproducible for any thread count (module docstring)
        self.iparm[34] = 1  # zero-based indexing
        self.n = 0
        self.active = False

    def call(self, phase: int, data: np.ndarray, indptr: np.ndarray, indices: np.ndarray,
             rhs: np.ndarray | None = None) -> np.ndarray | None:
        error = ctypes.c_int32(0)
        i32 = ctypes.POINTER(ctypes.c_int32)
        f64 = ctypes.POINTER(ctypes.c_double)
        nrhs = 1 if rhs is None or rhs.ndim == 1 else rhs.shape[1]
        b = np.zeros(1) if rhs is None else np.asfortranarray(rhs, dtype=float)
        x = np.zeros_like(b)
        perm = np.zeros(1, dtype=np.int32)
        self._pardiso(
            self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ctypes.byref(ctypes.c_int32(1)),
            ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(self.mtype)),
            ctypes.byref(ctypes.c_int32(phase)), ctypes.byref(ctypes.c_int32(self.n)), data.ctypes.data_as(f64),
            indptr.ctypes.data_as(i32), indices.ctypes.data_as(i32), perm.ctypes.data_as(i32),
            ctypes.byref(ctypes.c_int32(nrhs)), self.iparm.ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(0)),
            b.ctypes.data_as(f64), x.ctypes.data_as(f64), ctypes.byref(error),
        )
        if phase > 0:
            self.active = True
        if error.value == -4 and self.mtype == 2 and phase == 22:
            raise NotPositiveDefiniteError("PARDISO's Cholesky factorisation met a non-positive pivot")
        if error.value != 0:
            raise np.linalg.LinAlgError(f"PARDISO phase {phase} failed with error {error.value}")
        return np.ascontiguousarray(x) if rhs is not None else None

    def release(self) -> None:
        if self.active:
            dummy_i = np.zeros(1, dtype=np.int32)
            self.call(-1, np.zeros(1), dummy_i, dummy_i)
            self.active = False

    def __del__(self) -> None:  # pragma: no cover - depends on garbage collection
        if not sys.is_finalizing():
            self.release()


class LinearSolver:
    """Direct solver of ``K x = b`` for a fixed sparsity pattern and changing values.

    Parameters
    ----------
    solver : ``"pardiso"``, ``"umfpack"``, ``"scipy"`` or ``None`` (fastest available; see
        :func:`solver_name`).
    symmetric : promise that every matrix factorised is symmetric; only its upper triangle is
        then used (PARDISO symmetric indefinite, matrix type −2).
    definite : (with ``symmetric``) factorise by Cholesky (PARDISO's matrix type 2), for a caller that wants a
        solution only where the matrix is positive definite: :meth:`factorize` raises
        :class:`NotPositiveDefiniteError` at the first non-positive pivot, usually long before a whole
        factorisation. On the 1.0 diseased valve's tangent (74 250 dofs, one job per core under load 4) with 5, 50 and
        185 negative eigenvalues it gave up after 0.58, 0.22 and 0.02 s where the symmetric indefinite factorisation
        took 2.5-2.6 s to count them; on a positive definite one both took 2.4-2.5 s and their solutions agreed to
        2e-13. Other backends factorise as without it (:meth:`inertia` then None).

    Use::

        solver = LinearSolver(None, symmetric=True)
        solver.analyse(K)              # once per sparsity pattern (any values)
        solver.factorize(K.data)       # values in the order of K.indices (or a CSR matrix)
        x = solver.solve(rhs)
    """

    def __init__(self, solver: str | None = None, symmetric: bool = False, definite: bool = False) -> None:
        self.name = solver_name(solver)
        self.symmetric = bool(symmetric)
        if definite and not symmetric:
            raise ValueError("LinearSolver: definite=True needs symmetric=True")
        self.definite = bool(definite)
        self.statistics = SolverStatistics()
        self._indptr: np.ndarray | None = None
        self._indices: np.ndarray | None = None
        self._factor = None
        self._factorized_values: np.ndarray | None = None
        self._pardiso: _Pardiso | None = None
        self._permutation: np.ndarray | None = None
        self._permuted = False
        self.n = 0

    # ------------------------------------------------------------------ pattern
    def matches(self, indptr: np.ndarray, indices: np.ndarray) -> bool:
        """True when ``(indptr, indices)`` is the pattern analysed last."""
        return (self._indptr is not None and indptr.shape == self._indptr.shape
                and indices.shape == self._indices.shape and np.array_equal(indptr, self._indptr)
                and np.array_equal(indices, self._indices))

    def analyse(self, pattern: sp.spmatrix | tuple[np.ndarray, np.ndarray]) -> LinearSolver:
        """Take the sparsity pattern (a CSR matrix with sorted indices, or ``(indptr, indices)``).

        The reordering itself runs with the first :meth:`factorize` (PARDISO's scaling and matching
        for non-symmetric matrices need values) and then never again for this pattern.
        """
        if sp.issparse(pattern):
            csr = sp.csr_matrix(pattern)
            csr.sort_indices()
            indptr, indices = csr.indptr, csr.indices
        else:
            indptr, indices = pattern
        indptr = np.asarray(indptr, dtype=np.int64)
        indices = np.asarray(indices, dtype=np.int64)
        n = indptr.size - 1
        if n < 0 or indices.size != indptr[-1] or (indices.size and (indices.min() < 0 or indices.max() >= n)):
            raise ValueError("pattern must be a square CSR pattern (indptr of n+1 entries, indices in 0..n-1); "
                             f"got {indptr.size} indptr entries and {indices.size} indices")
        if self.matches(indptr, indices):
            return self
        if not rows_sorted_unique(indptr, indices):
            raise ValueError("pattern indices must be sorted and unique within each row")
        self._release()
        self._indptr, self._indices, self.n = indptr.copy(), indices.copy(), n
        if self.symmetric:  # upper triangle with every diagonal entry present (PARDISO needs them), and its sources
            self._upper_indptr, self._upper_indices, source = upper_triangle(indptr, indices)
            self._upper_source = np.maximum(source, 0)
            self._upper_inserted = source < 0
        self._indptr32, self._indices32 = indptr.astype(np.int32), indices.astype(np.int32)
        return self

    # ------------------------------------------------------------ factorisation
    def factorize(self, values: np.ndarray | sp.spmatrix) -> LinearSolver:
        """Numerical factorisation for ``values`` on the analysed pattern (skipped if unchanged)."""
        if self._indptr is None:
            raise RuntimeError("LinearSolver.factorize before analyse(pattern)")
        if sp.issparse(values):
            csr = sp.csr_matrix(values)
            csr.sort_indices()
            if not self.matches(np.asarray(csr.indptr, np.int64), np.asarray(csr.indices, np.int64)):
                raise ValueError("matrix pattern differs from the analysed one; call analyse() first")
            values = csr.data
        values = np.asarray(values, dtype=float)
        if values.shape != self._indices.shape:
            raise ValueError(f"values must have {self._indices.size} entries (the pattern); got {values.shape}")
        if self._factorized_values is not None and np.array_equal(values, self._factorized_values):
            self.statistics.reused_factorizations += 1
            return self
        if not np.all(np.isfinite(values)):
            raise np.linalg.LinAlgError("tangent matrix has non-finite entries")
        self._factorized_values = None
        if self.n > 0:  # an empty system (every dof prescribed) has nothing to factorise
            getattr(self, f"_factorize_{self.name}")(values)
        self._factorized_values = values.copy()
        self.statistics.factorizations += 1
        return self

    def _factorize_pardiso(self, values: np.ndarray) -> None:
        first = self._pardiso is None
        if first:
            self._pardiso = _Pardiso(2 if self.definite else -2 if self.symmetric else 11)
            self._pardiso.n = self.n
        if self.symmetric:
            self._data = values[self._upper_source]
            self._data[self._upper_inserted] = 0.0
        else:
            self._data = values
        if first:
            try:
                self._reorder_pardiso()
            except np.linalg.LinAlgError:
                self._release()
                raise
        try:
            self._pardiso.call(22, self._data, *self._pardiso_pattern())
        except NotPositiveDefiniteError:
            raise  # the analysis stays: the next matrix on this pattern is factorised without it
        except np.linalg.LinAlgError:
            self._release()
            raise

    def _reorder_pardiso(self) -> None:
        """PARDISO's analysis (phase 11: reordering and symbolic factorisation), once per pattern; the values of the
        first matrix go with it (scaling and matching of a non-symmetric one)."""
        self._pardiso.call(11, self._data, *self._pardiso_pattern())
        self.statistics.analyses += 1

    def _pardiso_pattern(self) -> tuple[np.ndarray, np.ndarray]:
        if self.symmetric:
            return self._upper_indptr, self._upper_indices
        return self._indptr32, self._indices32

    def _matrix(self, values: np.ndarray) -> sp.csc_matrix:
        return sp.csr_matrix((values, self._indices, self._indptr), shape=(self.n, self.n)).tocsc()

    def _factorize_scipy(self, values: np.ndarray) -> None:
        A = self._matrix(values)
        # symmetric: minimum degree on A^T + A (less fill for FE matrices); else COLAMD on the columns
        spec = "MMD_AT_PLUS_A" if self.symmetric else "COLAMD"
        with warnings.catch_warnings():
            warnings.simplefilter("error", spla.MatrixRankWarning)
            try:
                if self._permutation is None:
                    self._factor = spla.splu(A, permc_spec=spec)
                    self._permutation = self._factor.perm_c.copy()
                    self._permuted = False
                    self.statistics.analyses += 1
                else:  # the kept ordering, applied to the columns (and rows when symmetric), natural order
                    perm = self._permutation
                    self._factor = spla.splu(A[perm][:, perm] if self.symmetric else A[:, perm],
                                             permc_spec="NATURAL")
                    self._permuted = True
            except (RuntimeError, spla.MatrixRankWarning) as err:
                raise np.linalg.LinAlgError(f"singular tangent matrix ({err})") from err

    def _factorize_umfpack(self, values: np.ndarray) -> None:  # pragma: no cover - optional package
        self._factor = self._matrix(values)
        self.statistics.analyses += self.statistics.factorizations == 0

    # --------------------------------------------------------------------- solve
    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """``x`` with ``K x = rhs`` for the last factorised values; ``LinAlgError`` if not finite."""
        if self._factorized_values is None:
            raise RuntimeError("LinearSolver.solve before factorize(values)")
        rhs = np.asarray(rhs, dtype=float)
        if rhs.shape[0] != self.n:
            raise ValueError(f"rhs must have {self.n} rows; got {rhs.shape}")
        if self.n == 0:
            x = np.zeros_like(rhs)
        elif self.name == "pardiso":
            x = self._pardiso.call(33, self._data, *self._pardiso_pattern(), rhs=rhs)
        elif self.name == "scipy":
            perm = self._permutation
            if not self._permuted:
                x = self._factor.solve(rhs)
            else:  # (P A P^T)(P x) = P rhs, or A P^T (P x) = rhs: x[perm] = y
                y = self._factor.solve(rhs[perm] if self.symmetric else rhs)
                x = np.empty_like(y)
                x[perm] = y
        else:  # pragma: no cover - optional package
            x = spla.spsolve(self._factor, rhs, use_umfpack=True)
        self.statistics.solves += 1
        if not np.all(np.isfinite(x)):
            raise np.linalg.LinAlgError("sparse solve returned non-finite values (singular tangent?)")
        return x

    def inertia(self) -> tuple[int, int] | None:
        """(positive, negative) eigenvalue counts of the last symmetric factorisation (Sylvester's law of inertia
        on PARDISO's :math:`LDL^T`), or None where the backend does not report them (non-symmetric, SuperLU)."""
        if self._factorized_values is None:
            raise RuntimeError("LinearSolver.inertia before factorize(values)")
        if self.n == 0:
            return 0, 0
        if self.name != "pardiso" or not self.symmetric:
            return None
        if self.definite:  # a Cholesky factorisation that finished: every pivot positive
            return self.n, 0
        return int(self._pardiso.iparm[21]), int(self._pardiso.iparm[22])

    def _release(self) -> None:
        if self._pardiso is not None:
            self._pardiso.release()
        self._pardiso = None
        self._factor = None
        self._factorized_values = None
        self._permutation = None


class _PerThread(threading.local):
    solvers: dict[tuple[str, bool, bool], LinearSolver]

    def __init__(self) -> None:
        self.solvers = {}


_CACHE = _PerThread()


def clear_cache() -> None:
    """Release the factorisations kept by :func:`solve` in this thread (their memory goes back to MKL)."""
    for linear in _CACHE.solvers.values():
        linear._release()
    _CACHE.solvers.clear()


def solve(matrix: sp.spmatrix, rhs: np.ndarray, solver: str | None = None, symmetric: bool = False) -> np.ndarray:
    """Solve ``matrix @ x = rhs`` (square) and return ``x``.

    Keeps one :class:`LinearSolver` per (backend, symmetric) and thread: consecutive calls
    with the same sparsity pattern reuse its analysis, with the same values its factorisation.
    ``symmetric=True`` promises ``matrix == matrix.T``. Raises ``np.linalg.LinAlgError`` when the
    system is singular or the result is not finite. :func:`clear_cache` frees the kept factors.
    """
    csr = sp.csr_matrix(matrix)
    csr.sort_indices()
    linear = cached_solver(solver, symmetric)
    linear.analyse((csr.indptr, csr.indices))
    linear.factorize(csr.data)
    return linear.solve(rhs)


def cached_solver(solver: str | None = None, symmetric: bool = False, definite: bool = False) -> LinearSolver:
    """The :class:`LinearSolver` that :func:`solve` keeps for ``(solver, symmetric, definite)`` in this thread."""
    key = (solver_name(solver), bool(symmetric), bool(definite))
    if key not in _CACHE.solvers:
        _CACHE.solvers[key] = LinearSolver(*key)
    return _CACHE.solvers[key]


def solve_if_definite(matrix: sp.spmatrix, rhs: np.ndarray, solver: str | None = None) -> np.ndarray | None:
    """``x`` with ``matrix @ x = rhs`` for a symmetric ``matrix`` that is positive definite, ``None`` when its
    Cholesky factorisation (PARDISO's matrix type 2, :class:`LinearSolver` with ``definite=True``) meets a
    non-positive pivot or it is singular: a matrix that is not definite usually costs a fraction of a factorisation.
    Unlike the symmetric indefinite factorisation used before (whose pivots below 1e-8 of the matrix's size PARDISO
    perturbed and counted), a matrix singular only to rounding can pass as definite; the callers add a pseudo-mass or
    a shift, which keeps their matrices clear of that.
    Raises :class:`SolverUnavailableError` with a backend that has no such factorisation (SciPy's SuperLU)."""
    linear = cached_solver(solver, symmetric=True, definite=True)
    if linear.name != "pardiso":
        raise SolverUnavailableError(f"solve_if_definite needs PARDISO's Cholesky; the backend is {linear.name!r}")
    csr = sp.csr_matrix(matrix)
    csr.sort_indices()
    linear.analyse((csr.indptr, csr.indices))
    try:
        linear.factorize(csr.data)
        return linear.solve(rhs)
    except np.linalg.LinAlgError:
        return None

