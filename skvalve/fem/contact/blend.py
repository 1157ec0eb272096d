r"""Blended node-to-triangle contact: every triangle near a node carries a smooth share of its energy.

The closest-triangle rule of :class:`~skvalve.fem.contact.SurfaceContact` jumps where a node's projection leaves
one triangle for the next: over a concave crease a node can lie in no triangle's band, pass 0.2 mm deep and then
slide into one, and which triangle it has depends on the previous search. Blending removes both. Each candidate
pair :math:`j` (node :math:`s`, triangle :math:`T`) gets a weight

.. math::

    \phi_j = \chi(g_j)\prod_{i=1}^3 S\Big(\frac{\lambda_i - \ell_i}{2\beta}\Big), \qquad
    \ell_i = \begin{cases} -\beta & \text{edge opposite } i \text{ shared with a neighbour} \\
    -2\beta & \text{free edge} \end{cases}

with :math:`\lambda_i` the barycentric coordinates of the node's projection (:mod:`~skvalve.fem.contact.geometry`),
:math:`S` the :math:`C^2` smooth step and :math:`\beta` the ``blend`` band: across a shared edge of two coplanar
triangles of equal height the shares sum to one (:math:`S(t)+S(1-t)=1`), and past a free edge the surface is
extended by :math:`2\beta` as the closest-triangle band does. :math:`\chi(g)` fades a pair in over
:math:`g_\text{max} > -g > 0.8\,g_\text{max}` (too deep) and out over :math:`0 < g < g_a` (not yet touching), so a
triangle just above a node still counts in the node's normalisation. The node's energy on each sheet :math:`k` (its
pairs whose triangles connect through shared vertices: a node pressed between two sheets feels each in full) is the
weighted mean

.. math::

    E_{s,k} = A_s\,\frac{N}{M(\Phi)},\qquad N = \sum_{j\in k} \phi_j\,\psi(-g_j),\qquad
    \Phi = \sum_{j\in k} \phi_j,

with :math:`\psi` the penalty energy (:math:`\psi' = p`) and :math:`M(\Phi) = \Phi` for :math:`\Phi \ge 1`,
:math:`1 - \delta + (\Phi - 1 + 2\delta)^2/(4\delta)` on :math:`[1-2\delta, 1]` and :math:`1-\delta` below
(:math:`C^1`): a node whose triangles' shares sum to one or more (inside the surface, on an edge, at a vertex) gets
exactly the mean energy of its pairs, and one that is only partly covered (past a free edge, over a crease) gets a
share that fades to zero. :math:`E_s` is a function of the positions alone (no search memory), continuous with its
gradient. With :math:`F(N, \Phi) = A N/M`, forces and tangent follow from the pairs' derivatives:

.. math::

    \nabla E_s = F_N \nabla N + F_\Phi\nabla\Phi,\qquad
    \nabla^2 E_s = F_N\nabla^2 N + F_\Phi\nabla^2\Phi + F_{N\Phi}(\nabla N\otimes\nabla\Phi + \nabla\Phi\otimes\nabla N)
    + F_{\Phi\Phi}\nabla\Phi\otimes\nabla\Phi ,

the last three as sparse products :math:`G_N^T\,\mathrm{diag}(F_{N\Phi})\,G_\Phi` of the per-node gradient rows.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .geometry import smooth_step

__all__ = ["free_edges", "pair_weights", "sheets", "weighted_mean_energy", "DEEP_FADE", "BARRIER_FLOOR",
           "NORMALISATION_DELTA"]

#: The fade-in of deep pairs starts at this fraction of the search depth g_max.
DEEP_FADE = 0.8
#: The overlap (fraction of g_max) at which the contact's depth barrier becomes unbounded: just past the clearance
#: limit's floor, short of the fade.
BARRIER_FLOOR = DEEP_FADE - 0.04
#: delta of the normalisation M(Phi) (module docstring).
NORMALISATION_DELTA = 0.1


def free_edges(triangles: np.ndarray) -> np.ndarray:
    """(n, 3) bool: the edge opposite each corner is used by this triangle only."""
    triangles = np.asarray(triangles, dtype=np.int64)
    edges = np.stack([triangles[:, [1, 2]], triangles[:, [2, 0]], triangles[:, [0, 1]]], axis=1)
    edges = np.sort(edges, axis=2).reshape(-1, 2)
    _, inverse, counts = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
    return (counts[inverse.ravel()] == 1).reshape(-1, 3)


def pair_weights(lam, lam_grad, lam_hess, gap, gap_grad, gap_hess, free, band: float, depth: float,
                 above: float, hessian: bool = True):
    """Weights :math:`\\phi` (n,), gradients (n, 12) and Hessians (n, 12, 12) (module docstring).

    ``lam`` (n, 3) with derivatives (n, 3, 12), (n, 3, 12, 12); ``gap`` (n,) with (n, 12), (n, 12, 12);
    ``free`` (n, 3) the free-edge flags of each pair's triangle; ``band`` beta, ``depth`` g_max, ``above`` g_a.
    """
    lower = np.where(free, -2.0 * band, -band)
    scale = np.full(3, 1.0 / (2.0 * band))
    # five factors S(t_k): three barycentric, the deep fade-in and the fade-out above the surface
    t = np.column_stack([(lam - lower) * scale, (gap + depth) / ((1.0 - DEEP_FADE) * depth), (above - gap) / above])
    dt = np.concatenate([scale, [1.0 / ((1.0 - DEEP_FADE) * depth), -1.0 / above]])
    value, first, second = smooth_step(t)
    first = first * dt
    second = second * dt**2
    grads = np.concatenate([lam_grad, gap_grad[:, None], gap_grad[:, None]], axis=1)  # (n, 5, 12)
    k = t.shape[1]
    # d phi / d t_i = S_i' prod_{m != i} S_m;  d2 phi / d t_i d t_j = S_i' S_j' prod_{m != i, j} S_m (S_i'' on i = j)
    coefficient = np.empty((t.shape[0], k, k))
    for i in range(k):
        for j in range(k):
            rest = np.prod(value[:, [m for m in range(k) if m not in (i, j)]], axis=1)
            coefficient[:, i, j] = rest * (second[:, i] if i == j else first[:, i] * first[:, j])
    slope = first * np.stack([np.prod(np.delete(value, i, axis=1), axis=1) for i in range(k)], axis=1)
    phi = value.prod(axis=1)
    grad = np.einsum("nk,nkj->nj", slope, grads)
    if not hessian:
        return phi, grad, None
    hess = np.einsum("nkl,nki,nlj->nij", coefficient, grads, grads)
    hess += np.einsum("nk,nkij->nij", slope[:, :3], lam_hess)
    hess += (slope[:, 3] + slope[:, 4])[:, None, None] * gap_hess
    return phi, grad, hess


def normalisation(total: np.ndarray, delta: float = NORMALISATION_DELTA):
    """M(Phi), M' and M'' (module docstring)."""
    low, high = 1.0 - 2.0 * delta, 1.0
    blend = (total > low) & (total < high)
    value = np.where(total >= high, total, np.where(blend, 1.0 - delta + (total - low) ** 2 / (4.0 * delta),
                                                    1.0 - delta))
    first = np.where(total >= high, 1.0, np.where(blend, (total - low) / (2.0 * delta), 0.0))
    second = np.where(blend, 1.0 / (2.0 * delta), 0.0)
    return value, first, second


