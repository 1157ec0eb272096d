"""Numba kernels of the RVE force balance (Thomas et al. 2019 section 2.4; see ``rve.py``).

Unknowns are the positions of the interior cross-links, 3 per node, numbered in the
bandwidth-reducing order chosen by ``rve.py`` (``dof``); forces are divided by E_f A_f (which
cancels from the balance).  For a fiber k from node a to node b with d = x_b − x_a, ℓ = ‖d‖,
e = d/ℓ, λ = ℓ/L0 and force f(λ):

    residual:  r_a −= f e,   r_b += f e                      (r = ∂Π/∂x, Π = Σ L0 W(λ))
    stiffness: K_k = (f'(λ)/L0) e⊗e + (f/ℓ)(I − e⊗e),  added as [[K_k, −K_k], [−K_k, K_k]].

Only the lower envelope of K (rows from ``first[i]``) is assembled and factorised
(``dense_cholesky``); the same factor gives the Newton steps, the node sensitivities dx/dF
(9 right-hand sides in one blocked solve) and with them the consistent tangent.  The last
assembly stores f, f'/L0 and ℓ per fiber, which the sensitivity and stress passes reuse.
Work arrays are allocated once per chunk of RVEs (``workspace``), not per solve.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from skvalve.materials.exponential_fiber import normalized_energy, normalized_force_stiffness
from skvalve.networks.dense_cholesky import cholesky_solve_vector, factor_with_shift, node_cholesky_solve
from skvalve.networks.rve_tangent import FIBER_DATA_COLUMNS, stress_and_tangent

# status codes of ``solve_network``
CONVERGED, NOT_CONVERGED, INDEFINITE, COLLAPSED = 0, 1, 2, 3
# where an RVE of ``solve_many`` starts from: its stored state, the alternate one, the affine guess
START_STATE, START_ALTERNATE, START_COLD = 0, 1, 2
# Convergence: ‖r‖ ≤ tol ‖f‖ (forces in units of E_f A_f), or ‖r‖ below the round-off level
# ROUNDOFF · ‖(f'/L0)_k‖ — the residual that position errors of ~10 machine epsilons cause
# (it matters for nearly unloaded networks, where ‖f‖ itself is round-off, and for very short
# fibers, whose stiffness f'/L0 amplifies position round-off).
ROUNDOFF = 1e-15
# a Newton step reuses the previous factor if the last step cut the residual by this much
CHORD_RATIO = 1e-2
# columns of the per-fiber data stored by ``assemble`` (read by ``rve_tangent``)
FORCE, AXIAL, LENGTH = FIBER_DATA_COLUMNS


@njit(cache=True)
def workspace(n_max, m_max, nodes_max):
    """Work arrays of one thread: residuals, K and its factor (flat, reshaped per RVE), step,
    trial positions, per-fiber data (f, f'/L0, ℓ) and the node accumulators of the tangent."""
    return (
        np.empty(n_max),
        np.empty(n_max),
        np.empty(n_max * n_max),
        np.empty(n_max * n_max),
        np.empty(n_max),
        np.empty((nodes_max, 3)),
        np.empty((m_max, 3)),
        np.empty((n_max // 3, 6, 3)),
    )


@njit(cache=True)
def assemble(x, fibers, rest_length, dof, first, params, residual, matrix, fiber_data, with_matrix, convexified):
    """Residual (and lower envelope of K) of the interior DOFs; returns (‖f‖₂, ‖f'/L0‖₂, min length).

    ``convexified`` drops the negative (compressive) geometric stiffness, giving a positive
    semi-definite matrix for the Newton step when the true K is indefinite.
    """
    residual[:] = 0.0
    if with_matrix:
        for i in range(residual.shape[0]):
            for j in range(first[i], i + 1):
                matrix[i, j] = 0.0
    force_norm2 = 0.0
    stiffness_norm2 = 0.0
    min_length = np.inf
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        d0, d1, d2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        min_length = min(min_length, length)
        fiber_data[k, LENGTH] = length
        if length == 0.0:
            continue
        e = (d0 / length, d1 / length, d2 / length)
        f, stiffness = normalized_force_stiffness(length / rest_length[k], params)
        axial = stiffness / rest_length[k]
        fiber_data[k, FORCE] = f
        fiber_data[k, AXIAL] = axial
        force_norm2 += f * f
        stiffness_norm2 += axial * axial
        ia, ib = dof[a], dof[b]
        if ia >= 0:
            for i in range(3):
                residual[3 * ia + i] -= f * e[i]
        if ib >= 0:
            for i in range(3):
                residual[3 * ib + i] += f * e[i]
        if not with_matrix or (ia < 0 and ib < 0):
            continue
        lateral = f / length
        if convexified:
            lateral = max(lateral, 0.0)
        # k_ij = (f'/L0 − f/ℓ) e_i e_j + (f/ℓ) δ_ij, all nine (the off-diagonal block is not symmetric in round-off)
        s0, s1, s2 = (axial - lateral) * e[0], (axial - lateral) * e[1], (axial - lateral) * e[2]
        k00, k01, k02 = s0 * e[0] + lateral, s0 * e[1], s0 * e[2]
        k10, k11, k12 = s1 * e[0], s1 * e[1] + lateral, s1 * e[2]
        k20, k21, k22 = s2 * e[0], s2 * e[1], s2 * e[2] + lateral
        for node in (ia, ib):
            if node >= 0:
                row = 3 * node
                matrix[row, row] += k00
                matrix[row + 1, row] += k10
                matrix[row + 1, row + 1] += k11
                matrix[row + 2, row] += k20
                matrix[row + 2, row + 1] += k21
                matrix[row + 2, row + 2] += k22
        if ia >= 0 and ib >= 0:  # off-diagonal block in row block max(ia, ib)
            high, low = 3 * max(ia, ib), 3 * min(ia, ib)
            matrix[high, low] -= k00
            matrix[high, low + 1] -= k01
            matrix[high, low + 2] -= k02
            matrix[high + 1, low] -= k10
            matrix[high + 1, low + 1] -= k11
            matrix[high + 1, low + 2] -= k12
            matrix[high + 2, low] -= k20
            matrix[high + 2, low + 1] -= k21
            matrix[high + 2, low + 2] -= k22
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
                x_trial[node, c] = x[node, c] + alpha * step[3 * i + c]
        else:
            for c in range(3):
                x_trial[node, c] = x[node, c]


@njit(cache=True)
def solve_network(X, fibers, rest_length, dof, first, n_free, x, params, tol, max_iter, sensitivity, ws,
                  keep_start=False):
    """Newton iterations on ``x`` (interior rows updated in place; boundary rows must be F X).

    Fills ``sensitivity`` (3 n_free, 9) with dx/dF at the converged state and leaves the
    converged per-fiber data in ``ws``.  Returns (status, iterations, relative residual).
    ``keep_start``: if the start (the predictor) already satisfies the balance, ``sensitivity`` is
    left as it is (the start's; see ``solve_one``) and K is not factorised.
    """
    n = 3 * n_free
    residual, trial_residual = ws[0][:n], ws[1][:n]
    matrix, work = ws[2][: n * n].reshape((n, n)), ws[3][: n * n].reshape((n, n))
    step, x_trial, fiber_data = ws[4][:n], ws[5][: x.shape[0]], ws[6]
    status = NOT_CONVERGED
    relative = np.inf
    iterations = 0
    previous_norm = 0.0  # forces a factorisation on the first step
    known = False  # residual, K and norms at x already known (from the accepted trial step)
    for iterations in range(max_iter + 1):
        if not known:
            force_norm, stiffness_norm, min_length = assemble(
                x, fibers, rest_length, dof, first, params, residual, matrix, fiber_data, True, False
            )
        if min_length < 1e-12:
            return COLLAPSED, iterations, relative
        res_norm = math.sqrt(np.sum(residual * residual))
        relative = res_norm / force_norm if force_norm > 0.0 else 0.0
        converged = res_norm <= max(tol * force_norm, ROUNDOFF * stiffness_norm)
        # chord step (reuse the factor) while the residual falls fast, else refactor
        chord = res_norm < CHORD_RATIO * previous_norm
        if converged and iterations == 0 and keep_start:
            return CONVERGED, 0, relative
        if converged:
            positive_definite = factor_with_shift(matrix, work, n, first, True)  # for the tangent
            status = CONVERGED if positive_definite else INDEFINITE
            break
        if iterations == max_iter:
            break
        # an indefinite K (compressed fibers) is replaced by its convexified version
        if not chord:
            if not factor_with_shift(matrix, work, n, first, True):
                assemble(x, fibers, rest_length, dof, first, params, residual, matrix, fiber_data, True, True)
                factor_with_shift(matrix, work, n, first, True)
        previous_norm = res_norm
        for i in range(n):
            step[i] = -residual[i]
        cholesky_solve_vector(work, n, first, step)
        # full step if it lowers the residual (or we are already close); otherwise Armijo
        # backtracking on the energy Π, for which the step is a descent direction.  The trial
        # assembles K as well (the factor lives in ``work``): an accepted step needs it next.
        _trial_positions(x, dof, step, 1.0, x_trial)
        trial_norms = assemble(
            x_trial, fibers, rest_length, dof, first, params, trial_residual, matrix, fiber_data, True, False
        )
        trial_res = math.sqrt(np.sum(trial_residual * trial_residual))
        known = trial_res < res_norm or relative < 1e-6
        if known:  # the full step is taken: its residual is the next iteration's
            residual[:] = trial_residual
            force_norm, stiffness_norm, min_length = trial_norms
        else:
            energy = network_energy(x, fibers, rest_length, params)
            slope = 0.0
            for i in range(n):
                slope += residual[i] * step[i]
            alpha = 1.0
            for _ in range(60):
                if network_energy(x_trial, fibers, rest_length, params) <= energy + 1e-4 * alpha * slope:
                    break
                alpha *= 0.5
                _trial_positions(x, dof, step, alpha, x_trial)
        x[:, :] = x_trial
    if status == NOT_CONVERGED:
        return status, iterations, relative
    _sensitivities(X, x, fibers, dof, first, n_free, work, fiber_data, sensitivity)
    return status, iterations, relative


@njit(cache=True)
def _sensitivities(X, x, fibers, dof, first, n_free, factor, fiber_data, sensitivity):
    """dx_int/dF_pq = −K_ii⁻¹ K_ib (e_p X_q) for the 9 components, column pq = 3p + q.

    The 9 right-hand sides are the columns of ``sensitivity``, solved in one blocked sweep.
    """
    sensitivity[:, :] = 0.0
    for k in range(fibers.shape[0]):
        a, b = fibers[k, 0], fibers[k, 1]
        ia, ib = dof[a], dof[b]
        if (ia >= 0) == (ib >= 0):
            continue  # only interior–boundary fibers load the interior
        length = fiber_data[k, LENGTH]
        lateral = fiber_data[k, FORCE] / length
        axial = fiber_data[k, AXIAL]
        e = ((x[b, 0] - x[a, 0]) / length, (x[b, 1] - x[a, 1]) / length, (x[b, 2] - x[a, 2]) / length)
        # boundary velocity δx = e_p X_q of the boundary end; the interior row gets K_k δx
        # (with the sign of −K_ib = +K_k whichever end is interior)
        row, node = (ia, b) if ia >= 0 else (ib, a)
        for i in range(3):
            for p in range(3):
                kip = (axial - lateral) * e[i] * e[p] + (lateral if i == p else 0.0)
                for q in range(3):
                    sensitivity[3 * row + i, 3 * p + q] += kip * X[node, q]
    node_cholesky_solve(factor, 3 * n_free, first, sensitivity)


@njit(cache=True)
def predict(X, dof, x_previous, F_previous, sensitivity, F, x, cold=False):
    """Boundary x = F X; interior x = x_prev + (dx/dF) : (F − F_prev) (first-order predictor).

    ``cold``: no start state, every node at x = F X (the affine guess; ``x_previous`` etc. not read).
    """
    for node in range(X.shape[0]):
        i = dof[node]
        for c in range(3):
            if i < 0 or cold:
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
    first,
    n_free,
    x_previous,
    F_previous,
    sensitivity_previous,
    cold,
    F,
    params,
    scale,
    tol,
    max_iter,
    x,
    cauchy,
    tangent,
    stretch,
    sensitivity,
    ws,
    keep_start=False,
):
    """Predict from the start (``x_previous``, ``F_previous``, ``sensitivity_previous``; or ``cold``), solve,
    post-process one RVE into ``x``, ``cauchy``, ``tangent``, ``stretch`` and ``sensitivity`` (dx/dF).

    ``keep_start`` (the caller has put the start state's dσ/dF in ``tangent`` and checked that F differs
    from the start's by at most √tol): when the first-order predictor already satisfies the force
    balance to ``tol``, the start's dx/dF and dσ/dF are kept and only σ is computed at the new
    positions.  Their change over such a step is O(√tol) relative (1e-5 at tol = 1e-10): it affects the
    macro Newton tangent, not the stress.
    """
    predict(X, dof, x_previous, F_previous, sensitivity_previous, F, x, cold)
    status, iterations, relative = solve_network(
        X, fibers, rest_length, dof, first, n_free, x, params, tol, max_iter, sensitivity, ws, keep_start and not cold
    )
    if status == CONVERGED or status == INDEFINITE:
        kept = keep_start and not cold and iterations == 0
        if kept:
            sensitivity[:, :] = sensitivity_previous
        stress_and_tangent(
            X, x, fibers, rest_length, dof, F, scale, sensitivity, ws[6], ws[7][:n_free], cauchy, tangent, stretch,
            not kept,
        )
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
    first,
    n_free,
    x_state,
    F_state,
    sensitivity_state,
    x_alternate,
    F_alternate,
    sensitivity_alternate,
    start,
    F,
    params,
    scale,
    tol,
    max_iter,
    x,
    sensitivity,
    cauchy,
    tangent,
    stretch,
    status,
    iterations,
    relative,
    active,
    keep_start,
    n_chunks,
):
    """``solve_one`` for the RVEs listed in ``active`` of a batch packed end to end (offset arrays of length B + 1).

    RVE r starts from the stored state (``start[r]`` = ``START_STATE``), the alternate one (``START_ALTERNATE``)
    or the affine guess (``START_COLD``); results go to ``x``, ``sensitivity``, ... (never to a start array).
    ``keep_start[r]``: RVE r's start state came with its tangent (already in ``tangent[r]``).
    The active list is cut into ``n_chunks`` contiguous chunks scheduled by ``prange``; each chunk
    allocates one workspace and reuses it for its RVEs.  RVEs not listed are not touched.
    """
    count = active.shape[0]
    n_max = 3 * np.max(n_free)
    m_max = np.max(fiber_start[1:] - fiber_start[:-1])
    nodes_max = np.max(node_start[1:] - node_start[:-1])
    for chunk in prange(n_chunks):
        ws = workspace(n_max, m_max, nodes_max)
        for position in range(chunk * count // n_chunks, (chunk + 1) * count // n_chunks):
            r = active[position]
            n0, n1 = node_start[r], node_start[r + 1]
            m0, m1 = fiber_start[r], fiber_start[r + 1]
            s0, s1 = free_start[r], free_start[r + 1]
            alternate = start[r] == START_ALTERNATE
            x_previous = x_alternate[n0:n1] if alternate else x_state[n0:n1]
            F_previous = F_alternate[r] if alternate else F_state[r]
            sensitivity_previous = sensitivity_alternate[s0:s1] if alternate else sensitivity_state[s0:s1]
            status[r], iterations[r], relative[r] = solve_one(
                X[n0:n1],
                fibers[m0:m1],
                rest_length[m0:m1],
                dof[n0:n1],
                first[s0:s1],
                n_free[r],
                x_previous,
                F_previous,
                sensitivity_previous,
                start[r] == START_COLD,
                F[r],
                params,
                scale[r],
                tol,
                max_iter,
                x[n0:n1],
                cauchy[r],
                tangent[r],
                stretch[m0:m1],
                sensitivity[s0:s1],
                ws,
                keep_start[r],
            )


@njit(cache=True, parallel=True)
def copy_rows(node_start, fiber_start, free_start, rves, from_alternate, x_state, x_alternate, sensitivity_state,
              sensitivity_alternate, stretch_state, stretch_alternate, x, sensitivity, stretch):
    """Copy the packed rows (positions, dx/dF, fiber stretches) of the listed RVEs from the stored or the alternate
    results (``from_alternate[r]``) into the output arrays (RVEs whose F did not change)."""
    for position in prange(rves.shape[0]):
        r = rves[position]
        n0, n1 = node_start[r], node_start[r + 1]
        m0, m1 = fiber_start[r], fiber_start[r + 1]
        s0, s1 = free_start[r], free_start[r + 1]
        if from_alternate[r]:
            x[n0:n1] = x_alternate[n0:n1]
            sensitivity[s0:s1] = sensitivity_alternate[s0:s1]
            stretch[m0:m1] = stretch_alternate[m0:m1]
        else:
            x[n0:n1] = x_state[n0:n1]
            sensitivity[s0:s1] = sensitivity_state[s0:s1]
            stretch[m0:m1] = stretch_state[m0:m1]
