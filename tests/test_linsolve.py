"""Sparse direct solves: analysis kept per pattern, factor reuse, backend choice (skvalve.fem.solvers.linsolve)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from packaging.requirements import Requirement

from skvalve.fem.solvers import linsolve
from skvalve.fem.solvers.linsolve import LinearSolver, SlowSolverWarning, SolverUnavailableError

BACKENDS = [name for name in linsolve.available_solvers() if name != "umfpack"]


def _laplacian_like(n: int, seed: int, symmetric: bool) -> sp.csr_matrix:
    """A well-conditioned sparse matrix with an FE-like pattern (2D 5-point stencil) and random values."""
    rng = np.random.default_rng(seed)
    m = int(np.sqrt(n))
    second_difference = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m))
    lap = sp.kronsum(second_difference, second_difference)
    A = sp.csr_matrix(lap)
    A.data = A.data * (1.0 + 0.2 * rng.random(A.nnz))
    if symmetric:
        A = sp.csr_matrix(0.5 * (A + A.T))
    A.sort_indices()
    return A


def _same_pattern_new_values(A: sp.csr_matrix, seed: int, symmetric: bool) -> sp.csr_matrix:
    B = _laplacian_like(A.shape[0], seed, symmetric)
    assert np.array_equal(B.indptr, A.indptr) and np.array_equal(B.indices, A.indices)
    return B


@pytest.mark.parametrize("symmetric", [True, False])
@pytest.mark.parametrize("name", BACKENDS)
def test_analysis_once_per_pattern_and_solutions_exact(name, symmetric):
    A = _laplacian_like(400, 1, symmetric)
    solver = LinearSolver(name, symmetric=symmetric).analyse(A)
    rng = np.random.default_rng(2)
    for seed in range(3):  # three Newton iterations: new values, same pattern
        K = _same_pattern_new_values(A, 10 + seed, symmetric)
        b = rng.standard_normal(K.shape[0])
        x = solver.factorize(K.data).solve(b)
        reference = spla.spsolve(K.tocsc(), b)  # independent: a fresh SuperLU solve
        assert np.allclose(x, reference, rtol=1e-10, atol=1e-12)
    assert solver.statistics.analyses == 1
    assert solver.statistics.factorizations == 3
    # the same values again (predictor of a retried step): no refactorisation
    solver.factorize(K.data.copy())
    assert solver.statistics.factorizations == 3 and solver.statistics.reused_factorizations == 1
    # a new pattern is analysed again
    C = _laplacian_like(225, 3, symmetric)
    x = solver.analyse(C).factorize(C).solve(np.ones(225))
    assert np.allclose(C @ x, np.ones(225), rtol=1e-10, atol=1e-12)
    assert solver.statistics.analyses == 2


@pytest.mark.parametrize("name", BACKENDS)
def test_symmetric_saddle_point_without_stored_diagonal(name):
    """[[K, B], [B^T, 0]] with the zero block absent from the pattern (PARDISO needs the diagonal)."""
    K = _laplacian_like(100, 4, symmetric=True)
    rng = np.random.default_rng(5)
    B = sp.csr_matrix(rng.standard_normal((100, 3)))
    S = sp.bmat([[K, B], [B.T, None]], format="csr")
    S.sort_indices()
    assert S[100:, 100:].nnz == 0
    b = rng.standard_normal(103)
    x = LinearSolver(name, symmetric=True).analyse(S).factorize(S.data).solve(b)
    assert np.allclose(S @ x, b, rtol=1e-9, atol=1e-10)


def test_module_solve_keeps_the_analysis_between_calls():
    A = _laplacian_like(400, 6, symmetric=True)
    linsolve.clear_cache()
    name = linsolve.solver_name()
    for seed in range(3):
        K = _same_pattern_new_values(A, 20 + seed, symmetric=True)
        x = linsolve.solve(K, np.ones(400), name, symmetric=True)
        assert np.allclose(K @ x, np.ones(400), rtol=1e-10)
    stats = linsolve.cached_solver(name, symmetric=True).statistics
    assert (stats.analyses, stats.factorizations) == (1, 3)
    linsolve.clear_cache()
    assert not linsolve._CACHE.solvers


def test_factorize_rejects_another_pattern_and_order_of_calls():
    A = _laplacian_like(100, 7, symmetric=False)
    solver = LinearSolver("scipy")
    with pytest.raises(RuntimeError, match="before analyse"):
        solver.factorize(A.data)
    solver.analyse(A)
    with pytest.raises(RuntimeError, match="before factorize"):
        solver.solve(np.ones(100))
    with pytest.raises(ValueError, match="pattern differs"):
        solver.factorize(_laplacian_like(144, 7, symmetric=False))
    with pytest.raises(ValueError, match="values must have"):
        solver.factorize(np.ones(3))


@pytest.mark.parametrize("name", BACKENDS)
def test_singular_matrix_raises(name):
    A = sp.csr_matrix(np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
    with pytest.raises(np.linalg.LinAlgError):
        x = LinearSolver(name).analyse(A).factorize(A).solve(np.array([1.0, 0.0, 1.0]))
        # PARDISO perturbs the zero pivot instead of failing: the answer then does not solve the system
        if not np.allclose(A @ x, [1.0, 0.0, 1.0]):
            raise np.linalg.LinAlgError("residual")


# ------------------------------------------------------------ issue 12: fast by default


def test_explicit_pardiso_that_is_missing_is_an_error(monkeypatch):
    monkeypatch.setattr(linsolve, "_has", lambda module: False)
    with pytest.raises(SolverUnavailableError, match="pypardiso"):
        linsolve.solver_name("pardiso")
    with pytest.raises(SolverUnavailableError):
        LinearSolver("pardiso")
    assert linsolve.solver_name("scipy") == "scipy"


def test_fallback_to_scipy_warns_once(monkeypatch):
    monkeypatch.setattr(linsolve, "_has", lambda module: False)
    monkeypatch.setattr(linsolve, "_warned_fallback", False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert linsolve.solver_name() == "scipy"
        assert linsolve.solver_name() == "scipy"
        LinearSolver()
    slow = [w for w in caught if issubclass(w.category, SlowSolverWarning)]
    assert len(slow) == 1 and "pypardiso" in str(slow[0].message)


def test_no_warning_when_pardiso_is_available(monkeypatch):
    monkeypatch.setattr(linsolve, "_has", lambda module: module == "pypardiso")
    monkeypatch.setattr(linsolve, "_warned_fallback", False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SlowSolverWarning)
        assert linsolve.solver_name() == "pardiso"


def test_default_install_depends_on_pypardiso_where_mkl_wheels_exist():
    """pyproject: pypardiso is a default dependency on x86-64 (Linux, Windows, macOS), not elsewhere."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11
    pyproject = Path(__file__).resolve().parents[1] / "pyproject.toml"
    dependencies = [Requirement(d) for d in tomllib.loads(pyproject.read_text())["project"]["dependencies"]]
    pardiso = [r for r in dependencies if r.name == "pypardiso"]
    assert len(pardiso) == 1 and pardiso[0].marker is not None
    marker = pardiso[0].marker
    for system, machine, expected in [("linux", "x86_64", True), ("win32", "AMD64", True),
                                      ("darwin", "x86_64", True), ("linux", "aarch64", False),
                                      ("darwin", "arm64", False)]:
        assert marker.evaluate({"sys_platform": system, "platform_machine": machine}) is expected


