"""Sparse direct solve with the fastest available backend.

Order of preference: PARDISO through ``pypardiso`` (Intel MKL, optional extra ``fast``),
UMFPACK through ``scikit-umfpack`` when installed, then SciPy's SuperLU. All of them
handle non-symmetric matrices (the follower-pressure load stiffness makes the tangent
non-symmetric). A hyperelastic tangent without follower loads is symmetric (possibly
indefinite: mixed u/p, instabilities); with ``symmetric=True`` PARDISO factorises only its
upper triangle with symmetric Bunch–Kaufman pivoting (matrix type -2), about a third faster.
:func:`solver_name` says which backend runs.
"""

from __future__ import annotations

import importlib.util
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["solve", "solver_name", "available_solvers"]


def _has(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # pragma: no cover - broken installs
        return False


def available_solvers() -> list[str]:
    """Backends importable here, fastest first (``"scipy"`` is always last)."""
    names = [name for name, module in (("pardiso", "pypardiso"), ("umfpack", "scikits.umfpack")) if _has(module)]
    return names + ["scipy"]


def solver_name(preferred: str | None = None) -> str:
    """The backend :func:`solve` uses: ``preferred`` if available, else the fastest one."""
    names = available_solvers()
    if preferred is None:
        return names[0]
    if preferred not in ("pardiso", "umfpack", "scipy"):
        raise ValueError(f"unknown sparse solver {preferred!r}; choose pardiso, umfpack or scipy")
    return preferred if preferred in names else names[0]


_PARDISO: dict[int, object] = {}


def _pardiso(mtype: int):
    if mtype not in _PARDISO:
        import pypardiso

        _PARDISO[mtype] = pypardiso.PyPardisoSolver(mtype=mtype)
    return _PARDISO[mtype]


def solve(matrix: sp.spmatrix, rhs: np.ndarray, solver: str | None = None, symmetric: bool = False) -> np.ndarray:
    """Solve ``matrix @ x = rhs`` (square) and return ``x``.

    ``symmetric=True`` promises ``matrix == matrix.T`` (only the upper triangle is then used by
    PARDISO). Raises ``np.linalg.LinAlgError`` when the result is not finite (singular system).
    """
    matrix = sp.csr_matrix(matrix)
    name = solver_name(solver)
    rhs = np.asarray(rhs, dtype=float)
    if name == "pardiso":
        if symmetric:
            upper = sp.triu(matrix, format="csr")
            upper.sort_indices()
            x = _pardiso(-2).solve(upper, rhs)
        else:
            x = _pardiso(11).solve(matrix, rhs)
    elif name == "umfpack":  # pragma: no cover - depends on optional package
        x = spla.spsolve(matrix.tocsc(), rhs, use_umfpack=True)
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("error", spla.MatrixRankWarning)
            try:
                x = spla.spsolve(matrix.tocsc(), rhs, permc_spec="COLAMD", use_umfpack=False)
            except spla.MatrixRankWarning as err:
                raise np.linalg.LinAlgError(f"singular tangent matrix ({err})") from err
    if not np.all(np.isfinite(x)):
        raise np.linalg.LinAlgError("sparse solve returned non-finite values (singular tangent?)")
    return x
