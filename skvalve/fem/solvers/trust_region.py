r"""Energy trust-region Newton at a held load: large steps along the soft, indefinite modes of a floppy structure.

Pseudo-transient continuation (:mod:`skvalve.fem.solvers.ptc`) accepts a step when the residual does not blow up, so
where a structure must travel through a region of negative curvature to reach its equilibrium (a valve still closing
under its held pressure: leaflets that buckle towards coaptation) the residual rises and falls and the damping that
keeps the linearised steps sane also keeps them short. This solver measures progress by the energy instead: for an
(almost) conservative problem the residual is the gradient of a potential :math:`\Pi`, and the change of
:math:`\Pi` along a step :math:`p` is the work of the residual along it,

.. math::

    \Delta\Pi(p) = \int_0^1 R(u + s\,p)\cdot p\,\mathrm ds
        \approx \tfrac16\big(R(u) + 4R(u + \tfrac12 p) + R(u + p)\big)\cdot p

Each term with a potential contributes its own energy difference :math:`\Pi_k(u + p) - \Pi_k(u)`
(:meth:`~skvalve.fem.problem.Problem.potential_energy`: exact, where a barrier's logarithmic growth between
quadrature points defeats a rule), and each term without one (a follower pressure on an open surface) the work of its
residual by Simpson's rule above (exact for a quartic along the step); where the energies' difference is lost in their
rounding, the whole residual's Simpson work. Each step solves

.. math::

    (H + \alpha D)\,p = -R_f ,

with :math:`H` the symmetric part of the tangent, optionally with every symmetric term's element block projected
onto its positive semidefinite part (projected Newton: Teran, Sifakis, Irving & Fedkiw 2005), :math:`D` the
tangent's diagonal (Marquardt's scaling; floored) and :math:`\alpha \ge 0` raised until :math:`H + \alpha D` has
no negative eigenvalue (its inertia, from the symmetric indefinite factorisation; Nocedal & Wright 2006, Sect. 3.4).
The step is then scaled into a trust region on the largest nodal motion :math:`\Delta` (and on the change of tensile
stretch of watched edges), and accepted when the energy falls by at least a fraction :math:`\eta` of what the
quadratic model :math:`m(p) = R\cdot p + \tfrac12 p^T H p` predicts (:math:`\rho = \Delta\Pi/m \ge \eta`; for a
Newton step :math:`H` is the true symmetric part :math:`K_s`). The
ratio steers both controls: a good model (:math:`\rho > 3/4`) lowers :math:`\alpha` tenfold and widens
:math:`\Delta` threefold, a poor one raises :math:`\alpha`; a rejected step gives the nodes that carry its energy rise a
local shift, or halves :math:`\Delta`. With :math:`\alpha = 0` and a tangent whose
symmetric part is positive definite the step is Newton's with the full tangent, and the last iterations converge
quadratically. A trial that a term refuses (:class:`~skvalve.fem.errors.StateRefused`, e.g. an intersection among
collision primitives excluded from the barrier) is rejected as an inverted element is. Each step's
:class:`TrustRegionControl` lets a run stopped there resume as if it had not stopped.
A follower pressure on an open surface (leaflets with free edges) makes the problem non-conservative:
near the equilibrium the work of its non-symmetric part is as large as the energy decrease the model predicts, and
:math:`K_s` may stay indefinite at a stable state. Below ``newton_below`` each step first tries Newton's step with
the full tangent (held to the largest radius, ``max_radius``) and keeps it when the residual norm falls to
``newton_decrease`` of its value, or else the first of its halves, quarters, ... (``newton_backtracks``) that lowers
the norm in proportion to its length: there the merit is the residual, whose root is the equilibrium whatever the
symmetry, and which Newton's direction lowers for any regular tangent. On the 1.0 annuloplasty valve's held load the
energy steps had circled for 400 steps between relative residuals of 2e-4 and 1e-2 while each released energy; from
there, tries backtracked to a quarter or a half of Newton's step brought the residual from 6.6e-3 to 1.8e-9 in 13
steps. The residual is always the
undamped one: converged means :math:`\lVert R_f\rVert \le
\max(\text{atol}, \text{rtol}\cdot f_\text{ref})` (the reactions' and loads' scale, as Newton).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Sequence

import numpy as np
import scipy.sparse as sp
from tqdm.auto import tqdm

from ..errors import ConvergenceError, NonPositiveJacobianError, StateRefused
from ..problem import Problem, Tangent
from . import linsolve
from .incremental import ENERGY_RESOLUTION
from .newton import reference_force
from .ptc import _checked_edges, _limited, _stretch_changes, with_step_fraction
from .trust_region_options import TrustRegionControl, TrustRegionOptions, TrustRegionResult, TrustRegionStep
from .trust_steps import (
    FIT_ABOVE,
    factorize_counted,
    fit_radius,
    fitted_shift,
    largest_motion,
    on_all_dofs,
    project_psd,
    project_sparse_psd,
    shifted_direction,
    step_matrix,
)

__all__ = ["TrustRegionControl", "TrustRegionOptions", "TrustRegionStep", "TrustRegionResult", "trust_region",
           "step_matrix",
           "project_psd", "project_sparse_psd", "work_along", "fitted_shift"]

logger = logging.getLogger("skvalve.fem")


def work_along(r_start: np.ndarray, r_middle: np.ndarray, r_end: np.ndarray, step: np.ndarray) -> float:
    r"""Simpson's rule for :math:`\int_0^1 R(u + s p)\cdot p\,ds` from the residuals at s = 0, 1/2, 1 (free dofs)."""
    return float((r_start + 4.0 * r_middle + r_end) @ step) / 6.0


