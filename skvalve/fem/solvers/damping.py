r"""Pseudo-transient viscous damping: a regularisation that carries floppy, unloaded parts through early steps.

Over a load step from the committed state :math:`(u_n, t_n)` to :math:`t`, the term adds the residual

.. math::

    R_\text{damp}(u, t) = \frac{c(t)}{t - t_n}\,M\,(u - u_n), \qquad
    K_\text{damp} = \frac{c(t)}{t - t_n}\,M,

a viscous force against the velocity in pseudo-time (implicit Euler). :math:`M` is diagonal: the lumped
volume (each node gets an equal share of each adjacent element's reference volume; a mass matrix per unit
density) or the identity. The coefficient follows a :class:`DampingSchedule` that vanishes from
``t_off`` on, so past ``t_off`` the equilibrium solved is the undamped one; before, :func:`undamped_residual`
tells how far a damped state is from equilibrium. A converged step is committed (:math:`u_n \leftarrow u`);
a failed attempt is rewound. Mechanisms (leaflets without load, chord nodes before their chain tightens)
get the stiffness :math:`c/\Delta t\,M` instead of none, and large motions are spread over more steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..problem import Problem
from ..space import Space
from ..terms import Blocks, Contribution, Term

__all__ = ["DampingSchedule", "ViscousDamping", "undamped_residual", "lumped_volume"]


@dataclass(frozen=True)
class DampingSchedule:
    r"""Coefficient :math:`c(t) = c_0\,(1 - t/t_\text{off})^k` for :math:`t < t_\text{off}`, zero after."""

    c0: float
    t_off: float
    power: float = 2.0

    def __post_init__(self) -> None:
        for name in ("c0", "t_off", "power"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0.0):
                raise ValueError(f"DampingSchedule: {name} must be finite and >= 0; got {value!r}")
        if self.t_off <= 0.0:
            raise ValueError(f"DampingSchedule: t_off must be positive; got {self.t_off!r}")

    def __call__(self, t: float) -> float:
        if t >= self.t_off:
            return 0.0
        return float(self.c0 * (1.0 - t / self.t_off) ** self.power)


def lumped_volume(space: Space) -> np.ndarray:
    """Per displacement dof (n_dofs,): an equal share of each adjacent element's reference volume (zero for p)."""
    volume = space.dx.sum(axis=1)  # (nel,)
    nb, d = space.nb_u, space.dim
    scalar = space.element_dofs[:, : nb * d: d] // d
    nodal = np.bincount(scalar.ravel(), np.repeat(volume / nb, nb), minlength=space.n_scalar)
    weights = np.zeros(space.n_dofs)
    weights[: space.n_u] = np.repeat(nodal, d)
    return weights


class ViscousDamping(Term):
    """Pseudo-transient viscous damping (module docstring).

    Parameters
    ----------
    space : the field's :class:`~skvalve.fem.space.Space`.
    schedule : a :class:`DampingSchedule` or any callable ``t -> c(t) >= 0``.
    weighting : ``"lumped"`` (nodal volume, default) or ``"identity"``, or an (n_dofs,) array of weights.
    t0, u0 : the initial committed state (load factor and displacement; default 0 and zeros).
    """

    name = "viscous damping"
    load_dependent = True  # depends on t through c(t) and t - t_n

    def __init__(self, space: Space, schedule, weighting="lumped", t0: float = 0.0,
                 u0: np.ndarray | None = None) -> None:
        if not callable(schedule):
            raise TypeError(f"damping schedule must be callable t -> c(t); got {type(schedule).__name__}")
        self.space, self.schedule = space, schedule
        if isinstance(weighting, str):
            if weighting == "lumped":
                weights = lumped_volume(space)
            elif weighting == "identity":
                weights = np.zeros(space.n_dofs)
                weights[: space.n_u] = 1.0
            else:
                raise ValueError(f"damping weighting must be 'lumped', 'identity' or an array; got {weighting!r}")
        else:
            weights = np.asarray(weighting, dtype=float).ravel()
            if weights.shape != (space.n_dofs,) or not np.all(np.isfinite(weights) & (weights >= 0.0)):
                raise ValueError(f"damping weights must be {space.n_dofs} finite values >= 0")
        self.weights = weights
        self.dofs = np.flatnonzero(weights > 0.0)
        self.committed_u = np.zeros(space.n_dofs) if u0 is None else np.array(u0, dtype=float)
        self.committed_t = float(t0)
        self._trial: tuple[np.ndarray, float] | None = None

    def connectivity(self) -> list[np.ndarray]:
        return [self.dofs[:, None]]

    def coefficient(self, t: float) -> float:
        """:math:`c(t)/(t - t_n)`, zero when :math:`c(t) = 0` or the step has zero length."""
        c = float(self.schedule(t))
        if not (np.isfinite(c) and c >= 0.0):
            raise ValueError(f"damping coefficient must be finite and >= 0; got {c!r} at load factor {t}")
        dt = t - self.committed_t
        return c / dt if c > 0.0 and dt > 0.0 else 0.0

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        self._trial = (u.copy(), float(t))
        eta = self.coefficient(t)
        internal = eta * self.weights * (u - self.committed_u)
        matrices = (eta * self.weights[self.dofs])[:, None, None] if tangent else None
        return Contribution(internal=internal, blocks=[Blocks(self.dofs[:, None], matrices)])

    def commit(self) -> None:
        """Accept the last assembled state (the converged iterate) as :math:`(u_n, t_n)`."""
        if self._trial is not None:
            self.committed_u, self.committed_t = self._trial[0].copy(), self._trial[1]
        self._trial = None

    def rewind(self) -> None:
        self._trial = None


def undamped_residual(problem: Problem, u: np.ndarray, t: float) -> tuple[float, float]:
    """Norm of the free-dof residual of ``problem`` without its damping terms at ``(u, t)``, and that norm
    relative to ``max(|reactions|, |external forces|)`` (the solver's convergence measure)."""
    n = problem.space.n_dofs
    internal, external = np.zeros(n), np.zeros(n)
    for term in problem.terms:
        if isinstance(term, ViscousDamping):
            continue
        contribution = term.assemble(u, t, False, None)
        if contribution.internal is not None:
            internal += contribution.internal
        if contribution.external is not None:
            external += contribution.external
    residual = internal - external
    pattern = problem.pattern
    norm = float(np.linalg.norm(residual[pattern.free]))
    reference = max(float(np.linalg.norm(residual[pattern.fixed])), float(np.linalg.norm(external)), 1e-300)
    return norm, norm / reference
