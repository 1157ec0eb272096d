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

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numba
import numpy as np

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks import rve_kernels as kernels
from skvalve.networks.dense_cholesky import interior_numbering
from skvalve.networks.network import Network


@dataclass
class RVEState:
    """Warm-start data: node positions, the F they belong to, and dx_interior/dF."""

    positions: np.ndarray
    F: np.ndarray
    sensitivity: np.ndarray


@dataclass
class RVEResult:
    cauchy: np.ndarray  # (3, 3) volume-averaged fiber Cauchy stress, units of E_f
    tangent: np.ndarray  # (3, 3, 3, 3) dσ_ij/dF_kl
    fiber_stretch: np.ndarray  # (m,)
    state: RVEState
    deformed_nodes: np.ndarray  # (n, 3)
    iterations: int
    residual: float  # ‖r‖ / ‖f‖ at convergence
    status: int  # 0 converged, 2 converged on an indefinite stiffness
    rve_edge_length: float  # γ of Eq. 7 (m)


# RVE chunks per numba thread in a batch solve: load balance vs. one workspace per chunk
CHUNKS_PER_THREAD = 4


def _check_F(F: np.ndarray, where: str) -> np.ndarray:
    F = np.asarray(F, dtype=float)
    if F.shape[-2:] != (3, 3) or not np.all(np.isfinite(F)):
        raise ValueError(f"{where}: F must be finite with shape (..., 3, 3), got {F.shape}")
    if np.any(np.linalg.det(F) <= 0):
        raise ValueError(f"{where}: det F must be positive")
    return F


def _scale(network: Network, fiber: ExponentialFiber, psi: float, diameter: float | None):
    """(ψ E_f A_f /(L A_f,Eq8), γ): Eq. 8 prefactor for forces normalised by E_f A_f."""
    if not isinstance(network, Network):
        raise TypeError(f"solve_rve: network must be a skvalve.networks.Network, got {type(network).__name__}")
    if not isinstance(fiber, ExponentialFiber):
        raise TypeError(f"solve_rve: fiber must be an ExponentialFiber, got {type(fiber).__name__}")
    if not (0.0 < psi <= 1.0):
        raise ValueError(f"solve_rve: psi (fiber volume fraction) must be in (0, 1], got {psi}")
    if diameter is not None and not (math.isfinite(float(diameter)) and float(diameter) > 0.0):
        raise ValueError(f"solve_rve: fiber_diameter must be positive and finite, got {diameter}")
    area = fiber.A_f if diameter is None else math.pi * float(diameter) ** 2 / 4.0
    length = network.total_length
    if not length > 0.0:
        raise ValueError("solve_rve: the network has no fibers (total length 0)")
    return psi * fiber.axial_rigidity / (length * area), math.sqrt(length * area / psi)


