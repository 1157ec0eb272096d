r"""Taylor test of a problem's terms: how far each term's tangent predicts its forces along a step.

For a term with residual :math:`r_k(u)` and tangent :math:`K_k(u)` the remainder of the linearisation along a
direction :math:`p`,

.. math::

    e_k(h) = \big\lVert r_k(u + h\,p) - r_k(u) - h\,K_k(u)\,p \big\rVert_\text{free} ,

falls as :math:`h^2` when :math:`K_k` is the derivative of :math:`r_k` and the term is twice differentiable along the
step, as :math:`h` when the tangent is wrong (Farrell, Ham, Funke & Rognes, SIAM J. Sci. Comput. 35(4), 2013, the
"Taylor test"). Its size at a given :math:`h` says how long a step the quadratic model of a Newton or trust-region step
can be trusted for, term by term: on the closed 1.0 Texas TriValve at a relative residual of 1.25e-4 the contact's
remainder at a 0.01 mm step equalled the whole residual, 33 times the solid's, from a few pairs that had passed
through a leaflet (measured on the penalty contact's closure, which the IPC barrier contact of
:mod:`skvalve.fem.contact.ipc`, never passed through, has replaced).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .problem import Problem, Tangent

__all__ = ["TermTaylor", "taylor_test"]


@dataclass
class TermTaylor:
    """Linearisation remainders of one term along a step (:func:`taylor_test`).

    Attributes
    ----------
    name : the term's name.
    lengths : (m,) step lengths :math:`h` (largest nodal motion of :math:`h p`).
    errors : (m,) remainders :math:`e_k(h)` on the free dofs.
    orders : (m - 1,) observed orders :math:`\\log(e_{i+1}/e_i)/\\log(h_{i+1}/h_i)` (NaN where an error is zero).
    worst_nodes : (m, n_worst) the nodes with the largest remainder at each length, largest first.
    """

    name: str
    lengths: np.ndarray
    errors: np.ndarray
    orders: np.ndarray
    worst_nodes: np.ndarray


def taylor_test(problem: Problem, u: np.ndarray, t: float, direction: np.ndarray,
                lengths: Sequence[float] = (1e-3, 3e-3, 1e-2, 3e-2, 1e-1), n_worst: int = 4) -> list[TermTaylor]:
    """Remainders of every term's linearisation at ``u`` (load factor ``t``) along ``direction`` (all dofs), scaled so
    that its largest nodal motion is each of ``lengths`` (module docstring). The terms are assembled at the trial
    states but nothing is committed (a term whose energy lags a committed state, such as blended contact's facing
    factors, is tested on the energy of its last commit: commit at ``u`` first to test the one a solver step from ``u``
    sees); a trial state a term refuses (e.g. an inverted element) raises its error."""
    u, direction = np.asarray(u, dtype=float), np.asarray(direction, dtype=float)
    n = problem.space.n_dofs
    if u.shape != (n,) or direction.shape != (n,):
        raise ValueError(f"taylor_test: u and direction need {n} entries (all dofs); got {u.shape}, {direction.shape}")
    lengths = np.asarray(lengths, dtype=float)
    if lengths.ndim != 1 or lengths.size < 2 or not np.all(np.isfinite(lengths) & (lengths > 0)):
        raise ValueError(f"taylor_test: lengths must be two or more positive numbers; got {lengths!r}")
    n_u = problem.space.n_u
    largest = float(np.linalg.norm(direction[:n_u].reshape(-1, problem.space.dim), axis=1).max(initial=0.0))
    if not (math.isfinite(largest) and largest > 0.0):
        raise ValueError("taylor_test: the direction moves no node")
    free = problem.pattern.free
    unit = direction / largest
    base = [term.assemble(u, t, True, None) for term in problem.terms]
    slopes = [problem.apply(Tangent([contribution]), unit)[free] for contribution in base]
    forces = [contribution.residual(n)[free] for contribution in base]
    errors = np.zeros((len(problem.terms), lengths.size))
    worst = np.zeros((len(problem.terms), lengths.size, n_worst), dtype=np.int64)
    for j, h in enumerate(lengths):
        for k, term in enumerate(problem.terms):
            remainder = np.zeros(n)
            remainder[free] = term.assemble(u + h * unit, t, False, None).residual(n)[free] - forces[k] - h * slopes[k]
            errors[k, j] = np.linalg.norm(remainder)
            nodal = np.linalg.norm(remainder[:n_u].reshape(-1, problem.space.dim), axis=1)
            worst[k, j] = np.argsort(nodal)[::-1][:n_worst]
    with np.errstate(divide="ignore", invalid="ignore"):
        orders = np.log(errors[:, 1:] / errors[:, :-1]) / np.log(lengths[1:] / lengths[:-1])
    orders[~np.isfinite(orders)] = np.nan
    return [TermTaylor(getattr(term, "name", type(term).__name__), lengths.copy(), errors[k], orders[k], worst[k])
            for k, term in enumerate(problem.terms)]