class _Attempt(Exception):
    """A step that failed before its energy could be measured (a non-finite residual)."""


def trust_region(problem: Problem, t: float, u0: np.ndarray, options: TrustRegionOptions | None = None, *,
                 edges: np.ndarray | None = None, rest_lengths: np.ndarray | None = None,
                 callbacks: Sequence[Callable[[TrustRegionStep], None]] = (), progress: bool = True,
                 verbose: bool = False, relax: Callable[[np.ndarray, float], tuple] | None = None,
                 limit: Callable[[np.ndarray, np.ndarray], float] | None = None,
                 control: TrustRegionControl | None = None) -> TrustRegionResult:
    """Relax ``problem`` at the held load factor ``t`` from ``u0`` to an equilibrium (module docstring).


    ``relax``: a :class:`~skvalve.fem.solvers.block_relaxation.BlockRelaxation` (``relax(u, t) -> (u, result)``, the
    result with ``iterations`` and ``energy_change``) run before the first step and after each accepted one (e.g. the
    chordae branch points brought to equilibrium with the rest held; only its ``terms`` are assembled again after
    it); its energy change is added to the step's.

    ``limit``: ``limit(u, p) -> f`` in (0, 1], the fraction of a step ``p`` (already held to the radius) that may be
    taken (e.g. :func:`~skvalve.fem.contact.clearance.clearance_fraction`: no node carried through a contact sheet);
    it applies to Newton tries too.

    ``control``: the :class:`TrustRegionControl` of an earlier run's accepted step (``event.control``), to go on from
    its state ``u0`` as that run would have (``max_steps`` counts the steps of both).

    ``edges``/``rest_lengths`` as in :func:`~skvalve.fem.solvers.ptc.pseudo_transient`. Returns a
    :class:`TrustRegionResult` with ``converged`` (or ``stalled``: :attr:`TrustRegionOptions.stall_fraction`) set;
    raises :class:`~skvalve.fem.errors.ConvergenceError` (``error.last_state``: the result up to the last accepted step)
    when the radius falls below ``min_radius``, the shift passes ``max_shift`` or ``max_steps`` pass.
    """
    opts = options or TrustRegionOptions()
    if not math.isfinite(t):
        raise ValueError(f"the held load factor must be finite; got {t!r}")
    solver_name = linsolve.solver_name(opts.solver)
    n = problem.space.n_dofs
    u = np.array(u0, dtype=float).ravel()
    if u.shape != (n,) or not np.all(np.isfinite(u)):
        raise ValueError(f"u0 must be {n} finite values")
    if edges is not None:
        edges = _checked_edges(problem, edges, rest_lengths)
    problem.check_supports()
    limit = with_step_fraction(problem, t, limit)  # the terms' own caps (a barrier's collision-free step) too
    pattern = problem.pattern
    fixed, free = pattern.fixed, pattern.free

    def force_scale(residual: np.ndarray) -> float:
        return opts.reference if opts.reference is not None else reference_force(problem, residual, fixed)

    _, values = problem.constrained(t)
    u[fixed] = values
    result = TrustRegionResult(u=u, load_factor=t)
    # shifted H and K_s by Cholesky (a matrix that is not definite gives up early), K by LU or LDL^T
    solvers = (linsolve.LinearSolver(solver_name, symmetric=True, definite=True),
               linsolve.LinearSolver(solver_name, symmetric=True, definite=True),
               linsolve.LinearSolver(solver_name, symmetric=problem.symmetric))
    clock = time.perf_counter()
    if relax is not None:
        u, _ = relax(u, t)
    residual, tangent = problem.assemble(u, t, tangent=True, step=0)
    problem.commit()  # the start is the first accepted state (e.g. blended contact's facing factors are taken there)
    # the energy change of a step: the potential terms' own energies (exact, where a barrier's singular growth defeats
    # a quadrature) plus the work of the terms without a potential along it (Simpson's rule); the work of the whole
    # residual where the energies' difference is below their rounding (ENERGY_RESOLUTION |E|) within a tenth of the
    # acceptance margin eta |m|
    work_terms = problem.work_terms(u, t)
    energy = problem.potential_energy(u, t, skip=work_terms)
    result.timings["assembly"] += time.perf_counter() - clock
    norm = float(np.linalg.norm(residual[free]))
    relative = norm / force_scale(residual)
    result.relative_residual = relative
    state = control.copy() if control is not None else TrustRegionControl.start(opts, n)
    if state.local.shape != (n,):
        raise ValueError(f"control: {state.local.size} local shifts for {n} dofs")
    radius, shift = state.radius, state.shift
    fallback = state.fallback  # the last positive shift: where to start again when a Newton step is not possible
    local = state.local  # local shifts s_i (relative to D)
    space = problem.space
    bar = tqdm(total=opts.max_steps, initial=state.steps, disable=not progress, desc="trust region", leave=False)
    retry_below, retry_after = state.retry_below, state.retry_after  # when a failed Newton try may be repeated

    def record(step, work, ratio, shift_taken, largest, newton, held_by) -> None:
        result.u, result.relative_residual = u, relative
        result.newton_steps += newton
        for name, value in (("residuals", norm), ("energy_changes", work), ("ratios", ratio),
                            ("shifts", shift_taken), ("largest_increments", largest)):
            getattr(result, name).append(value)
        if verbose:
            print(f"step {step} |R|={norm:.3e} rel={relative:.3e} dPi={work:.3e} rho={ratio:.3f} "
                  f"shift={shift_taken:.3g} max|du|={largest:.3g} radius={radius:.3g} held by {held_by}"
                  f"{' newton' if newton else ''}", flush=True)
        if not bar.disable:
            bar.update(1)
            bar.set_postfix(rel=f"{relative:.1e}", shift=f"{shift:.1e}", radius=f"{radius:.2g}")
        state.steps, state.radius, state.shift, state.fallback, state.local = step, radius, shift, fallback, local
        state.retry_below, state.retry_after = retry_below, retry_after
        state.energy_changes.append(work)
        event = TrustRegionStep(problem, step, t, u, norm, relative, work, ratio, shift, radius, state.copy(),
                                largest)
        for callback in callbacks:
            callback(event)

    try:
        while True:
            if relative <= opts.rtol or norm <= opts.atol:
                result.converged = True
                result.negative_eigenvalues = _negative_eigenvalues(
                    linsolve.LinearSolver(solver_name, symmetric=True), problem, tangent, result)
                break
            if _stalled(state.energy_changes, opts):
                result.stalled = True
                break
            if state.steps >= opts.max_steps:
                raise _give_up(result, f"{opts.max_steps} steps without converging")
            if radius < opts.min_radius:
                raise _give_up(result, f"the trust region shrank to {radius:.2e} (below min_radius)")
            step = state.steps + 1
            state.attempts += 1
            clock = time.perf_counter()
            K = problem.tangent_matrix(tangent)
            if relative <= opts.newton_below and (relative <= retry_below or step >= retry_after):
                result.newton_tries += 1
                # Newton's step may go as far as the largest radius: it is kept by the residual's fall, not by the
                # model, and held to a radius the energy steps have shrunk it cannot halve the residual
                tried = _newton_try(problem, solvers[2], K, residual, u, t, step, opts.max_radius, norm, opts,
                                    result, limit)
                if tried is None:
                    retry_below, retry_after = 0.5 * relative, step + 10
                    if verbose:
                        print(f"  Newton try at step {step} did not lower |R| to {opts.newton_decrease:g} of "
                              f"{norm:.3e}", flush=True)
                else:
                    problem.commit()
                    p, residual, tangent, work, largest = tried
                    u = u + p
                    energy = problem.potential_energy(u, t, skip=work_terms)
                    norm = float(np.linalg.norm(residual[free]))
                    relative = norm / force_scale(residual)
                    retry_below = math.inf
                    record(step, work, math.nan, 0.0, largest, True, "newton try")
                    continue
            symmetric_K = problem.symmetric_part(K)
            H = step_matrix(problem, tangent, opts.project, opts.project_terms, opts.shift_terms) \
                if opts.project or opts.project_terms or opts.shift_terms else symmetric_K
            scale = np.abs(H.diagonal())
            typical = float(np.median(scale[scale > 0.0])) if np.any(scale > 0.0) else 1.0
            diagonal = np.maximum(scale, 1e-3 * typical)
            D = sp.diags(diagonal if opts.shift_scaling == "diagonal" else np.full(scale.size, typical), format="csr")
            model = H  # the model's Hessian: the step matrix without the shifts (the true tangent for Newton)
            if np.any(local[free] > 0.0):
                H = problem.add_diagonal(H, local[free] * diagonal)
            result.timings["assembly"] += time.perf_counter() - clock
            clock = time.perf_counter()
            direction, shift, newton = shifted_direction(solvers, symmetric_K, K, H, D, -residual[free], shift,
                                                         fallback, not np.any(local > 0.0), opts, result)
            if shift > 0.0:
                fallback = shift
            result.timings["solve"] += time.perf_counter() - clock
            if direction is None:
                raise _give_up(result, f"no shift up to max_shift {opts.max_shift:g} gives a positive definite step "
                                       "matrix or a descent direction")
            p = on_all_dofs(direction, n, free)
            largest = largest_motion(p, space)
            fits = result.radius_fits
            if opts.fit_radius and largest > FIT_ABOVE * radius:
                clock = time.perf_counter()
                direction, shift, newton = fit_radius(solvers[0], H, D, -residual[free], direction, shift, newton,
                                                       radius, space, free, opts, result)
                if shift > 0.0:
                    fallback = shift
                result.timings["solve"] += time.perf_counter() - clock
                p = on_all_dofs(direction, n, free)
                largest = largest_motion(p, space)
            factor = min(1.0, radius / largest) if largest > 0.0 else 1.0
            held_by = "radius" if factor < 1.0 else "none"  # what shortened the step (verbose output)
            if result.radius_fits > fits:
                held_by = f"shift fitted to the radius ({result.radius_fits - fits} fits), then {held_by}"
            if edges is not None and opts.max_strain_increment is not None and edges[0].size:
                change = float(np.max(_stretch_changes(edges[2], u, u + factor * p, edges[0], edges[1])))
                if change > opts.max_strain_increment:
                    factor *= opts.max_strain_increment / change
                    held_by = "stretch"
            if limit is not None:
                fraction = _limited(limit, u, factor * p, "trust region")
                if fraction < 1.0:
                    factor *= fraction
                    held_by = "limit"
            p *= factor
            largest *= factor
            r_free, p_free = residual[free], p[free]
            predicted = float(r_free @ p_free + 0.5 * p_free @ ((symmetric_K if newton else model) @ p_free))
            clock = time.perf_counter()
            try:
                middle, middle_tangent = _residual(problem, u + 0.5 * p, t, step)
                # the residual only: the tangent (most of an assembly's cost) is assembled once the step is accepted
                trial_residual, trial_tangent = problem.assemble(u + p, t, tangent=False, step=step)
                if not np.all(np.isfinite(trial_residual)):
                    raise _Attempt("the residual is not finite")
                trial_energy = problem.potential_energy(u + p, t, skip=work_terms)
            except (NonPositiveJacobianError, _Attempt) as err:
                result.timings["assembly"] += time.perf_counter() - clock
                radius = _reject(problem, result, step, largest, err, verbose)
                continue
            result.timings["assembly"] += time.perf_counter() - clock
            nodal_work = _nodal_work(residual, middle, trial_residual, p, free, space)  # where the energy went
            if abs(predicted) * opts.eta >= 10.0 * ENERGY_RESOLUTION * abs(energy):
                work = trial_energy - energy + _work_of(work_terms, (tangent, middle_tangent, trial_tangent), p, free)
            else:  # the energies' difference is lost in their rounding: the work of the whole residual
                work = float(nodal_work.sum())
            ratio = work / predicted if predicted < 0.0 else -math.inf
            refused = None
            if work < 0.0 and ratio >= opts.eta:
                try:  # a state a term refuses (e.g. primitives the barrier excludes crossing): a rejected step
                    problem.check_state(u + p, t)
                except StateRefused as err:
                    refused = err
            if refused is not None:
                radius = _reject(problem, result, step, largest, refused, verbose)
                continue
            if not (work < 0.0 and ratio >= opts.eta):
                problem.rewind()
                result.rejected += 1
                carriers = _carriers(nodal_work) if opts.local_shift > 0.0 else np.zeros(0, dtype=int)
                if carriers.size and carriers.size <= 0.1 * nodal_work.size:
                    dofs = space.displacement_dofs(carriers).ravel()
                    local[dofs] = np.maximum(10.0 * local[dofs], opts.local_shift)
                    radius = 0.7 * largest
                else:
                    radius = 0.5 * largest
                    shift = min(max(4.0 * shift, opts.min_shift), opts.max_shift)
                logger.info("trust-region step %d rejected: energy change %.3e, ratio %.3g", step, work, ratio)
                if verbose:
                    print(f"  rejected step {step}: dPi={work:.3e} m={predicted:.3e} rho={ratio:.3g} max|du|="
                          f"{largest:.3g}; radius {radius:.3g} shift {shift:.3g}; {carriers.size} nodes carry 90 % "
                          f"of the rise{f' (first {carriers[:5].tolist()})' if carriers.size else ''}", flush=True)
                continue
            clock = time.perf_counter()
            trial_residual, trial_tangent = problem.assemble(u + p, t, tangent=True, step=step)  # the last assembled
            result.timings["assembly"] += time.perf_counter() - clock
            problem.commit()
            local *= opts.local_decay
            local[local < opts.min_shift] = 0.0
            u, residual, tangent = u + p, trial_residual, trial_tangent
            energy = problem.potential_energy(u, t, skip=work_terms)  # after the commit (a term's state may move it)
            if relax is not None:
                clock = time.perf_counter()
                relaxed, inner = relax(u, t)
                if inner.iterations:  # only the block's terms touch the dofs it moved
                    u = relaxed
                    residual, tangent = problem.assemble(u, t, tangent=True, step=step, reuse=tangent,
                                                         fresh=relax.terms)
                    problem.commit()
                    problem.check_state(u, t)
                    work += inner.energy_change
                    energy = problem.potential_energy(u, t, skip=work_terms)
                result.timings["assembly"] += time.perf_counter() - clock
            norm = float(np.linalg.norm(residual[free]))
            relative = norm / force_scale(residual)
            shift_taken = 0.0 if newton else shift
            if ratio > 0.75:
                shift = 0.0 if shift / 10.0 < opts.min_shift else shift / 10.0
                if factor < 1.0 or result.radius_fits > fits:  # the radius held the step (scaled, or its shift)
                    radius = min(3.0 * radius, opts.max_radius)
            elif ratio < 0.25:
                shift = min(max(2.0 * shift, opts.min_shift), opts.max_shift)
                radius = max(0.5 * largest, opts.min_radius)
            record(step, work, ratio, shift_taken, largest, newton, held_by)
    finally:
        bar.close()
    return result


