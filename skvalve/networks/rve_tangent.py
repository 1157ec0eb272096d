"""Volume-averaged fiber stress (Thomas 2019 Eq. 8) and its consistent tangent, one RVE (numba).

Called by ``rve_kernels.solve_one`` once the force balance has converged; see ``rve.py`` for the
formulas.  Reads the per-fiber data (f, f'/L0, ℓ) the last assembly stored and the node
sensitivities dx/dF of the interior cross-links.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skvalve.networks.dense_cholesky import FAST

# columns of the per-fiber data (force f, axial stiffness f'/L0, length ℓ), in units of E_f A_f
FORCE, AXIAL, LENGTH = FIBER_DATA_COLUMNS = (0, 1, 2)


@njit(cache=True)
def _det_inv3(F):
    """det F and F⁻¹ of a 3×3 matrix by cofactors."""
    cof = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            i1, i2, j1, j2 = (i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3
            cof[i, j] = F[i1, j1] * F[i2, j2] - F[i1, j2] * F[i2, j1]
    det = F[0, 0] * cof[0, 0] + F[0, 1] * cof[0, 1] + F[0, 2] * cof[0, 2]
    return det, cof.T / det


SYM_I = (0, 1, 2, 0, 0, 1)  # the 6 independent (i, j) of a symmetric 3×3 tensor
SYM_J = (0, 1, 2, 1, 2, 2)


@njit(cache=True, fastmath=FAST)
def stress_and_tangent(
    X, x, fibers, rest_length, dof, F, scale, sensitivity, fiber_data, node_sum, cauchy, tangent, stretch,
    with_tangent=True,
):
    """σ = scale/J Σ (f/ℓ) d⊗d (Eq. 8 as a fiber virial) and dσ_ij/dF_pq, fiber stretches.

    ``with_tangent=False`` computes σ and the stretches only (``tangent`` is not written).

    The virial's derivative is linear in the end velocities δd = v_b − v_a of each fiber:
    Σ_k A_k δd_k with A_k[ij, c] = ∂(f/ℓ)/∂ℓ (d_c/ℓ) d_i d_j + (f/ℓ)(δ_ic d_j + d_i δ_jc).
    A boundary end moves with v_c,pq = δ_cp X_q, so its share is A_k[ij, p] X_q at once; the
    interior ends are first summed per node (``node_sum``, n_free × 6 × 3) and multiplied by
    the node sensitivities once per node instead of once per fiber.
    """
    J, F_inv = _det_inv3(F)
    virial = np.zeros(6)
    dvirial = np.zeros((6, 9))
    node_sum[:, :, :] = 0.0
    A = np.empty((6, 3))
    dd = np.empty(6)
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        d = (x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2])
        length = fiber_data[k, LENGTH]
        stretch[k] = length / rest_length[k]
        ratio = fiber_data[k, FORCE] / length
        dratio = (fiber_data[k, AXIAL] - ratio) / length  # ∂(f/ℓ)/∂ℓ
        scaled = dratio / length
        for s in range(6):
            i, j = SYM_I[s], SYM_J[s]
            dd[s] = d[i] * d[j]
            virial[s] += ratio * dd[s]
        if not with_tangent:
            continue
        for s in range(6):
            i, j = SYM_I[s], SYM_J[s]
            for c in range(3):
                A[s, c] = scaled * dd[s] * d[c]
            A[s, i] += ratio * d[j]
            A[s, j] += ratio * d[i]
        ia, ib = dof[a], dof[b]
        if ib >= 0:
            for s in range(6):
                for c in range(3):
                    node_sum[ib, s, c] += A[s, c]
        if ia >= 0:
            for s in range(6):
                for c in range(3):
                    node_sum[ia, s, c] -= A[s, c]
        if ia < 0 or ib < 0:
            w0, w1, w2 = 0.0, 0.0, 0.0
            if ib < 0:
                w0, w1, w2 = X[b, 0], X[b, 1], X[b, 2]
            if ia < 0:
                w0, w1, w2 = w0 - X[a, 0], w1 - X[a, 1], w2 - X[a, 2]
            for s in range(6):
                for p in range(3):
                    dvirial[s, 3 * p] += A[s, p] * w0
                    dvirial[s, 3 * p + 1] += A[s, p] * w1
                    dvirial[s, 3 * p + 2] += A[s, p] * w2
    factor = scale / J
    for s in range(6):
        i, j = SYM_I[s], SYM_J[s]
        cauchy[i, j] = cauchy[j, i] = factor * virial[s]
    if not with_tangent:
        return
    for node in range(node_sum.shape[0]):
        for s in range(6):
            for c in range(3):
                g = node_sum[node, s, c]
                for pq in range(9):
                    dvirial[s, pq] += g * sensitivity[3 * node + c, pq]
    for s in range(6):
        i, j = SYM_I[s], SYM_J[s]
        for p in range(3):
            for q in range(3):
                value = factor * dvirial[s, 3 * p + q] - cauchy[i, j] * F_inv[q, p]
                tangent[i, j, p, q] = value
                tangent[j, i, p, q] = value
