r"""The softest modes of a state: why a held solve creeps instead of converging.

At a state :math:`u` with free-dof residual :math:`R` and tangent :math:`K`, Newton's step solves
:math:`K p = -R`. Along an eigenvector :math:`v_j` of the symmetric part :math:`K_s = (K + K^T)/2`
(eigenvalue :math:`\lambda_j`, unit length) the step moves by

.. math::

    p \cdot v_j = -\frac{R \cdot v_j}{\lambda_j}

(exact when :math:`K` is symmetric), so a mode whose stiffness :math:`\lambda_j` is tiny turns a small
residual into a large step, and a residual of :math:`\varepsilon` fixes the state along it only to within
:math:`\varepsilon/\lambda_j`. :func:`soft_modes` finds the smallest :math:`\lambda_j` by shift-invert
Lanczos (ARPACK through :func:`scipy.sparse.linalg.eigsh`) about a shift just below zero, so a
positive semidefinite tangent with exact zero modes (an unstressed cable's transverse motion) still
factorises.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from ..problem import Problem

__all__ = ["SoftModes", "soft_modes"]


@dataclass
class SoftModes:
    """The ``k`` smallest eigenpairs of the symmetric free-dof tangent at one state.

    values : (k,) eigenvalues, ascending (force per displacement, e.g. N/mm; negative: an unstable state).
    vectors : (n_dofs, k) unit eigenvectors on all dofs (zero on the constrained ones), largest entry positive.
    residual_along : (k,) :math:`R \\cdot v_j`, the residual force along each mode.
    """

    values: np.ndarray
    vectors: np.ndarray
    residual_along: np.ndarray

    @property
    def newton_reach(self) -> np.ndarray:
        """(k,) :math:`-R\\cdot v_j/\\lambda_j`: how far Newton's step moves along each mode (inf at a zero mode)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.values != 0.0, -self.residual_along / self.values, np.inf)

    def moving_nodes(self, mode: int, dim: int, n_nodes: int, count: int = 10) -> np.ndarray:
        """The ``count`` nodes (of the ``n_nodes`` displacement nodes, ``dim`` components each) that mode ``mode``
        moves most, largest first."""
        if not 0 <= mode < self.values.size:
            raise IndexError(f"mode {mode} out of range: {self.values.size} modes were computed")
        motion = np.linalg.norm(self.vectors[: dim * n_nodes, mode].reshape(n_nodes, dim), axis=1)
        return np.argsort(-motion, kind="stable")[:count]


def soft_modes(problem: Problem, u: np.ndarray, t: float, k: int = 6, seed: int = 0) -> SoftModes:
    """The ``k`` softest modes of ``problem`` at displacement ``u`` and load factor ``t`` (see the module docstring).

    Assembles once (terms with state see ``u`` as a trial state; nothing is committed). Raises ``ValueError`` for a
    ``u`` of the wrong size or not finite, or ``k`` not below the number of free dofs; ``np.linalg.LinAlgError`` when
    the shifted tangent cannot be factorised. A negative value means the state is not a stable one: its mode is a
    direction of descent.
    """
    n = problem.space.n_dofs
    u = np.asarray(u, dtype=float).ravel()
    if u.shape != (n,) or not np.all(np.isfinite(u)):
        raise ValueError(f"u must be {n} finite values; got shape {u.shape}")
    residual, tangent = problem.assemble(u, t, tangent=True)
    free = problem.pattern.free
    if not 0 < k < free.size:
        raise ValueError(f"k must be between 1 and {free.size - 1} (the free dofs less one); got {k}")
    K = problem.tangent_matrix(tangent)
    symmetric = (0.5 * (K + K.T)).tocsc()
    mean_diagonal = float(np.abs(symmetric.diagonal()).mean())  # k < free.size: never empty
    scale = mean_diagonal if mean_diagonal > 0.0 else 1.0
    shift = -1e-9 * scale  # just below zero: zero modes factorise, and their computed eigenvalue stays ~1e-9 scale
    start = np.random.default_rng(seed).standard_normal(free.size)  # ARPACK's start vector: deterministic
    try:
        values, vectors = spla.eigsh(symmetric, k=k, sigma=shift, which="LM", v0=start)
    except RuntimeError as err:  # SuperLU: exactly singular after the shift
        raise np.linalg.LinAlgError(f"the shifted tangent could not be factorised ({err})") from err
    order = np.argsort(values)
    values, vectors = values[order], vectors[:, order]
    signs = np.sign(vectors[np.argmax(np.abs(vectors), axis=0), np.arange(k)])
    vectors = vectors * signs
    full = np.zeros((n, k))
    full[free] = vectors
    return SoftModes(values, full, vectors.T @ residual[free])