@pytest.mark.parametrize("name", BACKENDS)
def test_empty_system_every_dof_prescribed(name):
    empty = sp.csr_matrix((0, 0))
    x = LinearSolver(name, symmetric=True).analyse(empty).factorize(empty).solve(np.zeros(0))
    assert x.shape == (0,)
    assert linsolve.solve(empty, np.zeros(0), name, symmetric=True).shape == (0,)


def test_module_solve_keeps_one_solver_per_thread():
    from concurrent.futures import ThreadPoolExecutor

    matrices = [_laplacian_like(400, 30 + k, symmetric=True) for k in range(4)]

    def work(K):
        x = linsolve.solve(K, np.ones(400), None, symmetric=True)
        return np.linalg.norm(K @ x - np.ones(400))

    with ThreadPoolExecutor(max_workers=2) as pool:
        residuals = list(pool.map(work, matrices * 2))
    assert max(residuals) < 1e-10


@pytest.mark.skipif("pardiso" not in linsolve.available_solvers(), reason="Cholesky through PARDISO")
def test_a_definite_solver_gives_up_on_an_indefinite_matrix_and_keeps_its_analysis():
    """``definite=True`` (PARDISO's Cholesky): a positive definite matrix is solved as by the indefinite
    factorisation; one negative eigenvalue (an eigenvalue of the Laplacian-like matrix shifted below zero) raises
    NotPositiveDefiniteError, as do several; the analysis is kept across the failures (one in all);
    solve_if_definite answers None for the indefinite matrix and the solution for the definite one."""
    A = _laplacian_like(324, 5, symmetric=True).tocsr()  # 18 x 18 grid
    A.sort_indices()
    n = A.shape[0]
    lowest = float(np.linalg.eigvalsh(A.toarray())[0])
    identity = sp.identity(n, format="csr")
    definite = linsolve.LinearSolver("pardiso", symmetric=True, definite=True)
    reference = linsolve.LinearSolver("pardiso", symmetric=True)
    rhs = np.linspace(1.0, 2.0, n)
    for matrix in (A, (A - 0.5 * lowest * identity).tocsr()):
        matrix.sort_indices()
        definite.analyse(matrix).factorize(matrix)
        reference.analyse(matrix).factorize(matrix)
        assert definite.inertia() == (n, 0) == reference.inertia()
        np.testing.assert_allclose(definite.solve(rhs), reference.solve(rhs), rtol=1e-10)
    # one negative eigenvalue; several. (Not a zero one: with the lowest eigenvalue shifted to zero, whether the
    # last pivot comes out positive depends on rounding, and it did with one MKL thread.)
    for shift in (1.5 * lowest, 4.0 * lowest):
        shifted = (A - shift * identity).tocsr()
        shifted.sort_indices()
        definite.analyse(shifted)
        with pytest.raises(linsolve.NotPositiveDefiniteError):
            definite.factorize(shifted)
        assert linsolve.solve_if_definite(shifted, rhs) is None
    assert definite.statistics.analyses == 1
    np.testing.assert_allclose(linsolve.solve_if_definite(A, rhs), reference.analyse(A).factorize(A).solve(rhs),
                               rtol=1e-10)
    with pytest.raises(ValueError, match="definite=True needs symmetric=True"):
        linsolve.LinearSolver("pardiso", definite=True)
