r"""The protocol of a problem's terms: each adds a residual and a tangent on one displacement field.

A :class:`~skvalve.fem.problem.Problem` is a field and a sum of terms,

.. math::

    R(u, t) = \sum_k \big(f^\text{int}_k(u) - f^\text{ext}_k(u, t)\big), \qquad
    K(u, t) = \sum_k \frac{\partial}{\partial u}\big(f^\text{int}_k - f^\text{ext}_k\big),

(solid regions, follower pressure, nodal loads, trusses, contact, multipoint constraints). A term
returns a :class:`Contribution`: its internal and external force vectors and its tangent as element
blocks on a connectivity fixed for the problem's life (the sparsity pattern is built once from
:meth:`Term.connectivity`), plus an optional sparse matrix for connectivity that changes (contact).
Terms holding state (warm-started RVEs, active contact sets) accept it in :meth:`Term.commit` after
a converged load step and restore it in :meth:`Term.rewind` after a failed attempt.

Three optional hooks serve contact that must never pass through (:mod:`skvalve.fem.contact.ipc`) and steps solved as
minimisations (:mod:`skvalve.fem.solvers.incremental`): :meth:`Term.step_fraction` caps a trial step (every solver calls
it before it evaluates a trial state), :meth:`Term.check_state` vets an accepted state (e.g. no intersection, in debug
runs and tests), and :meth:`Term.energy` gives the term's potential :math:`\Pi_k` with :math:`\partial\Pi_k/\partial u =
f^\text{int}_k - f^\text{ext}_k`, or ``None`` where the term is not conservative.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

__all__ = ["Blocks", "Contribution", "Term"]


@dataclass
class Blocks:
    r"""Element-wise tangent blocks: ``matrices[e]`` couples the global dofs ``dofs[e]``.

    Parameters
    ----------
    dofs : (n, m) int array of global dof numbers.
    matrices : (n, m, m) array of :math:`\partial R_{dofs[e, a]}/\partial u_{dofs[e, b]}`, or None
        when no tangent was requested.
    projected : (n, m, m) positive semidefinite blocks the term derives itself (e.g. in closed form), used instead
        of an eigendecomposition of ``matrices`` by projected Newton steps
        (:meth:`~skvalve.fem.problem.Problem.tangent_matrix` ``projected=True``); None: project ``matrices``.
    """

    dofs: np.ndarray
    matrices: np.ndarray | None = None
    projected: np.ndarray | None = None


@dataclass
class Contribution:
    """What one term adds: forces (residual = internal - external) and tangent.

    Parameters
    ----------
    internal, external : (n_dofs,) force vectors, or None for zero.
    blocks : tangent blocks in the order of :meth:`Term.connectivity`.
    matrix : extra tangent on all dofs (n_dofs, n_dofs) for connectivity that changes.
    projected_matrix : the term's own positive semidefinite projection of ``matrix`` (e.g. per contact stencil), for
        projected Newton steps (:meth:`~skvalve.fem.problem.Problem.tangent_matrix` ``projected=True``).
    """

    internal: np.ndarray | None = None
    external: np.ndarray | None = None
    blocks: list[Blocks] = field(default_factory=list)
    matrix: sp.spmatrix | None = None
    projected_matrix: sp.spmatrix | None = None

    def residual(self, n_dofs: int) -> np.ndarray:
        """This term's residual ``internal - external`` on all ``n_dofs`` dofs (zeros where it adds nothing)."""
        force = np.zeros(n_dofs)
        if self.internal is not None:
            force += self.internal
        if self.external is not None:
            force -= self.external
        return force


class Term:
    """Base class of problem terms (no-op state handling).

    Attributes
    ----------
    load_dependent : True when the residual depends on the load factor ``t`` (loads, moved
        targets); the Newton predictor re-evaluates only those at a converged state.
    symmetric : True when the term's tangent is symmetric (lets the solver use a symmetric
        factorisation when every term is).
    name : shown in error messages.
    """

    load_dependent: bool = False
    symmetric: bool = True
    name: str = "term"

    def connectivity(self) -> list[np.ndarray]:
        """The (n, m) dof arrays of the blocks :meth:`assemble` returns, in the same order."""
        return []

    def assemble(self, u: np.ndarray, t: float, tangent: bool, step: int | None) -> Contribution:
        """Forces and (if ``tangent``) the tangent at state ``u`` and load factor ``t``."""
        raise NotImplementedError

    def commit(self) -> None:
        """Accept the current (converged) state."""

    def step_fraction(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> float:
        """The fraction in (0, 1] of the straight move from state ``(u0, t0)`` to ``(u1, t1)`` that may be taken
        (1: all of it). A contact barrier returns its collision-free step (continuous collision detection)."""
        return 1.0

    def pushed(self, u: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """``(dofs, increments)``: free dofs that the term's own prescribed motion from load factor ``t0`` to ``t1``
        pushes at state ``u`` (a kinematic obstacle sweeping into vertices pressed on it), and how far; a start for
        the step, not a constraint. ``None`` (the default): the term pushes nothing."""
        return None

    def crossed(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """``(dofs, increments)``: where the straight move from ``(u0, t0)`` to ``(u1, t1)`` is not collision-free,
        the free dofs that are crossed and the increments (from ``u0``) that would let them ride with what crosses
        them; ``None`` (the default) when the term sees no crossing."""
        return None

    def check_state(self, u: np.ndarray, t: float) -> None:
        """Raise when ``u`` at load factor ``t`` is not an admissible accepted state (called by the solvers after
        each accepted state; a no-op unless a term checks something, e.g. intersections in a debug run)."""

    def energy(self, u: np.ndarray, t: float) -> float | None:
        """The term's potential at ``u`` (its gradient is the residual), or ``None`` when it has none."""
        return None

    def rewind(self) -> None:
        """Return to the last committed state (after a failed attempt)."""

    # Optional, for checkpoints (skvalve.io.checkpoint): ``state() -> dict[str, ndarray]`` returns the
    # committed state and ``restore(arrays)`` sets it (and commits). Terms without state omit both. The solid
    # term forwards both to quadrature-point materials as ``checkpoint_arrays()`` / ``restore_arrays(arrays)``.