def _reject(problem: Problem, result: TrustRegionResult, step: int, largest: float, reason: Exception,
            verbose: bool) -> float:
    """Rewind a trial that failed before its energy decided (an inverted element, a non-finite residual, a refused
    state), count it, and return the halved radius."""
    problem.rewind()
    result.rejected += 1
    radius = 0.5 * largest
    logger.info("trust-region step %d rejected: %s", step, reason)
    if verbose:
        print(f"  rejected step {step}: {reason}; radius {radius:.3g}", flush=True)
    return radius


def _stalled(energy_changes: list[float], opts: TrustRegionOptions) -> bool:
    """Whether the energy drop of the last ``stall_window`` steps averages below ``stall_fraction`` of its average
    over all steps (:class:`TrustRegionOptions`)."""
    if opts.stall_fraction <= 0.0 or len(energy_changes) < opts.stall_window:
        return False
    drops = -np.asarray(energy_changes)
    return float(drops[-opts.stall_window:].mean()) < opts.stall_fraction * float(drops.mean())


def _newton_try(problem, solver, K, residual, u, t, step, radius, norm, opts, result, limit):
    """Newton's step with the full tangent, scaled into ``radius`` (the options' largest), or the first of its
    fractions a = 1/2, 1/4, ... (``newton_backtracks`` halvings) whose residual norm falls below
    ``1 - a (1 - newton_decrease)`` of ``norm``: (step, residual, tangent, trapezoidal work, largest nodal motion), or
    None (rewound) when none does."""
    free, space = problem.pattern.free, problem.space
    clock = time.perf_counter()
    try:
        factorize_counted(solver, K, result)
        direction = solver.solve(-residual[free])
    except np.linalg.LinAlgError:
        return None
    finally:
        result.timings["solve"] += time.perf_counter() - clock
    if not np.all(np.isfinite(direction)):
        return None
    p = np.zeros_like(u)
    p[free] = direction
    largest = largest_motion(p, space)
    if largest > radius:
        p *= radius / largest
        largest = radius
    if limit is not None:
        fraction = _limited(limit, u, p, "trust region")
        p *= fraction
        largest *= fraction
    clock = time.perf_counter()
    fraction = 1.0
    for _ in range(opts.newton_backtracks + 1):
        trial_step = fraction * p
        try:  # the residual first: the tangent only for a try that is taken
            trial, _ = problem.assemble(u + trial_step, t, tangent=False, step=step)
            problem.check_state(u + trial_step, t)
        except (NonPositiveJacobianError, StateRefused):
            trial = None
        if trial is not None and np.all(np.isfinite(trial)) and \
                np.linalg.norm(trial[free]) <= (1.0 - fraction * (1.0 - opts.newton_decrease)) * norm:
            trial, tangent = problem.assemble(u + trial_step, t, tangent=True, step=step)
            result.timings["assembly"] += time.perf_counter() - clock
            work = 0.5 * float((residual[free] + trial[free]) @ trial_step[free])
            return trial_step, trial, tangent, work, fraction * largest
        problem.rewind()
        fraction *= 0.5
    result.timings["assembly"] += time.perf_counter() - clock
    return None


