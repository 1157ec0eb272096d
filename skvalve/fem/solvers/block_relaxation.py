r"""Nonlinear block relaxation: bring a few dofs that only cheap terms touch to equilibrium, the others held.

In a valve the chordae branch points belong to no leaflet cell: only cables pull on them, and a cable between slack
and taut changes its stiffness by six orders of magnitude at its slack length. A global step whose quadratic model
sees a hub's slack side overshoots it, and a hub that a global step leaves out of balance carries most of the
residual (on the 1.0 diseased valve at the held load, 2 hubs held half of :math:`\lVert R\rVert^2`). Their own
equilibrium, with every other dof held, is a small problem: Newton on the hubs' dofs with the residual and tangent of
the terms that touch them (:class:`BlockRelaxation`), each iteration's step kept when the energy those terms store
falls along it (the work of their residual, :func:`~skvalve.fem.solvers.trust_region.work_along`'s Simpson rule), halved
otherwise. Running it after each accepted step of :func:`~skvalve.fem.solvers.trust_region.trust_region` is a nonlinear
Gauss–Seidel sweep over the block (nonlinear elimination: Cai & Keyes 2002): it lowers the energy, and the
equilibrium of the whole problem is unchanged. Inside a load step of the incremental potential
(:func:`~skvalve.fem.solvers.incremental.minimise_step`) the block's energy also carries the step's proximal term
:math:`\tfrac12\sum_i w_i (u_i - \tilde u_i)^2` on its dofs (``proximal=(w, ũ)``), so the sweep lowers that
step's merit and leaves its minimiser unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..problem import Problem
from .trust_region import work_along

__all__ = ["BlockRelaxation", "BlockRelaxationResult"]


@dataclass
class BlockRelaxationResult:
    """Iterations, the block's residual norm before and after, and the energy change (the work of its residual)."""

    iterations: int
    initial_norm: float
    final_norm: float
    energy_change: float


