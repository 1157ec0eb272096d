r"""Where a load step's minimisation starts when the step moves prescribed dofs.

Used by :func:`~skvalve.fem.solvers.incremental.minimise_step`. With only the prescribed dofs moved, an element with
one prescribed corner is distorted by the whole increment. Two starts that carry the free dofs along are tried, each
kept only where it lowers the step's merit (:func:`step_merit`) and its motion is collision-free:

* :func:`carried_start`: the increment's harmonic extension over the element graph
  (:class:`~skvalve.fem.solvers.extension.MotionExtension`), exact for a region translated as a whole;
* :func:`consistent_predictor`: the free dofs' linear response to the increment, by the tangent at the old state
  (the first Newton step of the step, taken before the prescribed motion distorts the elements it drags).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

import numpy as np

from ..errors import NonPositiveJacobianError
from ..problem import Problem
from . import linsolve
from .trust_steps import projected_tangent

__all__ = ["carried_start", "consistent_predictor", "step_merit"]

logger = logging.getLogger("skvalve.fem")

#: how many times a carried start that is not collision-free lets the dofs it crosses ride along before giving up
PUSH_ROUNDS = 6


def consistent_predictor(problem: Problem, u_old: np.ndarray, u: np.ndarray, t_new: float, predictor: np.ndarray,
                         inertia: np.ndarray, step: int, solver: str, energy_merit: bool) -> np.ndarray:
    """The state where the free dofs follow the prescribed motion linearly (the tangent at ``u_old``), capped at the
    collision-free share from ``u`` (the prescribed dofs moved, the free ones as in ``u_old`` or carried along);
    ``u`` when that is no better by the merit's measure."""
    free = problem.pattern.free
    residual, tangent = problem.assemble(u_old, t_new, tangent=True, step=step)
    rhs = residual + problem.apply(tangent, u - u_old) + inertia * (u - predictor)  # linearised at u_old
    K = problem.tangent_matrix(tangent) if not energy_merit else projected_tangent(problem, tangent)
    K = problem.add_diagonal(K, inertia[free])
    try:
        direction = linsolve.solve(K, -rhs[free], solver, symmetric=problem.symmetric or energy_merit)
    except np.linalg.LinAlgError:
        return u
    p = np.zeros_like(u)
    p[free] = direction
    candidate = u + problem.step_fraction(u, t_new, u + p, t_new) * p

    def measure(state: np.ndarray) -> float:
        return step_merit(problem, state, t_new, predictor, inertia, step, energy_merit)

    return candidate if measure(candidate) < measure(u) else u


def step_merit(problem: Problem, state: np.ndarray, t: float, predictor: np.ndarray, inertia: np.ndarray, step: int,
               energy_merit: bool) -> float:
    """The step's merit at ``state``: the incremental potential, or without one the norm of its gradient (inf where
    an element is inverted)."""
    d = state - predictor
    try:
        r, _ = problem.assemble(state, t, tangent=False, step=step)
        if energy_merit:
            return float(problem.energy(state, t) + 0.5 * float(d @ (inertia * d)))
    except NonPositiveJacobianError:
        return float("inf")
    value = float(np.linalg.norm((r + inertia * d)[problem.pattern.free]))
    return value if math.isfinite(value) else float("inf")


def carried_start(problem: Problem, u_old: np.ndarray, t_old: float, u: np.ndarray, alone_free: bool, t_new: float,
                  extend: Callable, pushed: tuple[np.ndarray, np.ndarray] | None, predictor: np.ndarray,
                  inertia: np.ndarray, step: int, energy_merit: bool) -> tuple[np.ndarray, bool, str]:
    """``(start, collision_free, limits)``: the carried state ``extend(pushed)`` (the free dofs moved by the prescribed
    increment's extension, ``pushed`` dofs moved as given) where its motion from ``u_old`` is collision-free and
    either the move to ``u`` (the prescribed dofs moved alone; its CCD verdict ``alone_free``) is not or the step's
    merit is lower at the carried state; else ``u`` and ``alone_free``. ``limits``: the terms that allow less than
    the whole move to the last carried state tried (:meth:`~skvalve.fem.problem.Problem.step_limits`) where it was
    refused, else empty.

    Where a term allows less than the whole carried motion, the free dofs it names ride as it says
    (:meth:`~skvalve.fem.problem.Problem.crossed`: those a collision crosses with what crosses them, the hexes that
    would fold a corner translated by their mean motion), and the extension is taken again, up to ``PUSH_ROUNDS``
    times."""
    carried = extend(pushed)
    rounds = 0
    while problem.step_fraction(u_old, t_old, carried, t_new) < 1.0:
        more = problem.crossed(u_old, t_old, carried, t_new) if rounds < PUSH_ROUNDS else None
        if more is None:
            return u, alone_free, problem.step_limits(u_old, t_old, carried, t_new)
        pushed = more if pushed is None else _merged(pushed, more)
        carried = extend(pushed)
        rounds += 1
        logger.debug("step %d: push round %d, %d dofs ride with what crosses them", step, rounds, more[0].size)
    if np.array_equal(carried, u):
        return u, alone_free, ""
    if not alone_free:
        logger.debug("step %d: carried (the prescribed dofs moved alone are not collision-free)", step)
        return carried, True, ""
    merits = [step_merit(problem, state, t_new, predictor, inertia, step, energy_merit) for state in (u, carried)]
    logger.debug("step %d: merit %.3e with the prescribed dofs moved alone, %.3e carried", step, *merits)
    return (carried if merits[1] < merits[0] else u), True, ""


def _merged(pushed: tuple[np.ndarray, np.ndarray], more: tuple[np.ndarray, np.ndarray]
            ) -> tuple[np.ndarray, np.ndarray]:
    """The union of two ``(dofs, increments)`` sets, ``more``'s increment where both hold a dof."""
    keep = ~np.isin(pushed[0], more[0])
    return np.concatenate([pushed[0][keep], more[0]]), np.concatenate([pushed[1][keep], more[1]])
