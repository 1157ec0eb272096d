r"""The step of the energy trust region (:mod:`skvalve.fem.solvers.trust_region`): its matrix, its shift and its
direction.

The step solves :math:`(H + \alpha D)\,p = -R_f` with :math:`H` the symmetric part of the tangent (element blocks
optionally projected onto their positive semidefinite parts: Teran, Sifakis, Irving & Fedkiw 2005), :math:`D`
Marquardt's diagonal or a uniform scale (Levenberg), and :math:`\alpha` raised until :math:`H + \alpha D` has no
negative eigenvalue (PARDISO's inertia) and, optionally, until the step fits the trust region's radius
(Moré 1978; Nocedal & Wright 2006, Sect. 4.3).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..kernels import psd_blocks
from ..problem import Problem, Tangent
from . import linsolve

__all__ = ["project_psd", "projected_tangent", "shift_psd", "project_sparse_psd", "step_matrix", "fitted_shift",
           "fit_radius", "shifted_direction", "factorize_counted", "largest_motion", "on_all_dofs", "FIT_ABOVE"]


def project_psd(matrices: np.ndarray) -> np.ndarray:
    """Each (m, m) block's symmetric part with its negative eigenvalues set to zero (the nearest positive
    semidefinite matrix in the Frobenius norm)."""
    blocks = np.asarray(matrices, dtype=float)
    if blocks.ndim == 3 and blocks.shape[0]:
        return psd_blocks(np.ascontiguousarray(blocks))  # compiled, block by block (kernels.psd_blocks)
    symmetric = 0.5 * (blocks + np.swapaxes(blocks, -1, -2))
    values, vectors = np.linalg.eigh(symmetric)
    if np.all(values >= 0.0):
        return symmetric
    return (vectors * np.maximum(values, 0.0)[..., None, :]) @ np.swapaxes(vectors, -1, -2)


def projected_tangent(problem: Problem, tangent: Tangent, diagonal: np.ndarray | None = None) -> sp.csr_matrix:
    """The free-dof tangent with every symmetric term's element blocks projected onto their PSD parts, a term's own
    projected sparse matrix where it gives one (contact stencils) and the symmetric part of everything else; plus
    ``diagonal`` (free dofs)."""

    def blocks(term, matrices):
        if getattr(term, "symmetric", True):
            return project_psd(matrices)
        return 0.5 * (matrices + np.swapaxes(matrices, -1, -2))

    def matrix(term, sparse):
        return 0.5 * (sparse + sparse.T)

    return problem.tangent_matrix(tangent, blocks=blocks, matrix=matrix, projected=True, diagonal=diagonal)


def shift_psd(matrices: np.ndarray) -> np.ndarray:
    r"""Each (m, m) block's symmetric part :math:`B` plus :math:`\max(-\lambda_\min(B), 0)\,I`: the smallest
    uniform diagonal that makes it positive semidefinite (a Levenberg shift of that block alone). Unlike
    :func:`project_psd` it stiffens every direction of an indefinite block, so a step does not run along the
    curvature it drops."""
    symmetric = 0.5 * (matrices + np.swapaxes(matrices, -1, -2))
    lowest = np.linalg.eigvalsh(symmetric)[..., 0]
    return symmetric + np.maximum(-lowest, 0.0)[..., None, None] * np.eye(symmetric.shape[-1])


def project_sparse_psd(matrix: sp.spmatrix, largest: int = 4000, shift: bool = False) -> sp.csr_matrix:
    """The symmetric part of a sparse matrix with each connected block (the components of its pattern's graph, e.g.
    one patch of contact pairs) projected onto its positive semidefinite part (``shift``: shifted to it,
    :func:`shift_psd`); a block of more than ``largest`` rows keeps its symmetric part (a dense eigendecomposition
    would cost too much)."""
    symmetric = (0.5 * (matrix + matrix.T)).tocsr()
    symmetric.eliminate_zeros()
    rows = np.flatnonzero(np.diff(symmetric.indptr))
    if rows.size == 0:
        return symmetric
    inner = symmetric[rows][:, rows]
    count, labels = connected_components(inner, directed=False)
    out_rows, out_cols, out_values = [], [], []
    order = np.argsort(labels, kind="stable")
    bounds = np.concatenate([[0], np.cumsum(np.bincount(labels, minlength=count))])
    for k in range(count):
        local = order[bounds[k]: bounds[k + 1]]
        block = inner[local][:, local].toarray()
        if local.size <= largest:
            block = (shift_psd if shift else project_psd)(block[None])[0]
        r, c = np.meshgrid(rows[local], rows[local], indexing="ij")
        out_rows.append(r.ravel())
        out_cols.append(c.ravel())
        out_values.append(block.ravel())
    return sp.csr_matrix((np.concatenate(out_values), (np.concatenate(out_rows), np.concatenate(out_cols))),
                         shape=matrix.shape)


def step_matrix(problem: Problem, tangent: Tangent, project: bool, terms: tuple[str, ...] = (),
                shifted: tuple[str, ...] = ()) -> sp.csr_matrix:
    """The symmetric part of the free-dof tangent; when ``project``, with the element blocks of every symmetric term
    and the extra sparse matrices projected onto their positive semidefinite parts (a non-symmetric term's blocks,
    e.g. a follower pressure's load stiffness, enter with their symmetric parts: their negative curvature is the
    structure's response to the load, which the shift handles); else only the blocks and matrices of the terms named
    in ``terms``; those of the terms named in ``shifted`` are shifted to semidefinite ones (:func:`shift_psd`).

    A projected sparse matrix is the term's own projection where it gives one (``Contribution.projected_matrix``: an
    IPC barrier's per-stencil projection, as :func:`projected_tangent` uses on the load path), else each connected
    block's (:func:`project_sparse_psd`). Per stencil, a contact patch keeps its sliding directions soft: on the 1.0
    diseased valve's held load (about 1600 barrier pairs, from relative residual 0.058) the settle stage converged to
    7.8e-8 in 34 steps with it, while the patch shifted as a whole (``shifted``) stiffened the sliding the leaflets
    still had to do, and its steps lowered the residual only to 5.5e-3 in 25 steps (ratio of actual to predicted
    energy drop 1.8-1.9 throughout: the model ten times too stiff along the step)."""

    def chosen(term) -> str | None:
        name = getattr(term, "name", None)
        if name in shifted:
            return "shift"
        return "project" if project or name in terms else None

    def blocks(term, matrices):
        how = chosen(term) if getattr(term, "symmetric", True) else None
        if how is not None:
            return shift_psd(matrices) if how == "shift" else project_psd(matrices)
        return 0.5 * (matrices + np.swapaxes(matrices, -1, -2))

    own = {id(term): contribution.projected_matrix
           for term, contribution in zip(problem.terms, tangent.contributions, strict=True)}

    def matrix(term, sparse):
        how = chosen(term)
        if how == "project" and own[id(term)] is not None:
            projected = own[id(term)]
            return 0.5 * (projected + projected.T)
        if how is not None:
            return project_sparse_psd(sparse, shift=how == "shift")
        return 0.5 * (sparse + sparse.T)

    return problem.tangent_matrix(tangent, blocks=blocks, matrix=matrix).tocsr()


#: a step longer than this many radii has its shift fitted (:attr:`TrustRegionOptions.fit_radius`)
FIT_ABOVE = 1.2


def fitted_shift(moving: np.ndarray, stiffness: np.ndarray, scale: np.ndarray, shift: float, radius: float) -> float:
    r"""The shift that brings a step taken with ``shift`` to ``radius``, from the node that moves most: its motion
    ``moving`` (dim,), the rows of :math:`H p` and of :math:`D p` at that node (``stiffness``, ``scale``). With the
    node's curvature :math:`\lambda = p_i\cdot(Hp)_i / p_i\cdot(Dp)_i` the step there scales as
    :math:`1/(\lambda + \alpha)`, so the shift that brings its length :math:`L = |p_i|` to :math:`\Delta` is

    .. math:: \alpha' = (\lambda + \alpha)\,\frac{L}{\Delta} - \lambda ,

    exact when :math:`p` is a mode of the pencil :math:`(H, D)` or the node is decoupled (then for any step); never
    below ``shift``."""
    moving = np.asarray(moving, dtype=float)
    curvature = max(float(moving @ stiffness) / float(moving @ scale), 0.0)
    return max((curvature + shift) * float(np.linalg.norm(moving)) / radius - curvature, shift)


def fit_radius(solver, H, D, rhs, direction, shift, newton, radius, space, free, opts, result):
    r"""Raise the shift until the step's largest nodal motion is within ``FIT_ABOVE`` radii (at most
    ``opts.fit_radius`` factorisations of :math:`H + \alpha D`, each checked positive definite and a descent
    direction; :func:`fitted_shift` from the node that moves most); returns the last step found, its shift and whether
    it is Newton's."""
    n, dim = space.n_dofs, space.dim

    def nodal(x):
        return on_all_dofs(x, n, free)[: space.n_u].reshape(-1, dim)

    scale = D.diagonal()
    for _ in range(opts.fit_radius):
        moves = nodal(direction)
        node = int(np.argmax(np.linalg.norm(moves, axis=1)))
        if np.linalg.norm(moves[node]) <= FIT_ABOVE * radius:
            break
        trial = fitted_shift(moves[node], nodal(H @ direction)[node], nodal(scale * direction)[node], shift, radius)
        trial = min(max(trial, opts.min_shift), opts.max_shift)
        if trial <= shift:
            break
        try:
            factorize_counted(solver, (H + trial * D).tocsr(), result)
            inertia = solver.inertia()
            if inertia is not None and inertia[1] > 0:
                break
            x = solver.solve(rhs)
        except np.linalg.LinAlgError:
            break
        if not float(rhs @ x) > 0.0:
            break
        result.radius_fits += 1
        direction, shift, newton = x, trial, False
    return direction, shift, newton