class RVEBatch:
    """Several networks packed for the parallel kernel, with their warm-start states.

    ``solve(F)`` (F of shape (B, 3, 3)) solves all RVEs from their stored states and, by
    default, stores the new ones.  This is the form the FE² coupling calls.
    """

    def __init__(
        self,
        networks: Sequence[Network],
        fiber: ExponentialFiber,
        psi: float,
        fiber_diameter: float | None,
        tol: float = 1e-10,
        max_iter: int = 30,
    ) -> None:
        if len(networks) == 0:
            raise ValueError("RVEBatch: no networks given")
        if not (math.isfinite(tol) and tol > 0.0):
            raise ValueError(f"RVEBatch: tol must be positive and finite, got {tol}")
        if int(max_iter) < 1:
            raise ValueError(f"RVEBatch: max_iter must be >= 1, got {max_iter}")
        self.networks = list(networks)
        scales = [_scale(net, fiber, psi, fiber_diameter) for net in self.networks]
        self.fiber, self.params = fiber, fiber.parameters()
        self.tol, self.max_iter = float(tol), int(max_iter)
        self.scale = np.array([s for s, _ in scales])
        self.edge_length = np.array([g for _, g in scales])
        n_nodes = [net.n_nodes for net in self.networks]
        n_fibers = [net.n_fibers for net in self.networks]
        self.n_free = np.array([int((~net.boundary).sum()) for net in self.networks])
        self.node_start = np.concatenate([[0], np.cumsum(n_nodes)]).astype(np.int64)
        self.fiber_start = np.concatenate([[0], np.cumsum(n_fibers)]).astype(np.int64)
        self.free_start = np.concatenate([[0], np.cumsum(3 * self.n_free)]).astype(np.int64)
        self.X = np.concatenate([net.nodes for net in self.networks])
        self.fibers = np.concatenate([net.fibers for net in self.networks])
        self.rest_length = np.concatenate([net.fiber_lengths() for net in self.networks])
        if np.any(self.rest_length <= 0):
            raise ValueError("RVEBatch: a network has a fiber of zero length")
        numbering: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # once per distinct network
        for net in self.networks:
            if id(net) not in numbering:
                numbering[id(net)] = interior_numbering(net)
        self.dof = np.concatenate([numbering[id(net)][0] for net in self.networks])
        self.first = np.concatenate([numbering[id(net)][1] for net in self.networks])
        batch = len(self.networks)
        self.positions = self.X.copy()
        self.F_state = np.tile(np.eye(3), (batch, 1, 1))
        self.sensitivity = np.zeros((self.free_start[-1], 9))
        self.has_state = np.zeros(batch, dtype=bool)

    def set_state(self, index: int, state: RVEState | None) -> None:
        n0, n1 = self.node_start[index], self.node_start[index + 1]
        s0, s1 = self.free_start[index], self.free_start[index + 1]
        if state is None:
            self.has_state[index] = False
            return
        if state.positions.shape != (n1 - n0, 3) or state.sensitivity.shape != (s1 - s0, 9):
            raise ValueError(f"RVEBatch: state {index} does not belong to this network")
        self.positions[n0:n1] = state.positions
        self.F_state[index] = state.F
        self.sensitivity[s0:s1] = state.sensitivity
        self.has_state[index] = True

    def get_state(self, index: int) -> RVEState:
        n0, n1 = self.node_start[index], self.node_start[index + 1]
        s0, s1 = self.free_start[index], self.free_start[index + 1]
        return RVEState(self.positions[n0:n1].copy(), self.F_state[index].copy(), self.sensitivity[s0:s1].copy())

    def solve(self, F: np.ndarray, update_state: bool = True) -> dict:
        """Solve every RVE at its F; returns arrays cauchy (B,3,3), tangent (B,3,3,3,3), ..."""
        F = _check_F(F, "RVEBatch.solve")
        batch = len(self.networks)
        if F.shape != (batch, 3, 3):
            raise ValueError(f"RVEBatch.solve: F must have shape ({batch}, 3, 3), got {F.shape}")
        x_previous, F_previous = self.positions.copy(), self.F_state.copy()
        sensitivity = self.sensitivity.copy()
        for r in np.flatnonzero(~self.has_state):  # cold start: affine guess
            n0, n1 = self.node_start[r], self.node_start[r + 1]
            x_previous[n0:n1] = self.X[n0:n1] @ F[r].T
            F_previous[r] = F[r]
            sensitivity[self.free_start[r] : self.free_start[r + 1]] = 0.0
        out = dict(
            x=np.empty_like(self.X),
            cauchy=np.zeros((batch, 3, 3)),
            tangent=np.zeros((batch, 3, 3, 3, 3)),
            stretch=np.empty(len(self.fibers)),
            status=np.empty(batch, dtype=np.int64),
            iterations=np.empty(batch, dtype=np.int64),
            residual=np.empty(batch),
        )
        if batch == 1:  # serial kernel: no parallel compilation for single solves
            m1 = self.fiber_start[1]
            workspace = kernels.workspace(3 * self.n_free[0], m1, self.node_start[1])
            out["status"][0], out["iterations"][0], out["residual"][0] = kernels.solve_one(
                *self._network_arrays(0),
                x_previous,
                F_previous[0],
                sensitivity,
                F[0],
                self.params,
                self.scale[0],
                self.tol,
                self.max_iter,
                out["x"],
                out["cauchy"][0],
                out["tangent"][0],
                out["stretch"][:m1],
                workspace,
            )
        else:
            kernels.solve_many(
                self.node_start,
                self.fiber_start,
                self.free_start,
                self.X,
                self.fibers,
                self.rest_length,
                self.dof,
                self.first,
                self.n_free,
                x_previous,
                F_previous,
                sensitivity,
                F,
                self.params,
                self.scale,
                self.tol,
                self.max_iter,
                out["x"],
                out["cauchy"],
                out["tangent"],
                out["stretch"],
                out["status"],
                out["iterations"],
                out["residual"],
                min(batch, CHUNKS_PER_THREAD * numba.get_num_threads()),
            )
        for r in np.flatnonzero(out["status"] != kernels.CONVERGED):
            self._substep(r, F[r], x_previous, F_previous, sensitivity, out)
        if update_state:
            self.positions[:] = out["x"]
            self.F_state[:] = F
            self.sensitivity[:] = sensitivity
            self.has_state[:] = True
        out["sensitivity"] = sensitivity
        return out

    def result(self, r: int, out: dict) -> RVEResult:
        """RVE ``r`` of the arrays returned by :meth:`solve`, with its current state."""
        n0, n1 = self.node_start[r], self.node_start[r + 1]
        m0, m1 = self.fiber_start[r], self.fiber_start[r + 1]
        return RVEResult(
            cauchy=out["cauchy"][r],
            tangent=out["tangent"][r],
            fiber_stretch=out["stretch"][m0:m1],
            state=self.get_state(r),
            deformed_nodes=out["x"][n0:n1],
            iterations=int(out["iterations"][r]),
            residual=float(out["residual"][r]),
            status=int(out["status"][r]),
            rve_edge_length=float(self.edge_length[r]),
        )

    def _network_arrays(self, r: int) -> tuple:
        n0, n1 = self.node_start[r], self.node_start[r + 1]
        m0, m1 = self.fiber_start[r], self.fiber_start[r + 1]
        s0, s1 = self.free_start[r], self.free_start[r + 1]
        return (
            self.X[n0:n1],
            self.fibers[m0:m1],
            self.rest_length[m0:m1],
            self.dof[n0:n1],
            self.first[s0:s1],
            self.n_free[r],
        )

    def _substep(self, r, F_target, x_previous, F_previous, sensitivity, out) -> None:
        """Retry a failed RVE from its start state in 2, 4, ..., 64 increments."""
        if out["status"][r] == kernels.INDEFINITE:
            warnings.warn(
                f"RVE {r}: equilibrium on an indefinite stiffness (unstable); tangent approximate",
                RuntimeWarning,
                stacklevel=3,
            )
            return
        n0, n1 = self.node_start[r], self.node_start[r + 1]
        m0, m1 = self.fiber_start[r], self.fiber_start[r + 1]
        s0, s1 = self.free_start[r], self.free_start[r + 1]
        args = self._network_arrays(r)
        workspace = kernels.workspace(s1 - s0, m1 - m0, n1 - n0)
        for n_steps in (2, 4, 8, 16, 32, 64):
            x_start = x_previous[n0:n1].copy()
            F_start = F_previous[r].copy()
            sens = np.zeros((s1 - s0, 9))
            x = np.empty_like(x_start)
            for step in range(1, n_steps + 1):
                F_step = F_start + (F_target - F_start) * step / n_steps
                status, iterations, residual = kernels.solve_one(
                    *args,
                    x_start,
                    F_start,
                    sens,
                    F_step,
                    self.params,
                    self.scale[r],
                    self.tol,
                    self.max_iter,
                    x,
                    out["cauchy"][r],
                    out["tangent"][r],
                    out["stretch"][m0:m1],
                    workspace,
                )
                if status not in (kernels.CONVERGED, kernels.INDEFINITE):
                    break
                x_start, F_start = x.copy(), F_step
            if status in (kernels.CONVERGED, kernels.INDEFINITE):
                out["x"][n0:n1] = x
                out["status"][r], out["iterations"][r], out["residual"][r] = status, iterations, residual
                sensitivity[s0:s1] = sens
                return
        raise RuntimeError(
            f"RVE {r}: force balance did not converge even in 64 increments "
            f"(relative residual {residual:.2e}, status {status})"
        )


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
