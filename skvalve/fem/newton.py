r"""Newton–Raphson with load control, line search and adaptive step cut-back.

A load step goes from the converged state at load factor :math:`t_n` to :math:`t_{n+1}`.
The first iteration is a consistent predictor: with the tangent :math:`K` at the converged
state and the increment :math:`\Delta u_D` of the prescribed displacements it solves

.. math::

    K_{ff}\,\Delta u_f = -R_f(u_n, t_{n+1}) - K_{fD}\,\Delta u_D ,

then iterates :math:`K_{ff}(u^k)\,\Delta u_f = -R_f(u^k, t_{n+1})`. The tangent at :math:`u_n`
is the one assembled at the last accepted iterate of the previous step (loads re-evaluated). A step
:math:`u^{k+1} = u^k + \alpha\,\Delta u` is accepted for the largest
:math:`\alpha \in \{1, \tfrac12, \dots\}` that keeps :math:`J > 0` and does not increase
:math:`\lVert R_f\rVert` (backtracking line search). Convergence: relative residual

.. math::

    \frac{\lVert R_f \rVert}{\max(\lVert R_D\rVert, \lVert f_\text{ext}\rVert)} \le \text{rtol}
    \quad\text{and (optional)}\quad
    \frac{|\Delta u^k\cdot R^{k-1}|}{|\Delta u^1\cdot R^0|} \le \text{energy\_tol},

with :math:`R_D` the reactions. A step that fails (too many iterations, :math:`J \le 0`,
singular tangent) is retried with half the increment, up to ``max_cutbacks`` times; the
increment grows back after successes. Converged steps are stored in a :class:`Result`.
"""

from __future__ import annotations

import logging
import time

import numpy as np
from tqdm.auto import tqdm

from . import linsolve
from .result import Result
from .solid import ConvergenceError, NonPositiveJacobianError, Solid, SolverError

__all__ = ["solve"]

logger = logging.getLogger("skvalve.fem")


class _StepFailed(Exception):
    pass


def _load_factors(steps) -> np.ndarray:
    if np.isscalar(steps):
        if int(steps) != steps or steps < 1:
            raise ValueError(f"steps must be a positive integer or an increasing sequence; got {steps!r}")
        return np.linspace(0.0, 1.0, int(steps) + 1)[1:]
    factors = np.asarray(steps, dtype=float).ravel()
    if factors.size == 0 or np.any(np.diff(factors) <= 0) or factors[0] <= 0 or not np.all(np.isfinite(factors)):
        raise ValueError("load factors must be positive, finite and strictly increasing")
    return factors


def _reference(solid: Solid, residual: np.ndarray, fixed: np.ndarray) -> float:
    return max(np.linalg.norm(residual[fixed]), np.linalg.norm(solid.external_forces), 1e-300)


def _newton_step(solid: Solid, u_old: np.ndarray, t_old: float, t_new: float, step: int, opts: dict,
                 cached=None):
    pat = solid.pattern
    fixed, free = pat["fixed"], pat["free"]
    _, old_values = solid.constrained(t_old)
    _, new_values = solid.constrained(t_new)
    timings = opts["timings"]
    u = u_old.copy()
    start = time.perf_counter()
    # the tangent of the converged state (last accepted trial) is reused: only loads change with t
    residual, mats = solid.assemble(u, t_new, tangent=True, step=step, reuse=cached)
    timings["assembly"] += time.perf_counter() - start
    rhs = residual
    if fixed.size and np.any(new_values != old_values):
        prescribed = np.zeros_like(u)
        prescribed[fixed] = new_values - old_values
        rhs = residual + solid.apply_elements(mats, prescribed)
        u[fixed] = new_values
        moved = True
    else:
        moved = False
    reference = _reference(solid, residual, fixed)
    norm = np.linalg.norm(rhs[free])
    history = []
    if not moved and norm <= opts["rtol"] * reference:
        return u, residual, history, (solid.internal_forces, mats)
    energy0 = None
    for iteration in range(1, opts["max_iter"] + 1):
        start = time.perf_counter()
        K = solid.tangent_matrix(mats)
        timings["assembly"] += time.perf_counter() - start
        start = time.perf_counter()
        try:
            du_free = linsolve.solve(K, -rhs[free], opts["solver"], symmetric=not solid.pressures)
        except np.linalg.LinAlgError as err:
            raise _StepFailed(f"linear solve failed: {err}") from err
        finally:
            timings["solve"] += time.perf_counter() - start
        du = np.zeros_like(u)
        du[free] = du_free
        energy = abs(du_free @ rhs[free])
        energy0 = energy if energy0 is None else energy0
        alpha, accepted = 1.0, None
        for _ in range(opts["max_line_search"] + 1):
            trial = u + alpha * du
            start = time.perf_counter()
            try:
                trial_residual, trial_mats = solid.assemble(trial, t_new, tangent=True, step=step)
            except NonPositiveJacobianError as err:
                last_error = err
                alpha *= 0.5
                continue
            finally:
                timings["assembly"] += time.perf_counter() - start
            trial_norm = np.linalg.norm(trial_residual[free])
            if not opts["line_search"] or trial_norm <= norm or alpha < 2.0 ** -opts["max_line_search"] * 1.5:
                accepted = (trial, trial_residual, trial_mats, trial_norm)
                break
            alpha *= 0.5
        if accepted is None:
            raise _StepFailed(str(last_error)) from last_error
        u, residual, mats, norm = accepted
        rhs = residual
        reference = _reference(solid, residual, fixed)
        relative = norm / reference
        relative_energy = energy / energy0 if energy0 > 0 else 0.0
        record = {"step": step, "load_factor": t_new, "iteration": iteration, "residual": norm,
                  "relative_residual": relative, "increment": float(np.linalg.norm(alpha * du_free)),
                  "relative_energy": relative_energy, "alpha": alpha}
        history.append(record)
        logger.info("step %d t=%.4g it %d |R|=%.3e rel=%.3e |du|=%.3e energy=%.3e alpha=%.3g", step, t_new,
                    iteration, norm, relative, record["increment"], relative_energy, alpha)
        if opts["verbose"]:
            print(f"  step {step} t={t_new:.4g} iter {iteration}: |R|/ref={relative:.3e} "
                  f"|du|={record['increment']:.3e} energy={relative_energy:.3e} alpha={alpha:g}")
        if not np.isfinite(norm):
            raise _StepFailed("residual is not finite")
        if relative <= opts["rtol"] and (opts["energy_tol"] is None or relative_energy <= opts["energy_tol"]):
            return u, residual, history, (solid.internal_forces, mats)
    raise _StepFailed(f"no convergence in {opts['max_iter']} iterations (relative residual {relative:.3e})")


