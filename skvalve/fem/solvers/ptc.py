r"""Pseudo-transient continuation (Ψtc): a linearly implicit, damped path to an equilibrium.

Newton with load steps asks for an equilibrium at every step; a structure with mechanisms along the path
(leaflets that swing freely until their chords or neighbours stop them, cables between slack and taut) has
steps where the damped equilibrium is far from the start and Newton needs tens of iterations or fails. Ψtc
(Kelley & Keyes 1998, *SIAM J. Numer. Anal.* 35:508; Coffey, Kelley & Keyes 2003) asks for no equilibrium on
the way: each pseudo-time step :math:`\Delta\tau_k` takes *one* linearised implicit-Euler step of the
gradient-like flow :math:`c\,M\,\dot u = -R(u, t)`,

.. math::

    \Big(K_{ff}(u_k, t_{k+1}) + \frac{c}{\Delta\tau_k}\,M_{ff}\Big)\,\Delta u_f
        = -R_f(u_k, t_{k+1}) - K_{fD}\,\Delta u_D ,

with :math:`M` a diagonal of lumped nodal volumes (optionally plus :math:`\beta\,|\mathrm{diag}\,K_{ff}|/c`, a
stiffness-proportional part), the load factor following pseudo-time up to ``end``
(:math:`t_{k+1} = \min(\tau_k + \Delta\tau_k, t_\text{end})`, prescribed values and loads included) and held after.
The step length follows switched evolution relaxation (SER),
:math:`\Delta\tau_{k+1} = \Delta\tau_k \min(g, \lVert R_k\rVert / \lVert R_{k+1}\rVert)`: while the residual
falls the damping :math:`c/\Delta\tau` fades and the iteration becomes Newton's, converging quadratically to
the undamped equilibrium. :math:`R` is always the undamped residual (the damping lives in the matrix only),
so the convergence test is on the problem itself.

A step is rejected (terms rewound, :math:`\Delta\tau` cut) when an element inverts, when some node would move
more than ``max_increment`` (a trust region), or when :math:`\lVert R\rVert` grows by more than ``blow_up``;
a step below ``min_step`` raises :class:`~skvalve.fem.errors.ConvergenceError` (or the inversion's
:class:`~skvalve.fem.errors.NonPositiveJacobianError`) with pseudo-step and load factor, the last accepted
state in ``error.last_state``.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from tqdm.auto import tqdm

from ..errors import ConvergenceError, NonPositiveJacobianError
from ..problem import Problem
from . import linsolve
from .newton import reference_force
from .ptc_options import PseudoTransientOptions

__all__ = ["PseudoTransientOptions", "PseudoTransientStep", "PseudoTransientResult", "pseudo_transient",
           "switched_evolution_factor"]

logger = logging.getLogger("skvalve.fem")


@dataclass
class PseudoTransientStep:
    """What a callback receives after each accepted pseudo-step."""

    problem: Problem
    step: int
    pseudo_time: float
    load_factor: float
    u: np.ndarray
    residual_norm: float
    relative_residual: float


@dataclass
class PseudoTransientResult:
    """Accepted steps (pseudo-time, load factor, step length, residual, largest nodal change) and a state: the last
    accepted one, except after giving up at the held load, where ``u`` (``load_factor``, ``relative_residual``) is
    the held state with the smallest residual, accepted step ``kept_step`` (1-based; the residuals of a soft
    structure's last held steps can rise and fall by several times)."""

    u: np.ndarray
    load_factor: float
    pseudo_times: list[float] = field(default_factory=list)
    load_factors: list[float] = field(default_factory=list)
    step_lengths: list[float] = field(default_factory=list)
    residuals: list[float] = field(default_factory=list)
    largest_increments: list[float] = field(default_factory=list)
    rejected: int = 0
    converged: bool = False
    relative_residual: float = math.inf
    kept_step: int | None = None
    timings: dict[str, float] = field(default_factory=lambda: {"assembly": 0.0, "solve": 0.0})


@dataclass
class _Kept:
    """The held state with the smallest residual so far, with the terms' state at that step."""

    norm: float
    u: np.ndarray
    load_factor: float
    relative: float
    step: int
    terms: dict[str, np.ndarray]


class _Rejected(Exception):
    """A pseudo-step that failed a test: the factor to cut the step by, and the nodes to damp locally (if any)."""

    def __init__(self, message: str, factor: float = 0.25, nodes: np.ndarray | None = None) -> None:
        super().__init__(message)
        self.factor, self.nodes = factor, nodes


def switched_evolution_factor(previous: float, current: float, growth: float, held: float = 1.0) -> float:
    r"""Switched evolution relaxation's pseudo-step factor :math:`\lVert R_{k-1}\rVert/\lVert R_k\rVert`, at
    least ``held`` while the residual does not grow and at least 1/2 when it does, at most ``growth``.

    The pseudo-step grows as the residual falls, so :math:`\Delta\tau\,\lVert R\rVert` stays about constant and
    the damping fades into Newton's steps near the equilibrium (Mulder & Van Leer 1985, J Comput Phys 59:232)."""
    return min(growth, max(previous / max(current, 1e-300), held if current <= previous else 0.5))


def pseudo_transient(problem: Problem, weights: np.ndarray, end: float, options: PseudoTransientOptions | None = None,
                     *, u0: np.ndarray | None = None, t0: float = 0.0, edges: np.ndarray | None = None,
                     rest_lengths: np.ndarray | None = None,
                     callbacks: Sequence[Callable[[PseudoTransientStep], None]] = (), progress: bool = True,
                     verbose: bool = False,
                     limit: Callable[[np.ndarray, np.ndarray], float] | None = None) -> PseudoTransientResult:
    """Follow the load factor from ``t0`` to ``end`` and relax to the equilibrium at ``end`` (module docstring).

    ``weights``: the diagonal :math:`M` (n_dofs,), e.g. :func:`~skvalve.fem.solvers.damping.lumped_volume`; dofs with
    zero weight get no damping. ``edges``: (m, 2) node pairs (element edges, cables) watched by
    ``max_strain_increment``, ``rest_lengths`` the lengths from which each carries tension (default: the reference
    lengths; for a cable, its rest length). ``limit``: ``limit(u, du) -> f`` in (0, 1], the fraction of a pseudo-step's
    increment that may be taken (e.g. :func:`~skvalve.fem.contact.clearance.clearance_fraction`); a step with ``f < 1``
    is rejected and ``dtau`` cut to ``max(0.1, 0.8 f)`` of itself (a pseudo-step's increment shrinks about as ``dtau``).
    Returns a :class:`PseudoTransientResult` with ``converged`` set; raises
    :class:`~skvalve.fem.errors.ConvergenceError` / :class:`~skvalve.fem.errors.NonPositiveJacobianError` when the
    step falls below ``min_step`` or ``max_steps`` pass (``error.last_state``: the last accepted result).
    """
    opts = options or PseudoTransientOptions()
    solver = linsolve.solver_name(opts.solver)
    n = problem.space.n_dofs
    weights = np.array(weights, dtype=float).ravel()
    if weights.shape != (n,) or not np.all(np.isfinite(weights) & (weights >= 0.0)):
        raise ValueError(f"weights must be {n} finite values >= 0")
    if not (math.isfinite(end) and end >= t0 >= 0.0):
        raise ValueError(f"need 0 <= t0 <= end; got t0={t0!r}, end={end!r}")
    if edges is not None:
        edges = _checked_edges(problem, edges, rest_lengths)
    floor = weights.copy()
    positive = floor[floor > 0.0]
    if positive.size:  # local damping needs a weight on every displacement dof to multiply
        floor[: problem.space.n_u] = np.maximum(floor[: problem.space.n_u], float(np.median(positive)) * 1e-3)
    boost = np.ones(n)  # local damping factors (1: none)
    problem.check_supports()
    pattern = problem.pattern
    fixed, free = pattern.fixed, pattern.free
    u = np.zeros(n) if u0 is None else np.array(u0, dtype=float)
    _, values = problem.constrained(t0)
    u[fixed] = values
    result = PseudoTransientResult(u=u, load_factor=t0)
    start = time.perf_counter()
    residual, tangent = problem.assemble(u, t0, tangent=True, step=0)
    result.timings["assembly"] += time.perf_counter() - start
    norm = float(np.linalg.norm(residual[free]))
    tau, t, dtau = t0, t0, opts.first_step
    held_from = 0 if t0 >= end else None  # index of the first accepted step at the held load
    relative = norm / reference_force(problem, residual, fixed)
    failure: Exception | None = None
    best: _Kept | None = None
    bar = tqdm(total=None if end == t0 else 100, disable=not progress, desc="pseudo-time", leave=False)
    try:
        while len(result.pseudo_times) < opts.max_steps:
            if t >= end and (relative <= opts.rtol or norm <= opts.atol):
                result.converged, result.relative_residual = True, relative
                break
            held = result.residuals[held_from:] if held_from is not None else []
            if opts.stall_steps and len(held) > opts.stall_steps and \
                    min(held[-opts.stall_steps:]) > 0.5 * held[-opts.stall_steps - 1]:
                raise _give_up(problem, None, None, len(result.pseudo_times), t, result, dtau, best,
                               reason=f"stalled: the residual at the held load fell by less than half in "
                                      f"{opts.stall_steps} pseudo-steps (relative {relative:.2e})")
            if dtau < opts.min_step:
                error_type = NonPositiveJacobianError if isinstance(failure, NonPositiveJacobianError) else None
                raise _give_up(problem, error_type, failure, len(result.pseudo_times) + 1, t, result, dtau, best)
            if t < end:
                dtau = min(dtau, opts.max_load_step)
            t_new = min(tau + dtau, end) if t < end else end
            if t < end and end - t_new < 1e-12 * max(1.0, end):
                t_new = end
            step = len(result.pseudo_times) + 1
            if t >= end and opts.held_stiffness_damping is not None:
                beta = opts.held_stiffness_damping
            else:
                beta = opts.stiffness_damping(t_new) if callable(opts.stiffness_damping) else opts.stiffness_damping
            try:
                local = np.where(boost > 1.0, floor, weights)
                trial, trial_residual, trial_tangent, largest, used = _step(
                    problem, u, t, t_new, dtau, tangent, local, boost, norm, opts, solver, step, result.timings, edges,
                    float(beta), limit)
            except _Rejected as err:
                problem.rewind()
                result.rejected += 1
                failure = err.__cause__ if err.__cause__ is not None else err
                factor = err.factor
                if opts.local_damping > 1.0 and err.nodes is not None and err.nodes.size:
                    # damp the nodes that broke a trust region, not the whole problem (cf. selective mass scaling)
                    dofs = problem.space.displacement_dofs(err.nodes).ravel()
                    boost[dofs] = np.minimum(boost[dofs] * opts.local_damping, opts.max_local_damping)
                    factor = max(factor, 0.7)
                logger.info("pseudo-step %d (t=%.5g, dtau=%.3g) rejected: %s", step, t_new, dtau, err)
                if verbose:
                    print(f"  rejected pseudo-step {step} t={t_new:.5g} dtau={dtau:.3g}: {err}", flush=True)
                dtau *= factor
                continue
            problem.commit()
            problem.check_state(trial, t_new)
            if opts.local_damping > 1.0:  # boosts fade: a node damped for one hard step must not stay frozen
                np.maximum(1.0, boost * opts.local_decay, out=boost)
            previous = norm
            u, residual, tangent = trial, trial_residual, trial_tangent
            norm = float(np.linalg.norm(residual[free]))
            tau, t = tau + dtau, t_new
            if held_from is None and t >= end:
                held_from = len(result.residuals)
            relative = norm / reference_force(problem, residual, fixed)
            result.u, result.load_factor, result.relative_residual = u, t, relative
            for name, value in (("pseudo_times", tau), ("load_factors", t), ("step_lengths", dtau),
                                ("residuals", norm), ("largest_increments", largest)):
                getattr(result, name).append(value)
            if t >= end and (best is None or norm < best.norm):
                best = _Kept(norm, u, t, relative, step, problem.state())
            if verbose:
                print(f"pseudo-step {step} tau={tau:.5g} t={t:.5g} dtau={dtau:.3g} |R|={norm:.3e} rel={relative:.3e} "
                      f"max|du|={largest:.3g}", flush=True)
            if not bar.disable:
                bar.n = int(100 * min(t - t0, end - t0) / (end - t0)) if end > t0 else 100
                bar.set_postfix(rel=f"{relative:.1e}", dtau=f"{dtau:.1e}")
                bar.refresh()
            event = PseudoTransientStep(problem, step, tau, t, u, norm, relative)
            for callback in callbacks:
                callback(event)
            dtau_taken = dtau
            if t < end:  # following the load: grow back towards the load path's resolution after cuts
                dtau = min(dtau * opts.load_growth, opts.max_load_step)
            else:  # switched evolution relaxation
                dtau *= switched_evolution_factor(previous, norm, opts.growth, opts.held_growth)
            if opts.fill is not None and used > 0.0:  # aim the next step at a share of the trust regions
                dtau = min(dtau, dtau_taken * opts.fill / used)
            failure = None
        else:
            raise _give_up(problem, None, None, len(result.pseudo_times), t, result, dtau, best,
                           reason=f"{opts.max_steps} pseudo-steps without converging")
    finally:
        bar.close()
    return result


def _step(problem: Problem, u, t_old: float, t_new: float, dtau: float, tangent, weights, boost, norm: float,
          opts: PseudoTransientOptions, solver: str, step: int, timings: dict, edges: tuple | None, beta: float,
          limit=None):
    """One linearised implicit-Euler step with the damping diagonal ``boost * (c weights + beta |diag K|)``: the
    trial state, its residual and tangent, the largest nodal move and the largest share of a trust region used;
    raises :class:`_Rejected` (with a cut ``factor`` and the ``nodes`` to damp) when it fails a test."""
    pattern = problem.pattern
    fixed, free = pattern.fixed, pattern.free
    clock = time.perf_counter()
    residual, tangent = problem.assemble(u, t_new, tangent=True, step=step, reuse=tangent)
    rhs = residual.copy()
    trial = u.copy()
    if fixed.size and t_new != t_old:
        _, old_values = problem.constrained(t_old)
        _, new_values = problem.constrained(t_new)
        prescribed = np.zeros_like(u)
        prescribed[fixed] = new_values - old_values
        rhs += problem.apply(tangent, prescribed)
        trial[fixed] = new_values
    K = problem.tangent_matrix(tangent)
    diagonal = opts.damping * weights[free]
    if not (math.isfinite(beta) and beta >= 0.0):
        raise ValueError(f"stiffness_damping must be finite and >= 0; got {beta!r} at load factor {t_new}")
    if beta > 0.0:
        diagonal = diagonal + beta * np.abs(K.diagonal())
    K = problem.add_diagonal(K, boost[free] * diagonal / dtau)
    timings["assembly"] += time.perf_counter() - clock
    clock = time.perf_counter()
    try:
        du_free = linsolve.solve(K, -rhs[free], solver, symmetric=problem.symmetric)
    except np.linalg.LinAlgError as err:
        raise _Rejected(f"singular damped tangent: {err}") from err
    finally:
        timings["solve"] += time.perf_counter() - clock
    if not np.all(np.isfinite(du_free)):
        raise _Rejected("the linear solve returned non-finite values")
    du = np.zeros_like(u)
    du[free] = du_free
    space = problem.space
    moves = np.linalg.norm(du[: space.n_u].reshape(-1, space.dim), axis=1)
    largest = float(np.max(moves, initial=0.0))
    used = largest / opts.max_increment if opts.max_increment is not None else 0.0
    if opts.max_increment is not None and largest > opts.max_increment:
        raise _Rejected(f"a node would move {largest:.3g} > max_increment {opts.max_increment:g}",
                        max(0.1, 0.7 * opts.max_increment / largest), np.flatnonzero(moves > opts.max_increment))
    if limit is not None:
        fraction = _limited(limit, u, trial + du - u, "pseudo-transient")  # with the prescribed increments
        if fraction < 1.0:
            raise _Rejected(f"the step limit allows {fraction:.3g} of the increment", max(0.1, 0.8 * fraction))
    fraction = problem.step_fraction(u, t_old, trial + du, t_new)  # e.g. a barrier's collision-free step
    if fraction < 1.0:
        raise _Rejected(f"term step limit (collision-free share) {fraction:.3g} of the increment",
                        max(0.1, 0.8 * fraction))
    trial[free] += du_free
    if edges is not None and opts.max_strain_increment is not None and edges[0].size:
        changes = _stretch_changes(edges[2], u, trial, edges[0], edges[1])
        worst = int(np.argmax(changes))
        change = float(changes[worst])
        used = max(used, change / opts.max_strain_increment)
        if change > opts.max_strain_increment:
            a, b = edges[0][worst]
            raise _Rejected(f"the stretch of edge {a}-{b} would change by {change:.3g} > max_strain_increment "
                            f"{opts.max_strain_increment:g}", max(0.1, 0.7 * opts.max_strain_increment / change),
                            np.unique(edges[0][changes > opts.max_strain_increment]))
    clock = time.perf_counter()
    try:
        trial_residual, trial_tangent = problem.assemble(trial, t_new, tangent=True, step=step)
    except NonPositiveJacobianError as err:
        raise _Rejected(f"inverted elements: {err}") from err
    finally:
        timings["assembly"] += time.perf_counter() - clock
    trial_norm = float(np.linalg.norm(trial_residual[free]))
    reference = max(norm, float(np.linalg.norm(rhs[free])))
    if not np.isfinite(trial_norm):
        raise _Rejected("the residual is not finite")
    if trial_norm > opts.blow_up * reference and dtau >= opts.accept_jumps_below:
        carriers = _carriers(trial_residual, free, space)
        raise _Rejected(f"|R| grows from {reference:.3e} to {trial_norm:.3e}", nodes=carriers)
    return trial, trial_residual, trial_tangent, largest, used


def _limited(limit, u: np.ndarray, p: np.ndarray, solver: str) -> float:
    """``limit(u, p)``, checked to be a fraction in (0, 1] (``solver`` names the caller in the error)."""
    fraction = float(limit(u, p))
    if not 0.0 < fraction <= 1.0:
        raise ValueError(f"{solver}: the step limit must return a fraction in (0, 1]; got {fraction!r}")
    return fraction


def with_step_fraction(problem: Problem, t: float, limit=None):
    """``limit(u, p)`` combined with the problem's own :meth:`~skvalve.fem.problem.Problem.step_fraction` at the held
    load factor ``t`` (a barrier's collision-free step): the smaller of the two."""

    def combined(u: np.ndarray, p: np.ndarray) -> float:
        fraction = problem.step_fraction(u, t, u + p, t)
        if limit is not None:
            fraction = min(fraction, _limited(limit, u, p, "step limit"))
        return fraction

    return combined


def _carriers(residual: np.ndarray, free: np.ndarray, space, share: float = 0.9, most: int = 1000) -> np.ndarray:
    """The fewest nodes (at most ``most``) that carry ``share`` of the squared free residual: where a step that
    blew up went wrong."""
    masked = np.zeros_like(residual)
    masked[free] = residual[free]
    nodal = (masked[: space.n_u].reshape(-1, space.dim) ** 2).sum(axis=1)
    order = np.argsort(nodal)[::-1][:most]
    count = int(np.searchsorted(np.cumsum(nodal[order]), share * nodal.sum())) + 1
    return order[: min(count, order.size)]


def _stretch_changes(X: np.ndarray, u: np.ndarray, trial: np.ndarray, edges: np.ndarray,
                     rest: np.ndarray) -> np.ndarray:
    r"""The change of each edge's tensile stretch :math:`\max(\ell/L, 1)` between ``u`` and ``trial`` (``rest``: the
    lengths :math:`L` at which each edge starts to carry tension)."""
    n = X.shape[0] * X.shape[1]
    before = X + u[:n].reshape(X.shape)
    after = X + trial[:n].reshape(X.shape)
    old = np.maximum(np.linalg.norm(before[edges[:, 1]] - before[edges[:, 0]], axis=1) / rest, 1.0)
    new = np.maximum(np.linalg.norm(after[edges[:, 1]] - after[edges[:, 0]], axis=1) / rest, 1.0)
    return np.abs(new - old)


def _checked_edges(problem: Problem, edges, rest_lengths) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(pairs, rest lengths, reference nodal coordinates (n, dim)); rest lengths default to the reference ones."""
    space = problem.space
    nodes = space.n_u // space.dim
    pairs = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if pairs.size and (pairs.min() < 0 or pairs.max() >= nodes):
        raise ValueError(f"edges must be node pairs in 0..{nodes - 1}")
    X = np.ascontiguousarray(space.dof_coordinates[:, :nodes].T)
    rest = np.linalg.norm(X[pairs[:, 1]] - X[pairs[:, 0]], axis=1) if rest_lengths is None else \
        np.asarray(rest_lengths, dtype=float).ravel()
    if rest.shape != (pairs.shape[0],) or not np.all(np.isfinite(rest) & (rest > 0.0)):
        raise ValueError(f"edge rest lengths must be {pairs.shape[0]} positive finite lengths")
    return pairs, rest, X


def _give_up(problem: Problem, error_type, cause, step: int, t: float, result: PseudoTransientResult, dtau: float,
             best: _Kept | None, reason: str | None = None):
    if best is not None:  # at the held load: keep its best state, not merely the last
        result.u, result.load_factor, result.relative_residual = best.u, best.load_factor, best.relative
        result.kept_step = best.step
        problem.restore(best.terms)  # e.g. a contact search's memory, so that the kept state evaluates as it did
    if error_type is NonPositiveJacobianError and cause is not None:
        error = NonPositiveJacobianError(cause.elements, step, t)
    else:
        reason = reason or f"the pseudo-time step fell to {dtau:.2e} (last rejection: {cause})"
        error = ConvergenceError(f"pseudo-transient continuation stopped at pseudo-step {step}, load factor {t:.6g}: "
                                 f"{reason}; last accepted load factor {result.load_factor:.6g}"
                                 + (f"; kept the held state of pseudo-step {result.kept_step} (relative residual "
                                    f"{result.relative_residual:.2e})" if result.kept_step is not None else ""))
    error.last_state = result
    return error
