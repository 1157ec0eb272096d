r"""Newton–Raphson with load control, line search and adaptive step cut-back.

A load step goes from the converged state at load factor :math:`t_n` to :math:`t_{n+1}`.
The first iteration is a consistent predictor: with the tangent :math:`K` at the converged
state and the increment :math:`\Delta u_D` of the prescribed displacements it solves

.. math::

    K_{ff}\,\Delta u_f = -R_f(u_n, t_{n+1}) - K_{fD}\,\Delta u_D ,

then iterates :math:`K_{ff}(u^k)\,\Delta u_f = -R_f(u^k, t_{n+1})`. The tangent at :math:`u_n`
is the one assembled at the last accepted iterate of the previous step (load-dependent terms
re-evaluated). A step :math:`u^{k+1} = u^k + \alpha\,\Delta u` is accepted for the largest
:math:`\alpha \in \{c, \tfrac c2, \dots\}` that keeps :math:`J > 0` and does not increase
:math:`\lVert R_f\rVert` (backtracking line search; in the predictor iteration the reference is the larger of
the linearised residual and the true residual at :math:`u_n` with the new prescribed values, which is what a
vanishing step length tends to: a slack cable that a prescribed motion pulls taut has a large true residual
that the tangent at :math:`u_n` does not see). The cap :math:`c \le 1` is the terms' own
(:meth:`~skvalve.fem.problem.Problem.step_fraction`: a barrier's collision-free step, so no iterate passes through
contact); a load step whose prescribed motion alone is not collision-free is cut back. Convergence: relative residual

.. math::

    \lVert R_f \rVert \le \max\big(\text{rtol}\,\max(\lVert R_D\rVert, \lVert f_\text{ext}\rVert),\ \text{atol}\big)
    \quad\text{and (optional)}\quad
    \frac{|\Delta u^k\cdot R^{k-1}|}{|\Delta u^1\cdot R^0|} \le \text{energy\_tol},

with :math:`R_D` the reactions (``atol``, in force units, decides steps whose loads and reactions
vanish, e.g. a stage before the pressure is applied). A step that fails (too many iterations, :math:`J \le 0`,
singular tangent) is retried with half the increment, up to ``max_cutbacks`` times, after
:meth:`~skvalve.fem.problem.Problem.rewind`; a converged step is
:meth:`~skvalve.fem.problem.Problem.commit`-ted, stored in a :class:`Result` and handed to the
callbacks (output, checkpoints). A tangent that is singular at the unloaded state (a body without
enough supports) raises :class:`SingularSystemError` at once.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from tqdm.auto import tqdm

from ..errors import ConvergenceError, NonPositiveJacobianError, OutputError, SingularSystemError, SolverError
from ..problem import Problem
from ..result import Result
from . import linsolve

__all__ = ["solve", "StepEvent", "NewtonOptions"]

logger = logging.getLogger("skvalve.fem")

#: linear solves whose relative residual exceeds this are taken as singular
_LINEAR_RESIDUAL_LIMIT = 1e-6
#: Levenberg-Marquardt shifts of the tangent below this are dropped (a full Newton step), above this capped
_SHIFT_FLOOR, _SHIFT_CEILING = 1e-6, 1e3
#: a line search that cannot reduce |R| still takes its shortest step, unless |R| grows by more than this factor
_BLOW_UP = 1e2


class _StepFailed(Exception):
    pass


@dataclass
class NewtonOptions:
    """Validated options of :func:`solve`."""

    rtol: float = 1e-8
    atol: float = 0.0
    energy_tol: float | None = None
    max_iter: int = 25
    max_cutbacks: int = 6
    line_search: bool = True
    max_line_search: int = 4
    solver: str = "scipy"
    verbose: bool = False
    max_increment: float | None = None
    regularization: float = 0.0
    timings: dict = field(default_factory=lambda: {"setup": 0.0, "assembly": 0.0, "solve": 0.0})

    def __post_init__(self) -> None:
        if not (isinstance(self.rtol, int | float) and math.isfinite(self.rtol) and self.rtol > 0):
            raise ValueError(f"rtol must be a positive finite number; got {self.rtol!r}")
        if not (isinstance(self.atol, int | float) and math.isfinite(self.atol) and self.atol >= 0):
            raise ValueError(f"atol must be a finite number >= 0; got {self.atol!r}")
        if self.energy_tol is not None and not (
            isinstance(self.energy_tol, int | float) and math.isfinite(self.energy_tol) and self.energy_tol > 0
        ):
            raise ValueError(f"energy_tol must be None or a positive finite number; got {self.energy_tol!r}")
        if self.max_increment is not None and not (isinstance(self.max_increment, int | float)
                                                   and math.isfinite(self.max_increment) and self.max_increment > 0):
            raise ValueError(f"max_increment must be None or a positive finite length; got {self.max_increment!r}")
        if not (isinstance(self.regularization, int | float) and math.isfinite(self.regularization)
                and self.regularization >= 0):
            raise ValueError(f"regularization must be a finite number >= 0; got {self.regularization!r}")
        for name, low in (("max_iter", 1), ("max_cutbacks", 0), ("max_line_search", 0)):
            value = getattr(self, name)
            if not isinstance(value, int | np.integer) or isinstance(value, bool) or value < low:
                raise ValueError(f"{name} must be an integer >= {low}; got {value!r}")


@dataclass
class StepEvent:
    """What a callback receives after each converged step (step 0 is the initial state)."""

    problem: Problem
    step: int
    load_factor: float
    u: np.ndarray
    result: Result


def _load_factors(steps, t0: float) -> np.ndarray:
    if np.isscalar(steps):
        if isinstance(steps, bool) or int(steps) != steps or steps < 1:
            raise ValueError(f"steps must be a positive integer or an increasing sequence; got {steps!r}")
        factors = np.linspace(0.0, 1.0, int(steps) + 1)[1:]
    else:
        factors = np.asarray(steps, dtype=float).ravel()
        if factors.size == 0 or np.any(np.diff(factors) <= 0) or factors[0] <= 0 or not np.all(np.isfinite(factors)):
            raise ValueError("load factors must be positive, finite and strictly increasing")
    return factors[factors > t0 * (1 + 1e-12)]


def reference_force(problem: Problem, residual: np.ndarray, fixed: np.ndarray) -> float:
    """The scale of a relative residual: the larger of the reactions' and the external forces' norms (after the
    last :meth:`~skvalve.fem.problem.Problem.assemble`)."""
    return max(np.linalg.norm(residual[fixed]), np.linalg.norm(problem.external_forces), 1e-300)


def _linear_solve(problem: Problem, K, rhs: np.ndarray, opts: NewtonOptions) -> np.ndarray:
    start = time.perf_counter()
    try:
        x = linsolve.solve(K, rhs, opts.solver, symmetric=problem.symmetric)
    except np.linalg.LinAlgError as err:
        raise SingularSystemError(f"singular tangent: {err}") from err
    finally:
        opts.timings["solve"] += time.perf_counter() - start
    scale = np.linalg.norm(rhs)
    if scale > 0 and np.linalg.norm(K @ x - rhs) > _LINEAR_RESIDUAL_LIMIT * scale:
        raise SingularSystemError(
            f"singular tangent: the linear solve leaves a relative residual "
            f"{np.linalg.norm(K @ x - rhs) / scale:.1e} (|du| = {np.linalg.norm(x):.1e})"
        )
    return x


def _newton_step(problem: Problem, u_old, t_old: float, t_new: float, step: int, opts: NewtonOptions, cached=None):
    pat = problem.pattern
    fixed, free = pat.fixed, pat.free
    _, old_values = problem.constrained(t_old)
    _, new_values = problem.constrained(t_new)
    u = u_old.copy()
    start = time.perf_counter()
    # the tangent of the converged state (last accepted trial) is reused: only load terms change with t
    residual, tangent = problem.assemble(u, t_new, tangent=True, step=step, reuse=cached)
    opts.timings["assembly"] += time.perf_counter() - start
    rhs = residual
    moved = fixed.size and np.any(new_values != old_values)
    if moved:
        prescribed = np.zeros_like(u)
        prescribed[fixed] = new_values - old_values
        rhs = residual + problem.apply(tangent, prescribed)
        u[fixed] = new_values
    if t_new != t_old and problem.step_fraction(u_old, t_old, u, t_new) < 1.0:
        # the prescribed motion alone (supports, kinematic obstacles) would carry a surface through another: a
        # shorter load step, not a shorter Newton step, is what can avoid it
        raise _StepFailed(f"the prescribed motion from load factor {t_old:.6g} to {t_new:.6g} is not collision-free "
                          "(or moves a surface vertex farther than one CCD sweep reaches)")
    if free.size == 0:  # every dof prescribed: the state is known, the residual gives the reactions
        residual, tangent = problem.assemble(u, t_new, tangent=True, step=step)
        return u, residual, [], tangent
    reference = reference_force(problem, residual, fixed)
    norm = np.linalg.norm(rhs[free])
    history = []
    if not moved and norm <= max(opts.rtol * reference, opts.atol):
        return u, residual, history, tangent
    energy0, last_error = None, None
    shift = opts.regularization
    for iteration in range(1, opts.max_iter + 1):
        start = time.perf_counter()
        K = problem.tangent_matrix(tangent)
        if shift >= _SHIFT_FLOOR:
            K = problem.add_diagonal(K, shift * np.abs(K.diagonal()))
        opts.timings["assembly"] += time.perf_counter() - start
        try:
            du_free = _linear_solve(problem, K, -rhs[free], opts)
        except SingularSystemError as err:
            failed = _StepFailed(str(err))
            failed.iterations_done = iteration - 1
            raise failed from err
        du = np.zeros_like(u)
        du[free] = du_free
        energy = abs(du_free @ rhs[free])
        energy0 = energy if energy0 is None else energy0
        largest = _largest_nodal(problem, du)
        alpha = 1.0 if opts.max_increment is None or largest <= opts.max_increment else opts.max_increment / largest
        cap = problem.step_fraction(u, t_new, u + alpha * du, t_new)  # e.g. a barrier's collision-free step
        alpha *= cap
        first_length, accepted = alpha, None
        shortest = alpha * 2.0 ** -opts.max_line_search * 1.5
        baseline = norm
        # the predictor's |R| is linearised about u_n; where the full first step does not beat it, the line
        # search's limit is the true residual with the new prescribed values (larger when, e.g., a slack cable
        # turns taut). Assembled only then: an FE2 material pays one RVE evaluation per assembly.
        lazy_baseline = bool(moved and iteration == 1 and opts.line_search)
        for _ in range(opts.max_line_search + 1 + lazy_baseline):  # one more for the re-assembly below
            trial = u + alpha * du
            start = time.perf_counter()
            try:
                trial_residual, trial_tangent = problem.assemble(trial, t_new, tangent=True, step=step)
            except NonPositiveJacobianError as err:
                last_error = err
                alpha *= 0.5
                continue
            finally:
                opts.timings["assembly"] += time.perf_counter() - start
            trial_norm = np.linalg.norm(trial_residual[free])
            if lazy_baseline and not trial_norm <= baseline:
                lazy_baseline = False
                baseline = max(norm, _true_residual(problem, u, t_new, step, free, opts))
                if trial_norm <= baseline:
                    # accepted after all: assembled again so that the last assembled state is the accepted one
                    # (terms with state, e.g. an RVE material's converged networks)
                    continue
            if not opts.line_search or trial_norm <= baseline:
                accepted = (trial, trial_residual, trial_tangent, trial_norm)
                break
            if alpha < shortest:
                # no length reduced |R|: take the shortest one unless the residual blows up (then cut back)
                if not trial_norm <= _BLOW_UP * baseline:
                    raise _StepFailed(f"line search: the residual grows from {baseline:.3e} to {trial_norm:.3e} "
                                      f"even at step length {alpha:g}")
                accepted = (trial, trial_residual, trial_tangent, trial_norm)
                break
            alpha *= 0.5
        if accepted is None:
            raise _StepFailed(str(last_error)) from last_error
        u, residual, tangent, norm = accepted
        if opts.regularization > 0.0:  # Levenberg-Marquardt: relax after a full step, tighten after a short one
            shift = shift * 0.25 if alpha >= first_length else min(4.0 * max(shift, _SHIFT_FLOOR), _SHIFT_CEILING)
        rhs = residual
        reference = reference_force(problem, residual, fixed)
        relative = norm / reference
        relative_energy = energy / energy0 if energy0 > 0 else 0.0
        record = {"step": step, "load_factor": t_new, "iteration": iteration, "residual": norm,
                  "relative_residual": relative, "increment": float(np.linalg.norm(alpha * du_free)),
                  "relative_energy": relative_energy, "alpha": alpha,
                  "largest_increment": alpha * largest}
        history.append(record)
        logger.info("step %d t=%.4g it %d |R|=%.3e rel=%.3e |du|=%.3e energy=%.3e alpha=%.3g", step, t_new,
                    iteration, norm, relative, record["increment"], relative_energy, alpha)
        if opts.verbose:
            print(f"  step {step} t={t_new:.4g} iter {iteration}: |R|/ref={relative:.3e} "
                  f"|du|={record['increment']:.3e} energy={relative_energy:.3e} alpha={alpha:g}")
        if not np.isfinite(norm):
            raise _StepFailed("residual is not finite")
        energy_ok = opts.energy_tol is None or relative_energy <= opts.energy_tol
        if (relative <= opts.rtol or norm <= opts.atol) and energy_ok:
            return u, residual, history, tangent
    raise _StepFailed(f"no convergence in {opts.max_iter} iterations (relative residual {relative:.3e})")


def _largest_nodal(problem: Problem, du: np.ndarray) -> float:
    """The largest nodal displacement change in ``du``."""
    space = problem.space
    return float(np.max(np.linalg.norm(du[: space.n_u].reshape(-1, space.dim), axis=1), initial=0.0))


def _true_residual(problem: Problem, u: np.ndarray, t: float, step: int, free: np.ndarray,
                   opts: NewtonOptions) -> float:
    """|R_f| at ``u`` (the converged state with the new prescribed values), without a tangent; 0 where an
    element inverts there (the linearised residual stays the reference)."""
    start = time.perf_counter()
    try:
        residual, _ = problem.assemble(u, t, tangent=False, step=step)
    except NonPositiveJacobianError:
        return 0.0
    finally:
        opts.timings["assembly"] += time.perf_counter() - start
    return float(np.linalg.norm(residual[free]))


def _notify(callbacks, event: StepEvent) -> None:
    for callback in callbacks:
        try:
            callback(event)
        except Exception as err:  # noqa: BLE001 - any output failure keeps the converged steps
            error = OutputError(f"step callback {callback!r} failed after load step {event.step} "
                                f"(load factor {event.load_factor:.6g}): {type(err).__name__}: {err}")
            error.last_converged = event.result
            raise error from err


def solve(problem: Problem, steps=10, *, rtol: float = 1e-8, atol: float = 0.0, energy_tol: float | None = None,
          max_iter: int = 25, max_cutbacks: int = 6, line_search: bool = True, max_line_search: int = 4,
          solver: str | None = None, progress: bool = True, verbose: bool = False, u0: np.ndarray | None = None,
          t0: float = 0.0, callbacks: Sequence[Callable[[StepEvent], None]] = (),
          max_increment: float | None = None, regularization: float = 0.0) -> Result:
    r"""Solve the load path ``t`` in ``steps`` (int: uniform steps to 1; or increasing factors).

    Parameters
    ----------
    problem : the :class:`~skvalve.fem.problem.Problem` (e.g. a :class:`~skvalve.fem.Solid`).
    steps : number of uniform load steps to ``t = 1``, or the increasing load factors to reach.
    rtol, atol, energy_tol : convergence tolerances (relative residual, absolute residual floor in force
        units, optional relative energy).
    max_iter, max_cutbacks, line_search, max_line_search : Newton controls.
    solver : sparse backend (``"pardiso"``, ``"umfpack"``, ``"scipy"``; default the fastest).
    progress, verbose : a progress bar over load steps; a line per iteration.
    u0, t0 : start from state ``u0`` at load factor ``t0`` (resume); factors <= ``t0`` are skipped.
    callbacks : called with a :class:`StepEvent` after the initial state and each converged step
        (e.g. :class:`skvalve.io.timeseries.TimeSeriesWriter`); a callback that raises ends the
        solve with :class:`OutputError` carrying the converged steps.
    max_increment : optional cap (length units) on any node's displacement change in one iteration: the line
        search starts from the step length that meets it (a trust region against Newton steps thrown far by
        nearly free directions, e.g. cable branch points between slack and taut).
    regularization : initial Levenberg–Marquardt shift :math:`\mu` of each step: the iterations solve
        :math:`(K_{ff} + \mu\,|\mathrm{diag}\,K_{ff}|)\,\Delta u = -R_f`, with :math:`\mu` divided by 4 after a
        full-length step and multiplied by 4 after a shortened one (dropped below 1e-6). It changes the path of the
        iterates, not the equilibrium solved for: a step through a buckling or wrinkling leaflet, where
        :math:`K_{ff}` is indefinite, gets descent directions instead of steps thrown along the unstable mode.

    Returns
    -------
    Result
        The converged steps (the start state first).

    Raises
    ------
    NonPositiveJacobianError, ConvergenceError, SingularSystemError
        When a step fails after ``max_cutbacks`` halvings (all carry ``last_converged``).
    """
    opts = NewtonOptions(rtol, atol, energy_tol, max_iter, max_cutbacks, line_search, max_line_search,
                         linsolve.solver_name(solver), verbose, max_increment, regularization)
    if not (isinstance(t0, int | float) and math.isfinite(t0) and t0 >= 0):
        raise ValueError(f"t0 must be a finite load factor >= 0; got {t0!r}")
    factors = _load_factors(steps, t0)
    start = time.perf_counter()
    problem.check_supports()  # also builds the sparsity pattern once, before the loop
    n = problem.space.n_dofs
    u = np.zeros(n) if u0 is None else np.array(u0, dtype=float)
    if u.shape != (n,):
        raise ValueError(f"u0 must have shape ({n},); got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise ValueError("u0 must be finite")
    residual, _ = problem.assemble(u, t0, tangent=False, step=0)
    result = Result(problem, solver=opts.solver)
    result.timings = opts.timings
    opts.timings["setup"] = time.perf_counter() - start
    result.append(t0, u, residual, [])
    _notify(callbacks, StepEvent(problem, 0, t0, u, result))
    t, target_index = t0, 0
    increment, failures = _nominal(factors, 0, t0), 0
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
                u_new, residual, history, tangent = _newton_step(problem, u, t, t_new, step, opts, cached)
            except (_StepFailed, NonPositiveJacobianError, np.linalg.LinAlgError, ValueError) as err:
                problem.rewind()
                failures += 1
                logger.info("step %d to t=%.4g failed (%s); cut-back %d", step, t_new, err, failures)
                if isinstance(err.__cause__, SingularSystemError) and step == 1 and failures == 1 \
                        and not _iterated(err):
                    raise _singular(err.__cause__, step, t_new, result) from err
                if failures > max_cutbacks:
                    raise _failure(err, step, t_new, result, max_cutbacks) from err
                increment = 0.5 * (t_new - t)
                continue
            was_cut = failures > 0 or increment < _nominal(factors, target_index, t0) * (1 - 1e-12)
            failures = 0
            problem.commit()
            problem.check_state(u_new, t_new)
            u, t = u_new, t_new
            cached = tangent
            result.append(t, u, residual, history)
            _notify(callbacks, StepEvent(problem, step, t, u, result))
            if t == target:
                target_index += 1
                bar.update(1)
            if target_index < len(factors):
                nominal = _nominal(factors, target_index, t0)
                increment = min(2.0 * increment, nominal) if was_cut else nominal
    finally:
        bar.close()
        for callback in callbacks:
            close = getattr(callback, "close", None)
            if close is not None:
                close()
    return result


def _iterated(err: Exception) -> bool:
    """True when the failed step had accepted an iteration before failing (not a start-state singularity)."""
    return bool(getattr(err, "iterations_done", 0))


def _nominal(factors: np.ndarray, index: int, t0: float) -> float:
    previous = factors[index - 1] if index > 0 else t0
    return factors[index] - previous


def _singular(cause: SingularSystemError, step: int, t: float, result: Result) -> SingularSystemError:
    error = SingularSystemError(
        f"the tangent is singular at the start state (load step {step}, load factor {t:.6g}): the body can move "
        f"without resistance — add supports (Dirichlet conditions) that remove every rigid-body motion. ({cause})",
        step, t)
    error.last_converged = result
    return error


def _failure(err: Exception, step: int, t: float, result: Result, max_cutbacks: int) -> SolverError:
    cause = err.__cause__ if isinstance(err, _StepFailed) else None
    if isinstance(err, NonPositiveJacobianError) or isinstance(cause, NonPositiveJacobianError):
        source = err if isinstance(err, NonPositiveJacobianError) else cause
        error = NonPositiveJacobianError(source.elements, step, t)
    elif isinstance(cause, SingularSystemError):
        error = SingularSystemError(
            f"load step {step} to load factor {t:.6g} failed after {max_cutbacks} cut-backs: {err} (a limit or "
            f"bifurcation point, or parts without supports); last converged load factor "
            f"{result.load_factors[-1]:.6g}", step, t)
    else:
        error = ConvergenceError(
            f"load step {step} to load factor {t:.6g} failed after {max_cutbacks} cut-backs: {err}; "
            f"last converged load factor {result.load_factors[-1]:.6g}"
        )
    error.last_converged = result
    return error
