"""RVE batches: networks packed end to end for the parallel numba kernel, with their warm-start states.

The model (force balance, Eq. 8 stress, consistent tangent) is described in :mod:`skvalve.networks.rve`;
:class:`RVEBatch` is its form for many RVEs at once (the FE² coupling's): each RVE keeps a stored state
(positions, the F they belong to, dx/dF) from which the next solve is predicted to first order, or starts
from an earlier output of the batch where its F is nearer; RVEs whose F is unchanged are copied, not solved.
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

__all__ = ["RVEBatch", "RVEResult", "RVEState", "CHUNKS_PER_THREAD"]


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
        # every quantity of a network is computed once per distinct network (an FE² batch repeats each network
        # at all Gauss points of its element, and a sample draws its networks from a small library)
        distinct: dict[int, int] = {}
        self._source = np.array([distinct.setdefault(id(net), len(distinct)) for net in self.networks], dtype=np.int64)
        unique = list({id(net): net for net in self.networks}.values())
        scales = [_scale(net, fiber, psi, fiber_diameter) for net in unique]
        self.fiber, self.params = fiber, fiber.parameters()
        self.tol, self.max_iter = float(tol), int(max_iter)
        self.psi, self.fiber_diameter = psi, fiber_diameter
        lengths = [net.fiber_lengths() for net in unique]
        if any(np.any(length <= 0) for length in lengths):
            raise ValueError("RVEBatch: a network has a fiber of zero length")
        numbering = [interior_numbering(net) for net in unique]
        self._first_of = np.unique(self._source, return_index=True)[1]  # the first RVE of each distinct network
        source = self._source
        self.scale = np.array([s for s, _ in scales])[source]
        self.edge_length = np.array([g for _, g in scales])[source]
        n_nodes = np.array([net.n_nodes for net in unique])[source]
        n_fibers = np.array([net.n_fibers for net in unique])[source]
        self.n_free = np.array([int((~net.boundary).sum()) for net in unique])[source]
        self.node_start = np.concatenate([[0], np.cumsum(n_nodes)]).astype(np.int64)
        self.fiber_start = np.concatenate([[0], np.cumsum(n_fibers)]).astype(np.int64)
        self.free_start = np.concatenate([[0], np.cumsum(3 * self.n_free)]).astype(np.int64)
        self.X = np.concatenate([unique[d].nodes for d in source])
        self.fibers = np.concatenate([unique[d].fibers for d in source])
        self.rest_length = np.concatenate([lengths[d] for d in source])
        self.dof = np.concatenate([numbering[d][0] for d in source])
        self.first = np.concatenate([numbering[d][1] for d in source])
        batch = len(self.networks)
        self.positions = self.X.copy()
        self.F_state = np.tile(np.eye(3), (batch, 1, 1))
        self.sensitivity = np.zeros((self.free_start[-1], 9))
        self.has_state = np.zeros(batch, dtype=bool)
        self.accepted: dict | None = None  # the solve output the stored state came from (results for reuse)
        rves = np.arange(batch)
        self._node_rve = np.repeat(rves, n_nodes)  # the RVE of each packed node, fiber, sensitivity row
        self._fiber_rve = np.repeat(rves, n_fibers)
        self._free_rve = np.repeat(rves, 3 * self.n_free)

    def solve_uniform(self, F: np.ndarray) -> dict:
        """Every RVE at the same F from the affine guess (a batch without stored states), as :meth:`solve` returns.

        One RVE of each distinct network is solved and its results are copied to the others: the same network,
        F and start give the same numbers bit for bit.  The FE² material's reference state (F = I) is built so.
        """
        F = _check_F(F, "RVEBatch.solve_uniform")
        if F.shape != (3, 3):
            raise ValueError(f"RVEBatch.solve_uniform: F must have shape (3, 3), got {F.shape}")
        if self.has_state.any():
            raise ValueError("RVEBatch.solve_uniform: the RVEs have stored states (use solve)")
        firsts = self._first_of
        small = RVEBatch([self.networks[r] for r in firsts], self.fiber, self.psi, self.fiber_diameter, self.tol,
                         self.max_iter)
        out = small.solve(np.tile(F, (firsts.size, 1, 1)), update_state=False)
        source = self._source
        full = {name: out[name][source] for name in ("F", "cauchy", "tangent", "status", "iterations", "residual")}
        for name, start, small_start, owner in (("x", self.node_start, small.node_start, self._node_rve),
                                                ("stretch", self.fiber_start, small.fiber_start, self._fiber_rve),
                                                ("sensitivity", self.free_start, small.free_start, self._free_rve)):
            local = np.arange(start[-1]) - start[owner]
            full[name] = out[name][small_start[source[owner]] + local]
        full["solved"] = out["solved"]
        return full

    def set_state(self, index: int, state: RVEState | None) -> None:
        n0, n1 = self.node_start[index], self.node_start[index + 1]
        s0, s1 = self.free_start[index], self.free_start[index + 1]
        self.accepted = None  # the stored results no longer match the state
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

    def solve(self, F: np.ndarray, update_state: bool = True, alternate: dict | None = None,
              buffers: dict | None = None) -> dict:
        """Solve every RVE at its F; returns arrays cauchy (B,3,3), tangent (B,3,3,3,3), x, F, ...

        Each RVE starts from its stored state with the first-order predictor, or — when ``alternate``
        (an earlier output of this batch) is given — from whichever of the two lies nearer to the new F
        (largest entry of the F difference; a tie keeps the stored state).  An RVE whose F equals its
        start's F bit for bit and whose start has results (``alternate``, or the stored state after
        :meth:`accept`) is not solved again: its results are copied (``iterations`` 0), which is what a
        solve would return, since a converged state at the same F passes the convergence check at once.
        Where the start has results, F differs from the start's by at most √tol in every entry and the
        first-order predictor already satisfies the balance, the start's dσ/dF and dx/dF are kept
        (:func:`~skvalve.networks.rve_kernels.solve_one`: they differ from the new state's by O(√tol)
        relative) and only σ is computed.  ``buffers``: an earlier output no longer needed, whose packed
        arrays (x, sensitivity, stretch) are overwritten instead of allocating new ones.
        """
        F = _check_F(F, "RVEBatch.solve")
        batch = len(self.networks)
        if F.shape != (batch, 3, 3):
            raise ValueError(f"RVEBatch.solve: F must have shape ({batch}, 3, 3), got {F.shape}")
        use_alternate = np.zeros(batch, dtype=bool)
        F_start = self.F_state.copy()
        if alternate is not None:
            distance = np.abs(F - self.F_state).max(axis=(1, 2))
            use_alternate = ~self.has_state | (np.abs(F - alternate["F"]).max(axis=(1, 2)) < distance)
            F_start[use_alternate] = alternate["F"][use_alternate]
        cold = ~self.has_state & ~use_alternate
        F_start[cold] = np.eye(3)  # a failed cold start is retried from the reference state
        start = np.where(use_alternate, kernels.START_ALTERNATE, kernels.START_STATE)
        start[cold] = kernels.START_COLD
        known = use_alternate | (self.has_state & ~use_alternate & (self.accepted is not None))
        reuse = known & np.all(F == F_start, axis=(1, 2))
        # the start's tangent may be kept only for a step within √tol (a network whose predictor is exact,
        # e.g. one without interior cross-links, converges at once after any step)
        keep = known & ~reuse & (np.abs(F - F_start).max(axis=(1, 2)) <= math.sqrt(self.tol))
        out = self._outputs(F, buffers)
        for results, chosen in ((self.accepted, ~use_alternate), (alternate, use_alternate)):
            if results is not None:
                copied, kept = reuse & chosen, keep & chosen
                for name in ("cauchy", "tangent", "status", "residual"):
                    out[name][copied] = results[name][copied]
                out["tangent"][kept] = results["tangent"][kept]
        if reuse.any():
            source = alternate if alternate is not None else self.accepted
            stored = self.accepted if self.accepted is not None else source
            kernels.copy_rows(self.node_start, self.fiber_start, self.free_start, np.flatnonzero(reuse),
                              use_alternate, self.positions, source["x"], self.sensitivity, source["sensitivity"],
                              stored["stretch"], source["stretch"], out["x"], out["sensitivity"], out["stretch"])
        active = np.flatnonzero(~reuse)
        if active.size:
            self._solve_active(active, F, start, alternate, out, keep)
        for r in active[out["status"][active] != kernels.CONVERGED]:
            self._substep(r, F[r], self._start_positions(r, start[r], alternate), F_start[r], out)
        out["solved"] = int(active.size)
        if update_state:
            self.accept(out)
        return out

    def _outputs(self, F: np.ndarray, buffers: dict | None) -> dict:
        batch = len(self.networks)
        if buffers is None:
            buffers = dict(x=np.empty_like(self.X), sensitivity=np.empty_like(self.sensitivity),
                           stretch=np.empty(len(self.fibers)))
        return dict(
            x=buffers["x"],
            sensitivity=buffers["sensitivity"],
            stretch=buffers["stretch"],
            F=np.array(F, copy=True),
            cauchy=np.zeros((batch, 3, 3)),
            tangent=np.zeros((batch, 3, 3, 3, 3)),
            status=np.zeros(batch, dtype=np.int64),
            iterations=np.zeros(batch, dtype=np.int64),
            residual=np.zeros(batch),
        )

    def accept(self, out: dict) -> None:
        """Make the output of :meth:`solve` the stored state (its results are kept for reuse)."""
        self.positions = out["x"]
        self.F_state = np.array(out["F"], copy=True)
        self.sensitivity = out["sensitivity"]
        self.has_state[:] = True
        self.accepted = out

    def _start_positions(self, r: int, start: int, alternate: dict | None) -> np.ndarray:
        """Node positions RVE ``r`` starts from (its stored state, the alternate one, or the reference X)."""
        n0, n1 = self.node_start[r], self.node_start[r + 1]
        if start == kernels.START_COLD:
            return self.X[n0:n1].copy()
        return (alternate["x"] if start == kernels.START_ALTERNATE else self.positions)[n0:n1].copy()

    def _solve_active(self, active, F, start, alternate, out, keep_start) -> None:
        source = self if alternate is None else None
        x_alternate = self.positions if source is not None else alternate["x"]
        F_alternate = self.F_state if source is not None else alternate["F"]
        sensitivity_alternate = self.sensitivity if source is not None else alternate["sensitivity"]
        if active.size == 1:  # serial kernel: no parallel compilation for single solves
            r = int(active[0])
            n0, n1 = self.node_start[r], self.node_start[r + 1]
            m0, m1 = self.fiber_start[r], self.fiber_start[r + 1]
            s0, s1 = self.free_start[r], self.free_start[r + 1]
            from_alternate = start[r] == kernels.START_ALTERNATE
            workspace = kernels.workspace(3 * self.n_free[r], m1 - m0, n1 - n0)
            out["status"][r], out["iterations"][r], out["residual"][r] = kernels.solve_one(
                *self._network_arrays(r),
                (x_alternate if from_alternate else self.positions)[n0:n1],
                (F_alternate if from_alternate else self.F_state)[r],
                (sensitivity_alternate if from_alternate else self.sensitivity)[s0:s1],
                bool(start[r] == kernels.START_COLD),
                F[r],
                self.params,
                self.scale[r],
                self.tol,
                self.max_iter,
                out["x"][n0:n1],
                out["cauchy"][r],
                out["tangent"][r],
                out["stretch"][m0:m1],
                out["sensitivity"][s0:s1],
                workspace,
                bool(keep_start[r]),
            )
            return
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
            self.positions,
            self.F_state,
            self.sensitivity,
            x_alternate,
            F_alternate,
            sensitivity_alternate,
            start.astype(np.int64),
            F,
            self.params,
            self.scale,
            self.tol,
            self.max_iter,
            out["x"],
            out["sensitivity"],
            out["cauchy"],
            out["tangent"],
            out["stretch"],
            out["status"],
            out["iterations"],
            out["residual"],
            active.astype(np.int64),
            keep_start,
            min(active.size, CHUNKS_PER_THREAD * numba.get_num_threads()),
        )

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

    def _substep(self, r, F_target, x_first, F_first, out) -> None:
        """Retry a failed RVE from its start (positions ``x_first`` at ``F_first``) in 2, 4, ..., 64 increments."""
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
            x_start, F_start = x_first.copy(), F_first.copy()
            sens_start, sens = np.zeros((s1 - s0, 9)), np.zeros((s1 - s0, 9))
            x = np.empty_like(x_start)
            for step in range(1, n_steps + 1):
                F_step = F_start + (F_target - F_start) * step / n_steps
                status, iterations, residual = kernels.solve_one(
                    *args,
                    x_start,
                    F_start,
                    sens_start,
                    False,
                    F_step,
                    self.params,
                    self.scale[r],
                    self.tol,
                    self.max_iter,
                    x,
                    out["cauchy"][r],
                    out["tangent"][r],
                    out["stretch"][m0:m1],
                    sens,
                    workspace,
                    False,
                )
                if status not in (kernels.CONVERGED, kernels.INDEFINITE):
                    break
                x_start, F_start, sens_start, sens = x.copy(), F_step, sens, sens_start
            if status in (kernels.CONVERGED, kernels.INDEFINITE):
                out["x"][n0:n1] = x
                out["status"][r], out["iterations"][r], out["residual"][r] = status, iterations, residual
                out["sensitivity"][s0:s1] = sens_start
                return
        raise RuntimeError(
            f"RVE {r}: force balance did not converge even in 64 increments "
            f"(relative residual {residual:.2e}, status {status})"
        )
