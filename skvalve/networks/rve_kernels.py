"""Numba kernels of the RVE force balance (Thomas et al. 2019 section 2.4; see ``rve.py``).

Unknowns are the positions of the interior cross-links, 3 per node; forces are divided by
E_f A_f (which cancels from the balance).  For a fiber k from node a to node b with
d = x_b − x_a, ℓ = |d|, e = d/ℓ, λ = ℓ/L0 and force f(λ):

    residual:  r_a −= f e,   r_b += f e                      (r = ∂Π/∂x, Π = Σ L0 W(λ))
    stiffness: K_k = (f'(λ)/L0) e⊗e + (f/ℓ)(I − e⊗e),  added as [[K_k, −K_k], [−K_k, K_k]].

K restricted to interior nodes is factorised by the dense Cholesky of ``dense_cholesky`` (no LAPACK
threads inside the numba ``prange`` over RVEs); the same factor gives the Newton steps, the
node sensitivities dx/dF (9 right-hand sides) and with them the consistent tangent.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from skvalve.materials.exponential_fiber import normalized_energy, normalized_force_stiffness
from skvalve.networks.dense_cholesky import cholesky_solve, factor_with_shift

# status codes of ``solve_network``
CONVERGED, NOT_CONVERGED, INDEFINITE, COLLAPSED = 0, 1, 2, 3
# Convergence: ‖r‖ ≤ tol ‖f‖ (forces in units of E_f A_f), or ‖r‖ below the round-off level
# ROUNDOFF · ‖(f'/L0)_k‖ — the residual that position errors of ~10 machine epsilons cause
# (it matters for nearly unloaded networks, where ‖f‖ itself is round-off, and for very short
# fibers, whose stiffness f'/L0 amplifies position round-off).
ROUNDOFF = 1e-15
# a Newton step reuses the previous factor if the last step cut the residual by this much
CHORD_RATIO = 1e-2


@njit(cache=True)
def assemble(x, fibers, rest_length, dof, params, residual, matrix, blocks, with_matrix, convexified=False):
    """Residual (and stiffness) of the interior DOFs; returns (‖f‖₂, ‖f'/L0‖₂, min length).

    ``convexified`` drops the negative (compressive) geometric stiffness, giving a positive
    semi-definite matrix for the Newton step when the true K is indefinite.
    """
    residual[:] = 0.0
    if with_matrix:
        matrix[:, :] = 0.0
    force_norm2 = 0.0
    stiffness_norm2 = 0.0
    min_length = np.inf
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        d0, d1, d2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        min_length = min(min_length, length)
        if length == 0.0:
            continue
        e = (d0 / length, d1 / length, d2 / length)
        f, stiffness = normalized_force_stiffness(length / rest_length[k], params)
        force_norm2 += f * f
        stiffness_norm2 += (stiffness / rest_length[k]) ** 2
        ia, ib = dof[a], dof[b]
        for i in range(3):
            if ia >= 0:
                residual[3 * ia + i] -= f * e[i]
            if ib >= 0:
                residual[3 * ib + i] += f * e[i]
        if not with_matrix:
            continue
        axial, lateral = stiffness / rest_length[k], f / length
        if convexified:
            lateral = max(lateral, 0.0)
        for i in range(3):
            for j in range(3):
                kij = (axial - lateral) * e[i] * e[j] + (lateral if i == j else 0.0)
                blocks[k, i, j] = kij
                if ia >= 0:
                    matrix[3 * ia + i, 3 * ia + j] += kij
                if ib >= 0:
                    matrix[3 * ib + i, 3 * ib + j] += kij
                if ia >= 0 and ib >= 0:
                    matrix[3 * ia + i, 3 * ib + j] -= kij
                    matrix[3 * ib + i, 3 * ia + j] -= kij
    return math.sqrt(force_norm2), math.sqrt(stiffness_norm2), min_length


@njit(cache=True)
def network_energy(x, fibers, rest_length, params):
    """Π = Σ L0 W(λ) in units of E_f A_f (for the line search)."""
    energy = 0.0
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        d0, d1, d2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        energy += rest_length[k] * normalized_energy(length / rest_length[k], params)
    return energy


@njit(cache=True)
def _trial_positions(x, dof, step, alpha, x_trial):
    for node in range(x.shape[0]):
        i = dof[node]
        if i >= 0:
            for c in range(3):
                x_trial[node, c] = x[node, c] + alpha * step[3 * i + c, 0]


@njit(cache=True)
def solve_network(X, fibers, rest_length, dof, n_free, x, F, params, tol, max_iter, sensitivity, blocks):
    """Newton iterations on ``x`` (interior rows updated in place; boundary rows must be F X).

    Fills ``sensitivity`` (3 n_free, 9) with dx/dF and ``blocks`` with the fiber stiffnesses
    at the converged state.  Returns (status, iterations, relative residual).
    """
    n = 3 * n_free
    residual = np.empty(n)
    trial_residual = np.empty(n)
    matrix = np.empty((n, n))
    work = np.empty((n, n))
    step = np.empty((n, 1))
    x_trial = x.copy()
    status = NOT_CONVERGED
    relative = np.inf
    iterations = 0
    previous_norm = 0.0  # forces a factorisation on the first step
    for iterations in range(max_iter + 1):
        force_norm, stiffness_norm, min_length = assemble(
            x, fibers, rest_length, dof, params, residual, matrix, blocks, True
        )
        if min_length < 1e-12:
            return COLLAPSED, iterations, relative
        res_norm = math.sqrt(np.sum(residual * residual))
        relative = res_norm / force_norm if force_norm > 0.0 else 0.0
        if res_norm <= max(tol * force_norm, ROUNDOFF * stiffness_norm):
            positive_definite = factor_with_shift(matrix, work, n)  # for the tangent
            status = CONVERGED if positive_definite else INDEFINITE
            break
        if iterations == max_iter:
            break
        # chord step (reuse the factor) while the residual falls fast, else refactor; an
        # indefinite K (compressed fibers) is replaced by its convexified version
        if not res_norm < CHORD_RATIO * previous_norm:
            if not factor_with_shift(matrix, work, n):
                assemble(x, fibers, rest_length, dof, params, residual, matrix, blocks, True, True)
                factor_with_shift(matrix, work, n)
        previous_norm = res_norm
        step[:, 0] = -residual
        cholesky_solve(work, n, step)
        # full step if it lowers the residual (or we are already close); otherwise Armijo
        # backtracking on the energy Π, for which the step is a descent direction
        _trial_positions(x, dof, step, 1.0, x_trial)
        assemble(x_trial, fibers, rest_length, dof, params, trial_residual, matrix, blocks, False)
        trial_res = math.sqrt(np.sum(trial_residual * trial_residual))
        if not (trial_res < res_norm or relative < 1e-6):
            energy = network_energy(x, fibers, rest_length, params)
            slope = 0.0
            for i in range(n):
                slope += residual[i] * step[i, 0]
            alpha = 1.0
            for _ in range(60):
                if network_energy(x_trial, fibers, rest_length, params) <= energy + 1e-4 * alpha * slope:
                    break
                alpha *= 0.5
                _trial_positions(x, dof, step, alpha, x_trial)
        x[:, :] = x_trial
    if status == NOT_CONVERGED:
        return status, iterations, relative
    _sensitivities(X, fibers, dof, n_free, work, blocks, sensitivity)
    return status, iterations, relative


@njit(cache=True)
def _sensitivities(X, fibers, dof, n_free, factor, blocks, sensitivity):
    """dx_int/dF_pq = −K_ii⁻¹ K_ib (e_p X_q) for the 9 components, column pq = 3p + q."""
    n = 3 * n_free
    sensitivity[:, :] = 0.0
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        ia, ib = dof[a], dof[b]
        if (ia >= 0) == (ib >= 0):
            continue  # only interior–boundary fibers load the interior
        for p in range(3):
            for q in range(3):
                # boundary velocity δx = e_p X_q; t = K_k (δx_b − δx_a)
                vb = X[b, q] if ib < 0 else 0.0
                va = X[a, q] if ia < 0 else 0.0
                for i in range(3):
                    t = blocks[k, i, p] * (vb - va)
                    if ia >= 0:
                        sensitivity[3 * ia + i, 3 * p + q] += t
                    if ib >= 0:
                        sensitivity[3 * ib + i, 3 * p + q] -= t
    cholesky_solve(factor, n, sensitivity)


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


@njit(cache=True)
def _node_velocity(node, dof, X, sensitivity, out):
    """∂x_node/∂F_pq as a (3, 9) array: dx/dF rows for interior nodes, δ_ip X_q on the boundary."""
    i = dof[node]
    if i >= 0:
        for c in range(3):
            for pq in range(9):
                out[c, pq] = sensitivity[3 * i + c, pq]
    else:
        out[:, :] = 0.0
        for p in range(3):
            for q in range(3):
                out[p, 3 * p + q] = X[node, q]


@njit(cache=True)
def stress_and_tangent(X, x, fibers, rest_length, dof, F, params, scale, sensitivity, cauchy, tangent, stretch):
    """σ = scale/J Σ (f/ℓ) d⊗d (Eq. 8 as a fiber virial) and dσ_ij/dF_pq, fiber stretches."""
    J, F_inv = _det_inv3(F)
    virial = np.zeros(6)
    dvirial = np.zeros((6, 9))
    d = np.empty(3)
    va, vb = np.empty((3, 9)), np.empty((3, 9))
    dd = np.empty((3, 9))
    dlength = np.empty(9)
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        for i in range(3):
            d[i] = x[b, i] - x[a, i]
        length = math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
        stretch[k] = length / rest_length[k]
        f, stiffness = normalized_force_stiffness(stretch[k], params)
        ratio = f / length
        dratio = (stiffness / rest_length[k] - ratio) / length  # ∂(f/ℓ)/∂ℓ
        _node_velocity(a, dof, X, sensitivity, va)
        _node_velocity(b, dof, X, sensitivity, vb)
        for pq in range(9):
            for i in range(3):
                dd[i, pq] = vb[i, pq] - va[i, pq]
            dlength[pq] = dratio * (d[0] * dd[0, pq] + d[1] * dd[1, pq] + d[2] * dd[2, pq]) / length
        for s in range(6):
            i, j = SYM_I[s], SYM_J[s]
            virial[s] += ratio * d[i] * d[j]
            for pq in range(9):
                dvirial[s, pq] += dlength[pq] * d[i] * d[j] + ratio * (dd[i, pq] * d[j] + d[i] * dd[j, pq])
    factor = scale / J
    for s in range(6):
        i, j = SYM_I[s], SYM_J[s]
        cauchy[i, j] = cauchy[j, i] = factor * virial[s]
    for s in range(6):
        i, j = SYM_I[s], SYM_J[s]
        for p in range(3):
            for q in range(3):
                value = factor * dvirial[s, 3 * p + q] - cauchy[i, j] * F_inv[q, p]
                tangent[i, j, p, q] = value
                tangent[j, i, p, q] = value


@njit(cache=True)
def predict(X, dof, x_previous, F_previous, sensitivity, F, x):
    """Boundary x = F X; interior x = x_prev + (dx/dF) : (F − F_prev) (first-order predictor)."""
    for node in range(X.shape[0]):
        i = dof[node]
        for c in range(3):
            if i < 0:
                x[node, c] = F[c, 0] * X[node, 0] + F[c, 1] * X[node, 1] + F[c, 2] * X[node, 2]
            else:
                value = x_previous[node, c]
                for p in range(3):
                    for q in range(3):
                        value += sensitivity[3 * i + c, 3 * p + q] * (F[p, q] - F_previous[p, q])
                x[node, c] = value


@njit(cache=True)
def solve_one(
    X,
    fibers,
    rest_length,
    dof,
    n_free,
    x_previous,
    F_previous,
    sensitivity,
    F,
    params,
    scale,
    tol,
    max_iter,
    x,
    cauchy,
    tangent,
    stretch,
):
    """Predict, solve, post-process one RVE; ``sensitivity`` is read then overwritten."""
    predict(X, dof, x_previous, F_previous, sensitivity, F, x)
    blocks = np.empty((fibers.shape[0], 3, 3))
    status, iterations, relative = solve_network(
        X, fibers, rest_length, dof, n_free, x, F, params, tol, max_iter, sensitivity, blocks
    )
    if status == CONVERGED or status == INDEFINITE:
        stress_and_tangent(X, x, fibers, rest_length, dof, F, params, scale, sensitivity, cauchy, tangent, stretch)
    return status, iterations, relative


@njit(cache=True, parallel=True)
def solve_many(
    node_start,
    fiber_start,
    free_start,
    X,
    fibers,
    rest_length,
    dof,
    n_free,
    x_previous,
    F_previous,
    sensitivity,
    F,
    params,
    scale,
    tol,
    max_iter,
    x,
    cauchy,
    tangent,
    stretch,
    status,
    iterations,
    relative,
):
    """``solve_one`` over a batch of RVEs packed end to end (offset arrays of length B + 1)."""
    for r in prange(F.shape[0]):
        n0, n1 = node_start[r], node_start[r + 1]
        m0, m1 = fiber_start[r], fiber_start[r + 1]
        s0, s1 = free_start[r], free_start[r + 1]
        status[r], iterations[r], relative[r] = solve_one(
            X[n0:n1],
            fibers[m0:m1],
            rest_length[m0:m1],
            dof[n0:n1],
            n_free[r],
            x_previous[n0:n1],
            F_previous[r],
            sensitivity[s0:s1],
            F[r],
            params,
            scale[r],
            tol,
            max_iter,
            x[n0:n1],
            cauchy[r],
            tangent[r],
            stretch[m0:m1],
        )