def largest_motion(p: np.ndarray, space) -> float:
    """The largest nodal displacement of ``p`` (all dofs)."""
    return float(np.linalg.norm(p[: space.n_u].reshape(-1, space.dim), axis=1).max(initial=0.0))


def on_all_dofs(direction: np.ndarray, n: int, free: np.ndarray) -> np.ndarray:
    """A free-dof vector on all ``n`` dofs (zero on the prescribed ones)."""
    p = np.zeros(n)
    p[free] = direction
    return p


def shifted_direction(solvers, symmetric_K, K, H, D, rhs, shift: float, fallback: float, newton_allowed: bool, opts,
                      result):
    """The step direction, the shift it took and whether it is Newton's (``opts``: the trust region's options,
    ``result``: what counts the factorisations).

    Newton's with the full tangent when the shift is 0, no local shift is on (``newton_allowed``) and the tangent's
    symmetric part is positive definite; else :math:`(H + \\alpha D)^{-1}` rhs with :math:`\\alpha` (from ``fallback``
    after a Newton step was not possible) raised x8 until the matrix has no negative eigenvalue and the direction is
    one of descent. (None, shift, False) when no shift up to ``max_shift`` gives one.
    """
    symmetric, definite, general = solvers
    if shift == 0.0 and newton_allowed:
        try:
            factorize_counted(definite, symmetric_K, result)
            inertia = definite.inertia()
        except np.linalg.LinAlgError:  # not definite (a Cholesky solver gives up at the first non-positive pivot)
            inertia = None
        if inertia is not None and inertia[1] == 0:
            try:
                factorize_counted(general, K, result)
                x = general.solve(rhs)
                if float(rhs @ x) > 0.0:
                    return x, 0.0, True
            except np.linalg.LinAlgError:
                pass
    if shift == 0.0:
        shift = max(opts.min_shift, 0.25 * fallback)
    while shift <= opts.max_shift:
        A = (H + shift * D).tocsr()
        try:
            factorize_counted(symmetric, A, result)
            inertia = symmetric.inertia()
            if inertia is None or inertia[1] == 0:
                x = symmetric.solve(rhs)
                if float(rhs @ x) > 0.0 and float(x @ (A @ x)) > 0.0:
                    return x, shift, False
        except np.linalg.LinAlgError:
            pass
        shift *= 8.0
    return None, shift, False


def factorize_counted(solver: linsolve.LinearSolver, matrix: sp.csr_matrix, result) -> None:
    """Analyse (when the pattern is new) and factorise ``matrix``, counting it in ``result.factorizations``."""
    csr = sp.csr_matrix(matrix)
    csr.sort_indices()
    solver.analyse((csr.indptr, csr.indices))
    solver.factorize(csr.data)
    result.factorizations += 1