def solve(solid: Solid, steps=10, *, rtol: float = 1e-8, energy_tol: float | None = None, max_iter: int = 25,
          max_cutbacks: int = 6, line_search: bool = True, max_line_search: int = 4, solver: str | None = None,
          progress: bool = True, verbose: bool = False, output=None, u0: np.ndarray | None = None) -> Result:
    """Solve the load path ``t`` in ``steps`` (int: uniform steps to 1; or increasing factors).

    Returns a :class:`Result` with the converged steps (and the reference state first).
    ``output``: path of a ``.pvd`` ParaView time series written after each converged step.
    Raises :class:`NonPositiveJacobianError` or :class:`ConvergenceError` (both carry
    ``last_converged``) when a step fails after ``max_cutbacks`` halvings.
    """
    if rtol <= 0 or max_iter < 1 or max_cutbacks < 0:
        raise ValueError("rtol must be positive, max_iter >= 1 and max_cutbacks >= 0")
    factors = _load_factors(steps)
    opts = {"rtol": rtol, "energy_tol": energy_tol, "max_iter": int(max_iter), "line_search": line_search,
            "max_line_search": int(max_line_search), "solver": linsolve.solver_name(solver), "verbose": verbose}
    start = time.perf_counter()
    opts["timings"] = {"setup": 0.0, "assembly": 0.0, "solve": 0.0}
    solid._build_pattern()
    u = np.zeros(solid.space.n_dofs) if u0 is None else np.array(u0, dtype=float)
    if u.shape != (solid.space.n_dofs,):
        raise ValueError(f"u0 must have shape ({solid.space.n_dofs},)")
    residual, _ = solid.assemble(u, 0.0, tangent=False, step=0)
    writer = None
    if output is not None:
        from ..io.timeseries import TimeSeriesWriter

        writer = TimeSeriesWriter(output, solid)
    result = Result(solid, solver=opts["solver"], writer=writer)
    result.timings = opts["timings"]
    result.timings["setup"] = time.perf_counter() - start
    result.append(0.0, u, residual, [])
    t, target_index = 0.0, 0
    increment, failures = _nominal(factors, 0), 0
    cached = None
    bar = tqdm(total=len(factors), disable=not progress, desc="load steps", leave=False)
    try:
        while target_index < len(factors):
            target = factors[target_index]
            t_new = min(t + increment, target)
            if target - t_new < 1e-12 * max(1.0, abs(target)):
                t_new = target
            step = len(result.load_factors)
            try:
                u_new, residual, history, converged_state = _newton_step(solid, u, t, t_new, step, opts, cached)
            except (_StepFailed, NonPositiveJacobianError, np.linalg.LinAlgError, ValueError) as err:
                failures += 1
                logger.info("step %d to t=%.4g failed (%s); cut-back %d", step, t_new, err, failures)
                if failures > max_cutbacks:
                    raise _failure(err, step, t_new, result, max_cutbacks) from err
                increment = 0.5 * (t_new - t)
                continue
            was_cut = failures > 0 or increment < _nominal(factors, target_index) * (1 - 1e-12)
            failures = 0
            u, t = u_new, t_new
            cached = converged_state
            result.append(t, u, residual, history)
            if t == target:
                target_index += 1
                bar.update(1)
            if target_index < len(factors):
                nominal = _nominal(factors, target_index)
                increment = min(2.0 * increment, nominal) if was_cut else nominal
    finally:
        bar.close()
        if writer is not None:
            writer.close()
    return result


def _nominal(factors: np.ndarray, index: int) -> float:
    previous = factors[index - 1] if index > 0 else 0.0
    return factors[index] - previous


def _failure(err: Exception, step: int, t: float, result: Result, max_cutbacks: int) -> SolverError:
    if isinstance(err, NonPositiveJacobianError):
        error = NonPositiveJacobianError(err.elements, step, t)
    elif isinstance(err, _StepFailed) and isinstance(err.__cause__, NonPositiveJacobianError):
        cause = err.__cause__
        error = NonPositiveJacobianError(cause.elements, step, t)
    else:
        error = ConvergenceError(
            f"load step {step} to load factor {t:.6g} failed after {max_cutbacks} cut-backs: {err}; "
            f"last converged load factor {result.load_factors[-1]:.6g}"
        )
    error.last_converged = result
    return error
