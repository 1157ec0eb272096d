"""Fiber-network RVE: force balance, volume-averaged stress, consistent tangent (Thomas 2019 §2.4).

Model.  Fibers are nonlinear springs (Eq. 9, :class:`ExponentialFiber`) between cross-links.
Boundary cross-links follow the macroscopic deformation, x = F X; interior cross-links are
placed by force balance Σ_fibers f e = 0, solved by Newton with a dense Cholesky (numba).

Stress.  Eq. 5 sums x ⊗ f over the boundary cross-links, f being the force the boundary
exerts on the network.  Summing instead over fibers (every fiber pulls its two ends with
±f e) gives the same number at equilibrium — the interior terms vanish — and a form that is
symmetric by construction:

    Σ_boundary x ⊗ f = Σ_fibers (f/ℓ) d ⊗ d,          d = x_b − x_a, ℓ = ‖d‖.

With the dimensional scaling of Eqs. 6–7 (RVE edge γ = √(L A_f/ψ), L the total reference
fiber length of the unit cube) Eq. 8 reads

    σ = ψ / (L A_f V) Σ_fibers (f/ℓ) d ⊗ d,            V = det F (current volume of the cube).

Because f ∝ E_f A_f, σ = ψ E_f/(L V) Σ (f̂/ℓ) d⊗d with f̂ = f/(E_f A_f): the fiber diameter
cancels (it only fixes γ) when the force law and Eq. 8 use the same A_f, which is the default.

Consistent tangent.  With the converged stiffness K = ∂r/∂x partitioned into interior (i) and
boundary (b) blocks, r_i(x_i(F), F X) = 0 gives for each component F_pq

    K_ii ∂x_i/∂F_pq = −K_ib (e_p X_q),

nine solves with the Cholesky factor already computed for the last Newton check.  Then

    ∂σ_ij/∂F_pq = ψ/(L A_f V) Σ [∂(f/ℓ)/∂ℓ δℓ d_i d_j + (f/ℓ)(δd_i d_j + d_i δd_j)]
                  − σ_ij F⁻¹_qp,   δd = ∂d/∂F_pq, δℓ = e·δd,  ∂(f/ℓ)/∂ℓ = (f'/L0 − f/ℓ)/ℓ.

The same dx/dF is the first-order predictor of the next warm-started solve.

Floppy / slack nodes: *regularised*, not eliminated.  Generated networks have no dangling
fibers or two-fiber hinges (``generate.prune``), and with the paper's force law a fiber is
never stress- and stiffness-free, so K is positive definite at and near the reference state.
Compressed fibers bring negative geometric stiffness f/ℓ < 0 and can make K indefinite
(buckling).  Then the Newton step uses the *convexified* K — compressive geometric terms
dropped, plus τ max(diag K) I with the smallest τ in 0, 1e-10, 1e-8, … that factorises — and
an Armijo backtracking on the stored energy Π = Σ L0 W(λ), for which that step is a descent
direction.  The converged state satisfies the exact balance; an equilibrium on an indefinite
K is flagged ``status == 2`` with a warning (unstable; tangent from the shifted factor).  With
``compression="buckle"`` slack fibers keep a residual stiffness (see ExponentialFiber), a
regularisation of the same kind.  Elimination of floppy nodes would change the unknowns
between load steps and break the warm start, which is why it was not chosen.  States where
most fibers are compressed (e.g. 20 % hydrostatic compression with the paper's law) are
buckling problems without a unique equilibrium; they may fail with RuntimeError.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks.network import Network
from skvalve.networks.rve_batch import CHUNKS_PER_THREAD, RVEBatch, RVEResult, RVEState, _scale

__all__ = ["CHUNKS_PER_THREAD", "RVEBatch", "RVEResult", "RVEState", "boundary_stress", "solve_rve",
           "solve_rve_batch"]


def solve_rve(
    network: Network,
    F: np.ndarray,
    fiber: ExponentialFiber,
    psi: float,
    fiber_diameter: float | None,
    state: RVEState | None = None,
    tol: float = 1e-10,
    max_iter: int = 30,
) -> RVEResult:
    """Equilibrate one RVE under x = F X on its boundary; σ (Eq. 8) and dσ/dF.

    ``fiber_diameter`` sets A_f in Eq. 8 and γ in Eq. 7 (None: use ``fiber.A_f``).
    ``state`` from a previous result warm-starts the Newton iteration.
    """
    F = np.asarray(F, dtype=float)
    if F.shape != (3, 3):
        raise ValueError(f"solve_rve: F must have shape (3, 3), got {F.shape} (use solve_rve_batch for many)")
    batch = RVEBatch([network], fiber, psi, fiber_diameter, tol, max_iter)
    batch.set_state(0, state)
    return batch.result(0, batch.solve(F[None]))


def solve_rve_batch(
    networks: Sequence[Network],
    F: np.ndarray,
    fiber: ExponentialFiber,
    psi: float,
    fiber_diameter: float | None,
    states: Sequence[RVEState | None] | None = None,
    tol: float = 1e-10,
) -> list[RVEResult]:
    """:func:`solve_rve` for many (network, F) pairs in one parallel numba call."""
    batch = RVEBatch(networks, fiber, psi, fiber_diameter, tol)
    states = [] if states is None else list(states)
    if len(states) not in (0, len(batch.networks)):
        raise ValueError(f"solve_rve_batch: {len(states)} states for {len(batch.networks)} networks")
    for r, state in enumerate(states):
        batch.set_state(r, state)
    out = batch.solve(np.asarray(F, dtype=float))
    return [batch.result(r, out) for r in range(len(batch.networks))]


def boundary_stress(
    network: Network,
    result: RVEResult,
    fiber: ExponentialFiber,
    psi: float,
    fiber_diameter: float | None,
) -> np.ndarray:
    """Eq. 8 literally: ψ/(L A_f V) Σ_boundary x ⊗ f, f the reaction at each boundary node."""
    x = result.deformed_nodes
    d = network.fiber_vectors(x)
    length = np.linalg.norm(d, axis=1)
    force = fiber.force(result.fiber_stretch)[:, None] * d / length[:, None]
    reaction = np.zeros_like(x)
    np.add.at(reaction, network.fibers[:, 1], force)  # fiber pulls its end b back: boundary
    np.add.at(reaction, network.fibers[:, 0], -force)  # holds it with +f e (and a with −f e)
    volume = np.linalg.det(result.state.F)
    prefactor = _scale(network, fiber, psi, fiber_diameter)[0] / fiber.axial_rigidity  # ψ / (L A_f)
    b = network.boundary
    return prefactor / volume * x[b].T @ reaction[b]