def _negative_eigenvalues(solver, problem, tangent, result) -> int | None:
    """The number of negative eigenvalues of the free-dof :math:`K_s` (None where the backend gives no inertia)."""
    K = problem.tangent_matrix(tangent)
    try:
        factorize_counted(solver, (0.5 * (K + K.T)).tocsr(), result)
    except (np.linalg.LinAlgError, RuntimeError):
        return None
    inertia = solver.inertia()
    return None if inertia is None else inertia[1]


def _work_of(terms: Sequence[int], tangents: tuple[Tangent, Tangent, Tangent], step: np.ndarray,
             free: np.ndarray) -> float:
    """The work of the residual of ``terms`` (indices) along ``step`` by Simpson's rule, from their contributions at
    the step's start, middle and end (:func:`work_along`)."""
    if not terms:
        return 0.0
    n = step.size
    start, middle, end = (sum(tangent.contributions[k].residual(n) for k in terms) for tangent in tangents)
    return work_along(start[free], middle[free], end[free], step[free])


def _nodal_work(r_start, r_middle, r_end, step, free, space) -> np.ndarray:
    """Each node's share of :func:`work_along` (free dofs only; the shares sum to the work)."""
    per_dof = np.zeros_like(step)
    per_dof[free] = (r_start[free] + 4.0 * r_middle[free] + r_end[free]) * step[free] / 6.0
    return per_dof[: space.n_u].reshape(-1, space.dim).sum(axis=1)


def _carriers(nodal_work: np.ndarray, share: float = 0.9) -> np.ndarray:
    """The fewest nodes whose work rises carry ``share`` of the total rise (empty when nothing rose)."""
    rising = np.maximum(nodal_work, 0.0)
    total = rising.sum()
    if total <= 0.0:
        return np.zeros(0, dtype=int)
    order = np.argsort(rising)[::-1]
    count = int(np.searchsorted(np.cumsum(rising[order]), share * total)) + 1
    return np.sort(order[: min(count, order.size)])


def _residual(problem: Problem, u: np.ndarray, t: float, step: int) -> tuple[np.ndarray, Tangent]:
    residual, tangent = problem.assemble(u, t, tangent=False, step=step)
    if not np.all(np.isfinite(residual)):
        raise _Attempt("the residual is not finite")
    return residual, tangent


def _give_up(result: TrustRegionResult, reason: str) -> ConvergenceError:
    error = ConvergenceError(f"trust-region relaxation stopped after {len(result.residuals)} accepted steps "
                             f"({result.rejected} rejected): {reason}; relative residual "
                             f"{result.relative_residual:.2e}")
    error.last_state = result
    return error
