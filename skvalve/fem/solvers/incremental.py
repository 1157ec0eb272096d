r"""Load steps solved as minimisations: the incremental potential, shifted or projected Newton and a collision-free
line search.

Each load step :math:`t_n \to t_{n+1}` minimises (Kane et al. 2000; Li et al. 2020, Sect. 4)

.. math::

    E(u) = \Pi(u, t_{n+1}) + \frac{1}{2h^2}\,(u - \tilde u)^T M\,(u - \tilde u), \qquad
    \tilde u = u_n + h\,v_n ,

with :math:`\Pi = \sum_k \Pi_k` the terms' potentials (:meth:`~skvalve.fem.problem.Problem.energy`: strain energy,
barrier contact, ...), :math:`M` a diagonal mass (``mass``: e.g. :func:`~skvalve.fem.solvers.damping.lumped_volume`
times the input's density) and :math:`h` the time step; without a mass the step is the static problem, with
``velocity=False`` :math:`\tilde u = u_n` (pseudo-mass: a proximal step that damps, whose fixed point is still the
static equilibrium).
The stationarity of :math:`E` is implicit Euler. Each iteration solves :math:`A\,p = -\nabla E` for a descent
direction :math:`p`, with :math:`A` chosen by ``direction``:

* ``"shifted"`` (default; needs PARDISO's inertia): :math:`A = K_s + M/h^2`, the symmetric tangent, where it is
  positive definite (Newton's step: quadratic rate near a stable minimum); where it is not, the element-projected
  tangent :math:`\mathcal P[K] + M/h^2` (below), and only if that is not definite either (the follower pressure's
  symmetric part is not projected), with Marquardt's diagonal :math:`D = |\mathrm{diag}|` and the smallest shift
  :math:`\mu` of :math:`0, 10^{-6}, 10^{-5}, \dots` for which :math:`A + \mu D` is positive definite
  (:func:`shifted_newton`). On the Texas TriValve leaflet's papillary stage the tangent with the pseudo-mass was
  definite at most iterations and the steps took 204 iterations against 284 projected (77 s against 152 s); on the
  whole valve's held load it was not (16 048 of 18 920 F-bar blocks indefinite), and a shift of :math:`K_s` alone needed
  0.01-1 times the diagonal, which stiffens every direction and left the steps crawling.
* ``"projected"`` (also the fallback without PARDISO): :math:`A = \mathcal P[K] + M/h^2`, the tangent whose element
  blocks (and each contact stencil, ``Contribution.projected_matrix``; a truss's own closed form, ``Blocks.projected``)
  are projected onto their positive semidefinite parts (projected Newton: Teran et al. 2005); once the relative
  residual is below ``newton_below`` the unprojected tangent is tried, falling back to the projected one when its
  step is not a descent direction, and for the rest of the load step once a full-tangent step raised
  :math:`|\nabla E|` (the two would otherwise alternate). Its rate is linear where elements are indefinite.

The step length starts at the terms' cap (:meth:`~skvalve.fem.problem.Problem.step_fraction`: 0.9 of the
collision-free share for a barrier, so no iterate intersects) and is halved until the Armijo condition
:math:`E(u + \alpha p) \le E(u) + c\,\alpha\,\nabla E\cdot p` holds (near convergence, where the predicted
decrease :math:`\alpha\,\nabla E\cdot p` falls below ``ENERGY_RESOLUTION`` :math:`|E|`, a step is accepted when the
gradient's norm falls); a step that ends far past the minimum along :math:`p` (Wolfe's curvature condition fails)
is moved to the zero of the slope's secant. Where a term has no potential (a follower pressure on an open surface is
not conservative) the merit is the residual norm instead (``energy_merit`` False in the history): the line search
then asks that :math:`|\nabla E|` falls, and every iteration takes the unprojected tangent, whose direction is a
descent direction of :math:`|\nabla E|` by construction.
Converged: :math:`\lVert \nabla E_f\rVert \le \max(\text{rtol}\,f_\text{ref}, \text{atol})`, with :math:`f_\text{ref}`
Newton's measure (the reactions' and loads' norm) or a fixed force ``reference`` the caller knows better (e.g. the
end load's nodal forces where reactions concentrated at a few nodes would dwarf a distributed load).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
import scipy.sparse as sp
from tqdm.auto import tqdm

from ..errors import ConvergenceError, NonPositiveJacobianError
from ..problem import Problem, Tangent
from ..result import Result
from . import linsolve
from .newton import StepEvent, reference_force
from .step_start import carried_start, consistent_predictor
from .trust_steps import projected_tangent

__all__ = ["IncrementalOptions", "StepFailed", "incremental_potential", "minimise_step", "projected_tangent",
           "shifted_newton"]

logger = logging.getLogger("skvalve.fem")

#: How an energy-merit iteration finds its descent direction (module docstring)
DIRECTIONS = ("projected", "shifted")
#: the shifted direction's first shift and its growth after a factorisation with a negative pivot
FIRST_SHIFT, SHIFT_GROWTH = 1e-6, 10.0
#: below this last shift the next iteration tries Newton's step first (else a hundredth of the last shift)
NEWTON_AGAIN_BELOW = 1e-3

#: Past ``max_iter`` a step goes on (up to twice as many iterations) while each iteration lowers the gradient norm
#: to at most this share: a contracting iteration is not cut back. Before, the residual after the last allowed
#: iteration was not even tested: on the 1.0 annuloplasty valve a step converging quadratically was cut back after
#: its 40th iteration with a relative residual of 9.8e-4 against its tolerance of 1e-3.
CONTRACTING = 0.5

#: Relative size below which a predicted change of the total potential is lost in its rounding (a sum over every
#: quadrature point and barrier stencil): the line search then asks that the gradient's norm falls instead.
ENERGY_RESOLUTION = 1e-12


@dataclass
class IncrementalOptions:
    """Controls of :func:`incremental_potential` (module docstring)."""

    rtol: float = 1e-8
    atol: float = 0.0
    reference: float | None = None
    max_iter: int = 60
    max_cutbacks: int = 8
    max_line_search: int = 40
    newton_below: float = 1e-3
    armijo: float = 1e-4
    solver: str | None = None
    predictor: bool = True
    stall_alpha: float = 1.0 / 16.0
    stall_iterations: int = 3
    direction: str = "shifted"
    curvature: float = 0.9
    secant_steps: int = 2

    def __post_init__(self) -> None:
        for name in ("rtol", "newton_below", "armijo", "stall_alpha", "curvature"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name} must be a finite number >= 0; got {value!r}")
        if not self.rtol > 0.0:
            raise ValueError(f"rtol must be positive; got {self.rtol!r}")
        if self.reference is not None and not (math.isfinite(self.reference) and self.reference > 0.0):
            raise ValueError(f"reference must be None or a finite force > 0; got {self.reference!r}")
        if self.direction not in DIRECTIONS:
            raise ValueError(f"direction must be one of {DIRECTIONS}; got {self.direction!r}")
        for name in ("max_iter", "max_cutbacks", "max_line_search", "stall_iterations", "secant_steps"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < (1 if name == "max_iter" else 0):
                raise ValueError(f"{name} must be a non-negative integer (max_iter >= 1); got {value!r}")


class StepFailed(Exception):
    """A load step whose minimisation did not converge (the caller rewinds and cuts the step back).

    ``last``: where the iterations ran out after at least one accepted iterate, that iterate as
    ``(u, static residual, history)``; the terms were last assembled with a tangent there, so ``problem.commit()``
    accepts it (an inexact step, e.g. a proximal step that lowered the static residual). ``None`` otherwise."""

    def __init__(self, message: str, last: tuple[np.ndarray, np.ndarray, list[dict]] | None = None) -> None:
        super().__init__(message)
        self.last = last


def incremental_potential(problem: Problem, steps=10, *, mass: np.ndarray | None = None, time_step: float = 1.0,
                          velocity: bool = True, options: IncrementalOptions | None = None,
                          u0: np.ndarray | None = None, t0: float = 0.0,
                          callbacks: Sequence[Callable[[StepEvent], None]] = (), progress: bool = True) -> Result:
    """Follow the load factors ``steps`` (int: uniform to 1; or increasing factors), each step a minimisation.

    ``mass``: diagonal (n_dofs,) or ``None`` (static); ``time_step`` :math:`h`; ``velocity`` False for a pseudo-mass
    (:math:`\\tilde u = u_n`). Returns a :class:`~skvalve.fem.result.Result` (each step's history records the
    iterations, step lengths, whether the energy was the merit and how many steps the collision cap shortened);
    raises :class:`~skvalve.fem.errors.ConvergenceError` after ``max_cutbacks`` halvings of a load step.
    """
    opts = options or IncrementalOptions()
    solver = linsolve.solver_name(opts.solver)
    if isinstance(steps, int | np.integer) and not isinstance(steps, bool):
        if steps < 1:
            raise ValueError(f"steps must be >= 1; got {steps!r}")
        factors = list(np.linspace(t0, 1.0, int(steps) + 1)[1:])
    else:
        factors = [float(f) for f in np.asarray(steps, dtype=float).ravel()]
        if not factors or np.any(np.diff([t0, *factors]) <= 0.0) or not np.all(np.isfinite(factors)):
            raise ValueError("load factors must be finite and increase from t0")
    if not (math.isfinite(time_step) and time_step > 0.0):
        raise ValueError(f"time_step must be positive; got {time_step!r}")
    n = problem.space.n_dofs
    weights = np.zeros(n) if mass is None else np.array(mass, dtype=float).ravel()
    if weights.shape != (n,) or not np.all(np.isfinite(weights) & (weights >= 0.0)):
        raise ValueError(f"mass must be {n} finite values >= 0")
    problem.check_supports()
    u = np.zeros(n) if u0 is None else np.array(u0, dtype=float)
    v = np.zeros(n)
    residual, _ = problem.assemble(u, t0, tangent=False, step=0)
    problem.commit()
    result = Result(problem, solver=solver)
    result.append(t0, u, residual, [])
    for callback in callbacks:
        callback(StepEvent(problem, 0, t0, u, result))
    t, target, failures = t0, 0, 0
    increment = factors[0] - t0
    bar = tqdm(total=len(factors), disable=not progress, desc="incremental potential", leave=False)
    try:
        while target < len(factors):
            t_new = min(t + increment, factors[target])
            step = len(result.load_factors)
            predictor = u + (time_step * v if velocity and mass is not None else 0.0)
            try:
                u_new, residual, history = minimise_step(problem, u, t, t_new, predictor, weights / time_step ** 2,
                                                     step, opts, solver)
            except (StepFailed, NonPositiveJacobianError, np.linalg.LinAlgError) as err:
                problem.rewind()
                failures += 1
                logger.info("incremental step %d to t=%.4g failed (%s); cut-back %d", step, t_new, err, failures)
                if failures > opts.max_cutbacks:
                    error = ConvergenceError(f"load step {step} to load factor {t_new:.6g} failed after "
                                             f"{opts.max_cutbacks} cut-backs: {err}")
                    error.last_converged = result
                    raise error from err
                increment = 0.5 * (t_new - t)
                continue
            problem.commit()
            problem.check_state(u_new, t_new)
            if mass is not None:
                v = (u_new - u) / time_step
            u, t = u_new, t_new
            result.append(t, u, residual, history)
            for callback in callbacks:
                callback(StepEvent(problem, step, t, u, result))
            if t >= factors[target] - 1e-14:
                target += 1
                bar.update(1)
                if target < len(factors):
                    increment = factors[target] - t if failures == 0 else min(2 * increment, factors[target] - t)
            else:
                increment = min(2.0 * increment, factors[target] - t) if failures else increment
            failures = 0
    finally:
        bar.close()
    return result


def minimise_step(problem: Problem, u_old: np.ndarray, t_old: float, t_new: float, predictor: np.ndarray,
                  inertia: np.ndarray, step: int, opts: IncrementalOptions, solver: str,
                  relax: Callable | None = None, carry: Callable | None = None
                  ) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """One load step from ``(u_old, t_old)`` to ``t_new``: the minimiser of the incremental potential with the
    diagonal ``inertia`` (:math:`M/h^2`, or any proximal weight) about ``predictor``; returns its state, the static
    residual there and the iterations' history. Raises :class:`StepFailed` (the caller rewinds the terms).

    ``relax``: a :class:`~skvalve.fem.solvers.block_relaxation.BlockRelaxation` run on the first iterate, on every
    line-search trial and after every accepted iteration with the step's proximal term (``relax(u, t,
    proximal=(inertia, predictor))``; only its ``terms`` are assembled again after it): a nonlinear Gauss–Seidel
    sweep over dofs that cheap, stiff terms alone hold (a valve's chordae branch points), which a global step
    overshoots. It lowers the merit and leaves the step's minimiser unchanged. Inside the line search the merit is
    that of the trial with the block re-minimised (nonlinear elimination of the block), so the block's stiff terms
    no longer cut the step short: on the 1.0 diseased valve's step from step time 0.2 to 0.25, Newton's steps had
    been held to 0.07-0.25 of their length for 28 iterations at a residual of 0.2-0.3 load norms (52 in all); with
    the relaxed trials the step took 34.

    ``carry``: a :class:`~skvalve.fem.solvers.extension.MotionExtension` (``carry(u_old, u, pushed)``): the step
    starts from the prescribed increment's harmonic extension where its merit is lower than with the prescribed dofs
    moved alone and its motion from ``u_old`` is collision-free. The free dofs a term's prescribed motion pushes
    (:meth:`~skvalve.fem.problem.Problem.pushed`: kinematic obstacles moving towards vertices within reach of them,
    :mod:`skvalve.fem.contact.push`) move with it, and the extension carries the rest; where that start is still not
    collision-free, the dofs it crosses ride with what crosses them (:func:`~.step_start.carried_start`)."""
    pattern = problem.pattern
    fixed, free = pattern.fixed, pattern.free
    u = u_old.copy()
    _, values = problem.constrained(t_new)
    u[fixed] = values
    # terms without a potential (their work is integrated along each ray), asked at the accepted state: the
    # prescribed motion alone may fold an element it drags
    work = problem.work_terms(u_old, t_new)
    energy_merit = not work
    moved = bool(fixed.size and np.any(u[fixed] != u_old[fixed]))
    # vertices pressed on an obstacle that moves towards them: its motion alone would cross them (and ipctk's CCD of
    # such a crossing is slow: 32 s for a 2 x 2 x 2 block on a plate rising through it), so they ride with it
    pushed = problem.pushed(u_old, t_old, t_new) if carry is not None else None
    collision_free = pushed is None and problem.step_fraction(u_old, t_old, u, t_new) >= 1.0
    limits = ""
    if carry is not None and (moved or not collision_free):
        u, collision_free, limits = carried_start(problem, u_old, t_old, u, collision_free, t_new,
                                                  partial(carry, u_old, u), pushed, predictor, inertia, step,
                                                  energy_merit)
    if not collision_free:
        carried = f"; the carried start is limited by {limits}" if limits else ""
        raise StepFailed(f"the prescribed motion from load factor {t_old:.6g} to {t_new:.6g} is not collision-free "
                         f"(or moves a surface vertex farther than one CCD sweep reaches){carried}")
    if opts.predictor and moved:
        u = consistent_predictor(problem, u_old, u, t_new, predictor, inertia, step, solver, energy_merit)
    if relax is not None:
        u, _ = relax(u, t_new, proximal=(inertia, predictor))
    residual, tangent = problem.assemble(u, t_new, tangent=True, step=step)
    gradient = residual + inertia * (u - predictor)

    def potential(state: np.ndarray) -> float:
        """The potential part of the incremental potential at ``state`` (+inf where a term refuses the state)."""
        d = state - predictor
        return 0.5 * float(d @ (inertia * d)) + problem.potential_energy(state, t_new, skip=work)

    def work_force(contributions) -> np.ndarray:
        force = np.zeros(problem.space.n_dofs)
        for k in work:
            force += contributions[k].residual(problem.space.n_dofs)
        return force

    history = []
    short = 0
    newton_allowed = True  # False once a full-tangent step raised |grad E| (a non-convex region: stay projected)
    shifted = opts.direction == "shifted" and solver == "pardiso"
    shift, projected = 0.0, False
    mass = inertia[free]

    def projected_with_mass(tangent: Tangent) -> sp.csr_matrix:
        return projected_tangent(problem, tangent, diagonal=mass)

    def scale(residual: np.ndarray) -> float:
        """The relative residual's force scale: ``opts.reference``, else the reactions' and loads' norm."""
        return opts.reference if opts.reference is not None else reference_force(problem, residual, fixed)

    iteration, before = 0, math.inf  # before: |grad E| before the last iteration
    while True:
        reference = scale(residual)
        norm = float(np.linalg.norm(gradient[free]))
        if norm <= max(opts.rtol * reference, opts.atol):
            return u, residual, history
        if iteration >= opts.max_iter and not (iteration < 2 * opts.max_iter and norm <= CONTRACTING * before):
            raise StepFailed(f"no convergence in {iteration} iterations (relative residual {norm / reference:.3e})",
                             last=(u, residual, history) if history else None)
        iteration, before = iteration + 1, norm
        clock = time.perf_counter()
        if shifted:
            K = problem.tangent_matrix(tangent)
            H = problem.symmetric_part(K, diagonal=mass)  # K itself where every term has a potential
            direction, shift, projected = shifted_newton(H, -gradient[free], shift, solver,
                                                         fallback=partial(projected_with_mass, tangent))
            newton = shift == 0.0 and not projected and energy_merit
            if shift < NEWTON_AGAIN_BELOW and not energy_merit and norm <= opts.newton_below * reference:
                # near the solution: the full (non-symmetric) tangent for Newton's rate, where it points downhill
                full = linsolve.solve(problem.add_diagonal(K, mass), -gradient[free], solver)
                if float(full @ gradient[free]) < 0.0:
                    direction, newton = full, True
        else:
            # without a potential: Newton's direction (the projected one need not lower |grad E|); with one:
            # projected Newton until close
            newton = (newton_allowed and norm <= opts.newton_below * reference) or not energy_merit
            K = problem.tangent_matrix(tangent, diagonal=mass) if newton else projected_with_mass(tangent)
            direction = linsolve.solve(K, -gradient[free], solver, symmetric=problem.symmetric or not newton)
            if newton and not float(direction @ gradient[free]) < 0.0:  # not descent: projected
                newton = False
                direction = linsolve.solve(projected_with_mass(tangent), -gradient[free], solver, symmetric=True)
        p = np.zeros_like(u)
        p[free] = direction
        cap = problem.step_fraction(u, t_new, u + p, t_new)
        slope = float(direction @ gradient[free])
        value = potential(u)
        along = _Ray(potential, work_force, p, None if energy_merit else float(work_force(tangent.contributions) @ p))
        if relax is None:
            ray = partial(_on_ray, u, p)
        else:  # each trial with the block re-minimised: its stiff terms do not cut the step short
            ray = partial(_relaxed_on_ray, u, p, relax, t_new, (inertia, predictor))
        alpha, accepted = _line_search(problem, ray, p, cap, slope, value, norm, along, t_new, step, inertia,
                                       predictor, opts)
        if accepted is None:
            raise StepFailed(f"line search: no decrease of the {'energy' if energy_merit else 'energy and work'} "
                             f"along the step (iteration {iteration}, relative residual {norm / reference:.3e})")
        if newton and energy_merit and not shifted and np.linalg.norm(accepted[3][free]) > norm:
            newton_allowed = False
        u, residual, tangent, gradient, _ = accepted
        if relax is not None:
            relaxed, sweep = relax(u, t_new, proximal=(inertia, predictor))
            if sweep.iterations:  # only the block's terms touch the dofs it moved
                u = relaxed
                residual, tangent = problem.assemble(u, t_new, tangent=True, step=step, reuse=tangent,
                                                     fresh=relax.terms)
                gradient = residual + inertia * (u - predictor)
        short = short + 1 if alpha <= opts.stall_alpha * cap else 0
        if short >= opts.stall_iterations:
            raise StepFailed(f"line search: {short} iterations in a row took at most {opts.stall_alpha:g} of the step "
                             f"(iteration {iteration}): a shorter load step is cheaper")
        if newton:
            kind = "newton"
        else:
            kind = f"{'projected, ' if projected else ''}shift {shift:.2g}" if shifted else "projected"
        logger.debug("step %d iteration %d: alpha %.3g (cap %.3g), %s, relative residual %.3e", step, iteration,
                     alpha, cap, kind, float(np.linalg.norm(gradient[free])) / reference)
        history.append({"step": step, "load_factor": t_new, "iteration": iteration, "alpha": alpha, "cap": cap,
                        "newton": newton, "shift": shift, "projected": projected or not shifted,
                        "energy_merit": energy_merit,
                        "residual": float(np.linalg.norm(gradient[free])),
                        "relative_residual": float(np.linalg.norm(gradient[free])) / reference,
                        "seconds": time.perf_counter() - clock})


@dataclass
class _Ray:
    r""":math:`\phi(\alpha)` along the ray :math:`u + \alpha p`: the potential terms' incremental potential at the
    state plus the work of the terms without one from :math:`u`, by the trapezoidal rule
    :math:`\tfrac\alpha2\,(r_w(u) + r_w(u + \alpha p))\cdot p`, so that :math:`\phi'` is the whole gradient along
    :math:`p` (to :math:`O(\alpha^3)`); ``base_work`` :math:`r_w(u)\cdot p`, None when every term has a potential."""

    potential: Callable[[np.ndarray], float]
    work_force: Callable[[list], np.ndarray]
    p: np.ndarray
    base_work: float | None

    def __call__(self, alpha: float, state: np.ndarray, contributions: list) -> float:
        if self.base_work is None:
            return self.potential(state)
        return self.potential(state) + 0.5 * alpha * (self.base_work + float(self.work_force(contributions) @ self.p))


def _on_ray(u: np.ndarray, p: np.ndarray, alpha: float) -> np.ndarray:
    return u + alpha * p


def _relaxed_on_ray(u: np.ndarray, p: np.ndarray, relax: Callable, t: float, proximal: tuple,
                    alpha: float) -> np.ndarray:
    return relax(u + alpha * p, t, proximal=proximal)[0]


def _line_search(problem: Problem, ray: Callable[[float], np.ndarray], p: np.ndarray, cap: float, slope: float,
                 value: float, norm: float, along, t: float, step: int, inertia: np.ndarray, predictor: np.ndarray,
                 opts: IncrementalOptions):
    """Backtracking from ``cap`` along ``ray`` (the trial at a step length: ``u + alpha p``, or that with a block
    re-minimised) until Armijo's condition holds for ``along`` (module docstring; ``norm``: the
    gradient's norm at ``u``, the test where the energy's change is below its rounding), then Wolfe's
    curvature refinement (:func:`_past_the_minimum`); returns ``(alpha, (state, residual, tangent, gradient,
    value))`` or ``(alpha, None)`` when no step length decreases it."""
    free = problem.pattern.free
    alpha = cap
    for _ in range(opts.max_line_search + 1):
        trial = ray(alpha)
        try:  # the residual only: a trial's tangent (most of an assembly's cost) is wasted when it is rejected
            trial_residual, trial_terms = problem.assemble(trial, t, tangent=False, step=step)
        except NonPositiveJacobianError:
            alpha *= 0.5
            continue
        trial_gradient = trial_residual + inertia * (trial - predictor)
        trial_value = along(alpha, trial, trial_terms.contributions)
        with np.errstate(over="ignore"):  # a trial deep in an exponential law: +inf, rejected below
            trial_norm = float(np.linalg.norm(trial_gradient[free]))
        resolved = abs(alpha * slope) > ENERGY_RESOLUTION * abs(value)
        if along.base_work is not None:  # phi's trapezoid is O(alpha^3): near a solution |grad| decides as well
            ok = (trial_value <= value + opts.armijo * alpha * slope
                  or trial_norm <= (1.0 - opts.armijo * alpha) * norm)
        elif resolved:
            ok = trial_value <= value + opts.armijo * alpha * slope
        else:  # the decrease is below the energy's rounding: the gradient's norm decides
            ok = (trial_norm < norm
                  and trial_value <= value + ENERGY_RESOLUTION * abs(value))
        if ok and np.isfinite(trial_value):
            accepted = (trial, trial_residual, trial_terms, trial_gradient, trial_value)
            if resolved:
                alpha, accepted = _past_the_minimum(problem, ray, p, alpha, slope, value, accepted, t, step,
                                                    inertia, predictor, along, opts)
            return alpha, _with_tangent(problem, accepted, t, step, inertia, predictor)
        alpha *= 0.5
    return alpha, None


def _with_tangent(problem: Problem, accepted: tuple, t: float, step: int, inertia: np.ndarray,
                  predictor: np.ndarray) -> tuple:
    """The accepted trial ``(state, residual, contributions, gradient, value)`` assembled again with its tangent: the
    line search's trials are assembled without one, and the accepted state is the last one assembled (a term's
    :meth:`commit` accepts the state it saw last)."""
    state, _, _, _, value = accepted
    residual, tangent = problem.assemble(state, t, tangent=True, step=step)
    return state, residual, tangent, residual + inertia * (state - predictor), value


def _past_the_minimum(problem: Problem, ray: Callable[[float], np.ndarray], p: np.ndarray, alpha: float,
                      slope: float, value: float,
                      accepted: tuple, t: float, step: int, inertia: np.ndarray, predictor: np.ndarray, along,
                      opts: IncrementalOptions) -> tuple[float, tuple]:
    r"""The curvature condition of Wolfe: a step that decreased the energy but ended far past the minimum along
    :math:`p` (slope :math:`\nabla E(u + \alpha p)\cdot p > c_2\,|\nabla E(u)\cdot p|`) is moved to the zero of the
    slope's secant between 0 and :math:`\alpha` (at most ``opts.secant_steps`` times; kept where the energy is lower).
    Without it Newton's iterates on stiffening cables (a chordae branch point between slack and taut branches)
    cycle about the minimum with full steps that each pass the Armijo test."""
    free = problem.pattern.free
    for _ in range(opts.secant_steps):
        trial_slope = float(accepted[3][free] @ p[free])
        if trial_slope <= opts.curvature * abs(slope):
            break
        secant = alpha * (-slope) / (trial_slope - slope)
        trial = ray(secant)
        try:
            residual, terms = problem.assemble(trial, t, tangent=False, step=step)
        except NonPositiveJacobianError:
            break
        gradient = residual + inertia * (trial - predictor)
        trial_value = along(secant, trial, terms.contributions)
        if not (np.isfinite(trial_value) and trial_value <= value + opts.armijo * secant * slope
                and trial_value < accepted[4]):
            break
        alpha, accepted = secant, (trial, residual, terms, gradient, trial_value)
    return alpha, accepted


def shifted_newton(H: sp.spmatrix, rhs: np.ndarray, shift: float, solver: str,
                   fallback: Callable[[], sp.spmatrix] | None = None) -> tuple[np.ndarray, float, bool]:
    r"""The direction :math:`p = (A + \mu D)^{-1}\,\text{rhs}` for the first positive definite matrix (PARDISO's
    inertia) of: Newton's :math:`A = H` unshifted; then, with a ``fallback`` :math:`A = \mathcal P[H]` (its element
    blocks projected onto their positive semidefinite parts, :func:`projected_tangent`), else :math:`A = H`, with
    Marquardt's diagonal :math:`D = |\text{diag}\,A|` and the smallest shift :math:`\mu` of the sequence
    :math:`0, \mu_0, 10\mu_0, \dots` (starting from a hundredth of the last iteration's ``shift``, or from 0 when it
    was below ``NEWTON_AGAIN_BELOW``). Returns ``(p, mu, projected)``. Newton's step is tried at every call: going
    straight to the fallback once :math:`H` had been indefinite in a step (a factorisation saved per iteration) left
    the 1.0 posterior leaflet's papillary steps converging linearly on the projected matrix, cut back to 0.004-0.008
    of step time.

    A positive definite matrix makes ``p`` a descent direction, and :math:`\mu = 0` on :math:`H` is Newton's step,
    so the iteration is quadratic near a stable minimum. Away from one the projection keeps every element's
    positive curvature as it is and drops only its negative part, where a uniform shift stiffens every direction: on
    the 1.0 diseased valve at its held end load 16 048 of 18 920 F-bar element blocks were indefinite (the most
    negative eigenvalue as large as the block's largest diagonal entry); without the pseudo-mass :math:`H` needed
    :math:`\mu` = 0.01 and the projected matrix 0.001, with it the projected matrix none. There the held steps of
    pseudo-step 0.08 converged (38 and 28 iterations) where the shifted ones failed at 0.16 and 0.08 and converged
    only at 0.04."""
    A = sp.csr_matrix(H)
    projected = fallback is not None
    if projected:
        direction = linsolve.solve_if_definite(A, rhs, solver)
        if direction is not None:
            return direction, 0.0, False
        A = sp.csr_matrix(fallback())
    scale = np.abs(A.diagonal())
    scale = np.maximum(scale, 1e-12 * scale.max(initial=0.0))
    diagonal = A.diagonal()
    trial = 0.0 if shift < NEWTON_AGAIN_BELOW else shift / SHIFT_GROWTH**2
    for _ in range(40):
        matrix = A.copy()
        matrix.setdiag(diagonal + trial * scale)  # the pattern stays (a diagonal entry shifted to 0 is kept)
        direction = linsolve.solve_if_definite(matrix, rhs, solver)
        if direction is not None:
            return direction, trial, projected
        trial = FIRST_SHIFT if trial == 0.0 else SHIFT_GROWTH * trial
    raise StepFailed(f"no shift up to {trial:.3g} x diag makes the {'projected ' if projected else ''}tangent "
                     "positive definite")
