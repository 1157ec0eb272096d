r"""Prescribed motion carried into the free nodes: the harmonic extension of a load step's boundary increment.

A load step that moves prescribed nodes (an annulus, a clamp) starts from the old state with only those nodes moved.
Where a prescribed node is one corner of an element whose other corners are free, that first state distorts the
element by the whole increment: on the Texas TriValve 1.0 annuloplasty input the ring drags single corners of
leaflet hexes (smallest edge 0.18 mm) by up to 0.36 mm in one step of 0.034 step time, changing a vertex distance by
115 %, and the exponential leaflet law answers with a residual :math:`1.4\times 10^7` times the end load's nodal
forces; the linear (tangent) predictor, the tangent taken at the old state, made it worse
(:math:`4\times 10^{21}`) and the step failed after 40 iterations.

The extension moves the free nodes of a mesh graph with the prescribed ones: with :math:`L` the graph Laplacian of
the elements' node sets (unit weight for every pair of nodes of an element, each displacement component on its own),

.. math::

    (L_{ff} + \varepsilon\,D_{ff})\,\delta_f = -L_{fp}\,\delta_p ,

the discrete harmonic extension of the prescribed increment :math:`\delta_p` (the mesh-motion step of ALE methods:
a smooth interpolation that translates a region moved as a whole instead of shearing its boundary row). The small
:math:`\varepsilon` times the degree :math:`D` keeps a component that no prescribed node reaches at rest. The
graph is fixed, so :math:`L_{ff}` is factorised once. On the annuloplasty step above the extension (leaflet hexes
and LINK bars) took the first residual from :math:`1.4\times 10^7` to :math:`4.2\times 10^3` load norms.
:func:`~skvalve.fem.solvers.incremental.minimise_step` starts from it where the step's merit is lower there.

Free dofs that a kinematic obstacle pushes (:mod:`skvalve.fem.contact.push`) join the prescribed ones for one call:
their increments are given, and the extension solves the Laplace problem on the remaining free dofs (a factorisation
of that block per call).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from ..problem import Problem
from ..terms import Term
from . import linsolve

__all__ = ["MotionExtension"]

#: :math:`\varepsilon`: the degree's share on the diagonal (a component with no prescribed node stays at rest)
REGULARISATION = 1e-9


class MotionExtension:
    """The harmonic extension of prescribed increments over the element graph of ``terms`` (module docstring).

    ``terms``: the terms whose elements carry the motion (e.g. a solid, stiff links; not slack cables, which a
    prescribed tip does not drag). Nodes of no such element are left where they are."""

    def __init__(self, problem: Problem, terms: Sequence[Term], solver: str | None = None) -> None:
        if not terms:
            raise ValueError("MotionExtension needs at least one term whose elements carry the motion")
        dim, n = problem.space.dim, problem.space.n_dofs
        rows, cols = [], []
        for term in terms:
            for connectivity in term.connectivity():
                dofs = np.asarray(connectivity, dtype=np.int64)
                if dofs.size == 0:
                    continue
                if dofs.shape[1] % dim:
                    raise ValueError(f"{type(term).__name__}: element dofs ({dofs.shape[1]}) are not whole nodes of "
                                     f"{dim} components")
                nodes = dofs[:, ::dim] // dim
                for component in range(dim):
                    if not np.array_equal(dofs[:, component::dim], dim * nodes + component):
                        raise ValueError(f"{type(term).__name__}: element dofs are not node-major displacement dofs")
                    column = dim * nodes + component
                    k = column.shape[1]
                    rows.append(np.repeat(column, k, axis=1).ravel())
                    cols.append(np.tile(column, (1, k)).ravel())
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        adjacency = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
        degree = np.asarray(adjacency.sum(axis=1)).ravel()
        laplacian = (sp.diags(degree * (1.0 + REGULARISATION) + (degree == 0)) - adjacency).tocsr()
        pattern = problem.pattern
        self.fixed, self.free = pattern.fixed, pattern.free
        self._laplacian = laplacian
        self._adjacency = adjacency.tocsr()
        self._name = linsolve.solver_name(solver)
        self._coupling = laplacian[self.free][:, self.fixed].tocsr()
        self._solver = self._factorised(self.free)

    def _with_elements(self, dofs: np.ndarray, moved: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``dofs`` and the free dofs that share an element with one (same component), the latter moved by the mean
        increment of those they share elements with (weighted by how many)."""
        n = self._adjacency.shape[0]
        indicator, amount = np.zeros(n), np.zeros(n)
        indicator[dofs], amount[dofs] = 1.0, moved
        counts, sums = self._adjacency @ indicator, self._adjacency @ amount
        ring = np.setdiff1d(self.free[counts[self.free] > 0.0], dofs, assume_unique=True)
        return np.concatenate([dofs, ring]), np.concatenate([moved, sums[ring] / counts[ring]])

    def _factorised(self, dofs: np.ndarray) -> linsolve.LinearSolver:
        matrix = self._laplacian[dofs][:, dofs].tocsr()
        matrix.sort_indices()
        return linsolve.LinearSolver(self._name, symmetric=True).analyse(matrix).factorize(matrix)

    def __call__(self, u_old: np.ndarray, u: np.ndarray,
                 pushed: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """``u`` (prescribed dofs at their new values, free dofs as in ``u_old``) with the free dofs moved by the
        extension of the prescribed increment ``u - u_old``.

        ``pushed``: ``(dofs, increments)`` of free dofs moved as if prescribed (an obstacle's push:
        :meth:`~skvalve.fem.problem.Problem.pushed`), and with them the free dofs of their elements' other nodes,
        each by the mean increment of the pushed dofs it shares an element with: an element with a pushed corner
        moves as a whole (pushed alone, the front skin of a 0.4 mm leaflet moved 0.5 mm by a clip arm crushed its
        hexes, and the start's leaflet residual was 1e15 load norms). The extension then runs over the other free
        dofs, on a factorisation of their own block of the Laplacian."""
        increment = np.asarray(u, dtype=float)[self.fixed] - np.asarray(u_old, dtype=float)[self.fixed]
        carried = np.array(u, dtype=float)
        if pushed is not None and len(pushed[0]):
            dofs, moved = self._with_elements(np.asarray(pushed[0], dtype=np.int64), np.asarray(pushed[1], dtype=float))
            rest = np.setdiff1d(self.free, dofs, assume_unique=True)
            carried[dofs] = np.asarray(u_old, dtype=float)[dofs] + moved
            rows = self._laplacian[rest]
            rhs = rows[:, self.fixed] @ increment + rows[:, dofs] @ moved
            carried[rest] += self._factorised(rest).solve(-rhs)
        elif np.any(increment):
            carried[self.free] += self._solver.solve(-(self._coupling @ increment))
        return carried