def sheets(node: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Group id (n,) of each pair: the pairs of one node whose triangles are connected through shared vertices (one
    sheet of the surface; a node between two sheets gets one group per sheet). ``triangles`` (n, 3) vertex ids."""
    n = node.size
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    _, key = np.unique(np.column_stack([np.repeat(node, 3), triangles.ravel()]), axis=0, return_inverse=True)
    incidence = sp.csr_matrix((np.ones(3 * n), (np.repeat(np.arange(n), 3), key.ravel())), shape=(n, key.max() + 1))
    return connected_components(incidence @ incidence.T, directed=False)[1].astype(np.int64)


def weighted_mean_energy(node, group, dofs, area, phi, phi_grad, phi_hess, psi, psi_grad, psi_hess, n_dofs: int,
                         tangent: bool):
    """Internal force (n_dofs,) and tangent (sparse or ``None``) of :math:`\\sum_g A_{s(g)} N_g/M(\\Phi_g)`.

    Per pair: ``node`` (n,), its ``group`` (n,) (:func:`sheets`: the normalisation runs over one node's pairs on
    one sheet), ``dofs`` (n, 12), ``phi``/``psi`` with gradients (n, 12) and Hessians (n, 12, 12); ``area``
    (n_nodes,) the tributary areas indexed by node. Also returns the energy.
    """
    _, first, row = np.unique(group, return_index=True, return_inverse=True)
    active = node[first]
    numerator = phi * psi
    numerator_grad = phi[:, None] * psi_grad + psi[:, None] * phi_grad
    N = np.bincount(row, numerator, minlength=active.size)
    Phi = np.bincount(row, phi, minlength=active.size)
    M, M1, M2 = normalisation(Phi)
    A = area[active]
    F_N = A / M
    F_Phi = -A * N * M1 / M**2
    internal = np.zeros(n_dofs)
    forces = F_N[row, None] * numerator_grad + F_Phi[row, None] * phi_grad
    np.add.at(internal, dofs.ravel(), forces.ravel())
    energy = float(np.sum(A * N / M))
    if not tangent:
        return internal, None, energy
    numerator_hess = phi[:, None, None] * psi_hess + psi[:, None, None] * phi_hess \
        + phi_grad[:, :, None] * psi_grad[:, None, :] + psi_grad[:, :, None] * phi_grad[:, None, :]
    blocks = F_N[row, None, None] * numerator_hess + F_Phi[row, None, None] * phi_hess
    rows = np.repeat(dofs, 12, axis=1).ravel()
    cols = np.tile(dofs, (1, 12)).ravel()
    matrix = sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n_dofs, n_dofs))
    F_NPhi = -A * M1 / M**2
    F_PhiPhi = A * N * (2.0 * M1**2 / M**3 - M2 / M**2)
    shape = (active.size, n_dofs)
    G_N = sp.csr_matrix((numerator_grad.ravel(), (np.repeat(row, 12), dofs.ravel())), shape=shape)
    G_Phi = sp.csr_matrix((phi_grad.ravel(), (np.repeat(row, 12), dofs.ravel())), shape=shape)
    cross = G_N.T @ sp.diags(F_NPhi) @ G_Phi
    matrix = matrix + cross + cross.T + G_Phi.T @ sp.diags(F_PhiPhi) @ G_Phi
    return internal, matrix.tocsr(), energy