class BlockRelaxation:
    """Newton on ``dofs`` of ``problem`` with the residual and tangent of ``terms`` only, the other dofs held.

    Parameters
    ----------
    problem : the problem (its Dirichlet dofs are left out of ``dofs``).
    dofs : global dof numbers of the block (e.g. the displacement dofs of the nodes of no cell).
    terms : the problem's terms that touch those dofs; the caller promises that no other term does (checked against
        the terms' element connectivities; terms with an extra sparse matrix, e.g. contact, must not touch them).
    tol : stop when the block's residual norm is below this (force).
    max_iterations, max_increment : the most Newton iterations, and the most a node may move in one (length).
    """

    def __init__(self, problem: Problem, dofs: np.ndarray, terms, tol: float = 1e-9, max_iterations: int = 30,
                 max_increment: float = 0.5) -> None:
        dofs = np.setdiff1d(np.asarray(dofs, dtype=np.int64).ravel(), problem.pattern.fixed)
        if dofs.size and (dofs.min() < 0 or dofs.max() >= problem.space.n_dofs):
            raise ValueError(f"block dofs must lie in 0..{problem.space.n_dofs - 1}")
        terms = list(terms)
        unknown = [term for term in terms if all(term is not other for other in problem.terms)]
        if unknown:
            raise ValueError(f"block relaxation: {len(unknown)} term(s) are not terms of the problem")
        inside = np.zeros(problem.space.n_dofs, dtype=bool)
        inside[dofs] = True
        for term in problem.terms:
            if any(term is mine for mine in terms):
                continue
            touched = [c for c in term.connectivity() if c.size and inside[np.asarray(c)].any()]
            if touched:
                raise ValueError(f"block relaxation: the term {getattr(term, 'name', type(term).__name__)!r}, not "
                                 "given, also acts on the block's dofs")
        if not (math.isfinite(tol) and tol > 0 and max_iterations > 0 and max_increment > 0):
            raise ValueError("block relaxation: tol, max_iterations and max_increment must be positive")
        self.problem, self.dofs, self.terms = problem, dofs, terms
        self.tol, self.max_iterations, self.max_increment = float(tol), int(max_iterations), float(max_increment)
        self._local = np.full(problem.space.n_dofs, -1, dtype=np.int64)
        self._local[dofs] = np.arange(dofs.size)
        self.nodes = np.unique(dofs // problem.space.dim) if dofs.size else np.zeros(0, dtype=np.int64)

    def residual(self, u: np.ndarray, t: float, tangent: bool = False,
                 proximal: tuple[np.ndarray, np.ndarray] | None = None):
        """The block's residual (its dofs) and, with ``tangent``, its (n, n) tangent (CSR) from the terms' blocks;
        ``proximal=(w, center)`` (both (n_dofs,)) adds :math:`w_i (u_i - c_i)` and the diagonal :math:`w_i`."""
        n = self.problem.space.n_dofs
        force = np.zeros(n)
        rows, cols, values = [], [], []
        for term in self.terms:
            contribution = term.assemble(u, t, tangent, None)
            force += contribution.residual(n)
            if tangent:
                for block in contribution.blocks:
                    local = self._local[block.dofs]
                    a = local[:, :, None]
                    b = local[:, None, :]
                    keep = (a >= 0) & (b >= 0)
                    rows.append(np.broadcast_to(a, keep.shape)[keep])
                    cols.append(np.broadcast_to(b, keep.shape)[keep])
                    values.append(block.matrices[keep])
        r = force[self.dofs]
        if proximal is not None:
            weights, center = proximal
            r = r + weights[self.dofs] * (u[self.dofs] - center[self.dofs])
        if not tangent:
            return r, None
        m = self.dofs.size
        K = sp.csr_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))), shape=(m, m))
        if proximal is not None:
            K = K + sp.diags(proximal[0][self.dofs], format="csr")
        return r, K

    def __call__(self, u: np.ndarray, t: float, proximal: tuple[np.ndarray, np.ndarray] | None = None
                 ) -> tuple[np.ndarray, BlockRelaxationResult]:
        """``u`` with the block relaxed (a copy), and what it took; ``proximal``: as in :meth:`residual`."""
        u = np.array(u, dtype=float)
        if self.dofs.size == 0:
            return u, BlockRelaxationResult(0, 0.0, 0.0, 0.0)
        r, K = self.residual(u, t, tangent=True, proximal=proximal)
        first = float(np.linalg.norm(r))
        total, iteration = 0.0, 0
        dim = self.problem.space.dim
        while iteration < self.max_iterations and float(np.linalg.norm(r)) > self.tol:
            iteration += 1
            symmetric = 0.5 * (K + K.T)
            diagonal = np.abs(symmetric.diagonal())
            shift = 1e-8 * max(float(diagonal.max(initial=0.0)), 1e-300)
            values, _ = np.linalg.eigh(symmetric.toarray()) if self.dofs.size <= 600 else (None, None)
            if values is not None and values.min() <= shift:
                shift = shift - values.min()  # a slack hub: make its step matrix definite
            try:
                step = spla.spsolve((symmetric + shift * sp.identity(self.dofs.size)).tocsc(), -r)
            except RuntimeError:
                break
            if not np.all(np.isfinite(step)):
                break
            largest = float(np.linalg.norm(step.reshape(-1, dim), axis=1).max(initial=0.0))
            if largest > self.max_increment:
                step *= self.max_increment / largest
            accepted = False
            for _ in range(30):
                trial = u.copy()
                trial[self.dofs] += step
                middle = u.copy()
                middle[self.dofs] += 0.5 * step
                r_middle, _ = self.residual(middle, t, proximal=proximal)
                r_end, K_end = self.residual(trial, t, tangent=True, proximal=proximal)
                work = work_along(r, r_middle, r_end, step)
                if work < 0.0 and np.all(np.isfinite(r_end)):
                    accepted = True
                    break
                step *= 0.5
            if not accepted:
                break
            u, r, K = trial, r_end, K_end
            total += work
        return u, BlockRelaxationResult(iteration, first, float(np.linalg.norm(r)), total)
