r"""FE² quadrature-point material: neo-Hookean matrix plus a fiber-network RVE at every point.

Thomas et al. (2019) §2.4 add two Cauchy stresses at each Gauss point (assumption 1):

.. math::

    \sigma = \sigma^m(F) + \sigma^c(F),

the compressible neo-Hookean matrix of Eq. 10 (:class:`~skvalve.materials.NeoHookean`) and the
volume-averaged fiber stress of Eq. 8 from an RVE whose boundary cross-links follow
:math:`x = F X` (:class:`~skvalve.networks.RVEBatch`). The solver works with the first
Piola–Kirchhoff stress and its derivative, so the fiber part is converted with
:math:`P = J\sigma F^{-T}` and, with :math:`T_{ijkL} = \partial\sigma_{ij}/\partial F_{kL}` from the
RVE's implicit sensitivities,

.. math::

    \frac{\partial P_{iJ}}{\partial F_{kL}} = P_{iJ} F^{-1}_{Lk} + J\,T_{ijkL} F^{-1}_{Jj}
        - J\,\sigma_{ij} F^{-1}_{Jk} F^{-1}_{Lj}

(:func:`cauchy_to_pk1`; :math:`\partial J/\partial F = J F^{-T}`,
:math:`\partial F^{-1}_{Jj}/\partial F_{kL} = -F^{-1}_{Jk}F^{-1}_{Lj}`).

State. Each RVE keeps its committed state (node positions, the F they belong to and
:math:`\partial x/\partial F`). An evaluation starts each RVE with the first-order predictor from
the committed state or from the last evaluation since the commit, whichever has the nearer F: within
a Newton step the iterates approach each other, so after the step's first iterate the RVE solves
need one or two iterations instead of five to eight. An RVE whose F did not change is not solved
again (its results are copied): the residual Newton evaluates with the new prescribed values at the
old state re-solves only the elements next to the moved nodes. The stress is thus a function of
(committed state, last evaluation, F), equal to the converged RVE balance to its tolerance whatever
the start. :meth:`RVEMaterial.commit` accepts the state of the last evaluation (the converged one, in
a Newton solve); :meth:`RVEMaterial.rewind` discards it and the last evaluation, leaving the
committed arrays untouched bit for bit, so a retried step repeats the first attempt's numbers. The
reference state (F = I) is committed at construction, with its sensitivities (solved once per
distinct network), so the very first solve is already warm-started by the linear predictor.

Eq. 11 (the Chandran–Barocas averaging correction) is *not* part of the balance solved
here; :mod:`skvalve.multiscale.correction` estimates its size from converged RVEs.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..kinematics import as_tensor_field, determinant, inverse
from ..materials.exponential_fiber import ExponentialFiber
from ..materials.neo_hookean import NeoHookean
from ..networks.network import Network
from ..networks.rve import RVEBatch

__all__ = ["RVEMaterial", "RVEFailure", "RVEMaterialState", "cauchy_to_pk1"]


class RVEFailure(ValueError):
    """An RVE force balance failed; names the element and quadrature point (the solver cuts back)."""


@dataclass
class RVEMaterialState:
    """Committed RVE state of an :class:`RVEMaterial` (what a checkpoint stores).

    positions : (n_nodes_total, 3) packed node positions of all RVEs.
    F : (n_rves, 3, 3) deformation gradient of each RVE's committed state.
    sensitivity : (n_free_total, 9) dx_interior/dF of each RVE (the warm-start predictor).
    fiber_stretch : (n_fibers_total,) fiber stretches of the committed state.
    """

    positions: np.ndarray
    F: np.ndarray
    sensitivity: np.ndarray
    fiber_stretch: np.ndarray


def cauchy_to_pk1(F: np.ndarray, sigma: np.ndarray, dsigma_dF: np.ndarray | None):
    """P = J σ F⁻ᵀ and dP/dF from σ and dσ/dF (all batch-last: F (3,3,*b), dσ/dF (3,3,3,3,*b))."""
    J = determinant(F)
    F_inv = inverse(F)
    P = J * np.einsum("ij...,Jj...->iJ...", sigma, F_inv)
    if dsigma_dF is None:
        return P, None
    sigma_FinvT = np.einsum("ij...,Lj...->iL...", sigma, F_inv)
    A = np.einsum("iJ...,Lk...->iJkL...", P, F_inv)
    A += J * np.einsum("ijkL...,Jj...->iJkL...", dsigma_dF, F_inv)
    A -= J * np.einsum("iL...,Jk...->iJkL...", sigma_FinvT, F_inv)
    return P, A


def checked_inputs(owner: str, networks: Sequence[Network], matrix, n_points) -> list[Network]:
    """The networks as a list, after checking the matrix law, ``n_points`` and every network (named errors)."""
    if not isinstance(matrix, NeoHookean):
        raise TypeError(f"{owner}: matrix must be a NeoHookean (Eq. 10), got {type(matrix).__name__}")
    if isinstance(n_points, bool) or int(n_points) != n_points or n_points < 1:
        raise ValueError(f"{owner}: n_points must be a positive integer, got {n_points!r}")
    networks = list(networks)
    if not networks:
        raise ValueError(f"{owner}: no networks given (one per element is needed)")
    for e, net in enumerate(networks):
        if not isinstance(net, Network):
            raise TypeError(f"{owner}: networks[{e}] is a {type(net).__name__}, not a Network")
    return networks


class RVEMaterial:
    """Matrix (Eq. 10) plus fiber-network RVE (Eq. 8) at every quadrature point, evaluated in batch.

    Parameters
    ----------
    networks : one :class:`~skvalve.networks.Network` per element (in the element order of the
        region the material is used on); each of the element's ``n_points`` quadrature points gets
        its own RVE (own state) of that network.
    matrix : the non-collagenous matrix, :class:`~skvalve.materials.NeoHookean` (Eq. 10).
    fiber : the fiber force law, :class:`~skvalve.materials.ExponentialFiber` (Eq. 9).
    n_points : quadrature points per element (8 for trilinear hexahedra).
    psi, fiber_diameter : fiber volume fraction ψ and diameter (Eqs. 6–8).
    tol, max_iter : RVE force-balance tolerance and Newton iterations (see :class:`RVEBatch`).

    Notes
    -----
    The solver calls :meth:`pk1_and_tangent` with F of shape (3, 3, n_points, n_elements);
    RVE ``r = element * n_points + point``.

    Examples
    --------
    >>> material = RVEMaterial(networks, NeoHookean.from_shear_poisson(G, nu), fiber)  # doctest: +SKIP
    >>> P, A = material.pk1_and_tangent(F)          # F: (3, 3, 8, n_elements)  # doctest: +SKIP
    >>> material.commit()                           # after the load step converged  # doctest: +SKIP
    """

    incompressible = False

    def __init__(
        self,
        networks: Sequence[Network],
        matrix: NeoHookean,
        fiber: ExponentialFiber,
        n_points: int = 8,
        psi: float = 0.43,
        fiber_diameter: float | None = 450e-9,
        tol: float = 1e-10,
        max_iter: int = 30,
    ) -> None:
        networks = checked_inputs("RVEMaterial", networks, matrix, n_points)
        self.matrix, self.fiber = matrix, fiber
        self.psi, self.fiber_diameter, self.tol = psi, fiber_diameter, tol
        self.n_elements, self.n_points = len(networks), int(n_points)
        self.networks = networks
        per_point = [net for net in networks for _ in range(self.n_points)]
        self.batch = RVEBatch(per_point, fiber, psi, fiber_diameter, tol, max_iter)
        self.n_rves = len(per_point)
        self.solves = 0  # RVE solves performed (for throughput figures)
        self.reused = 0  # RVE results copied instead of solved (F unchanged since the start state)
        self.evaluations = 0  # batch evaluations (calls that solved or reused every RVE)
        self.solve_seconds = 0.0
        self.solve_cpu_seconds = 0.0  # CPU time of the process (all threads) during the RVE solves
        self._last: tuple[np.ndarray, dict] | None = None
        self._latest: dict | None = None  # the last evaluation since the commit: an alternative warm start
        self._spare: dict | None = None  # an evaluation no longer needed: its packed arrays are reused
        # commit the reference state with its sensitivities: the linear predictor for the first step
        out = self.batch.solve_uniform(np.eye(3))
        self._accept(out)

    # ------------------------------------------------------------------ evaluation
    def _rve_F(self, F: np.ndarray) -> np.ndarray:
        F = as_tensor_field(F)
        if F.shape[2:] != (self.n_points, self.n_elements):
            raise ValueError(
                f"RVEMaterial: F must have shape (3, 3, {self.n_points}, {self.n_elements}) "
                f"(quadrature points, elements), got {F.shape}"
            )
        return np.ascontiguousarray(F.transpose(3, 2, 0, 1).reshape(self.n_rves, 3, 3))

    def _solve(self, F: np.ndarray) -> dict:
        """RVE results at F (3,3,nqp,nel); cached for a repeated F.

        Each RVE starts from the committed state or from the last evaluation since the commit, whichever
        has the nearer F (:meth:`RVEBatch.solve`; within a Newton step the iterates approach each other,
        so the later RVE solves are short); an RVE whose F has not changed is not solved again.
        """
        if self._last is not None and np.array_equal(self._last[0], F):
            return self._last[1]
        F_rve = self._rve_F(F)
        det = np.linalg.det(F_rve)
        if not np.all(np.isfinite(F_rve)) or np.any(det <= 0.0):
            r = int(np.flatnonzero(~(det > 0.0))[0]) if np.any(~(det > 0.0)) else 0
            raise RVEFailure(
                f"RVEMaterial: det F <= 0 or F not finite at element {r // self.n_points}, point {r % self.n_points}"
            )
        start, cpu = time.perf_counter(), time.process_time()
        try:
            buffers, self._spare = self._spare, None
            out = self.batch.solve(F_rve, update_state=False, alternate=self._latest, buffers=buffers)
        except RuntimeError as err:
            raise RVEFailure(f"RVEMaterial: {self._where(err)}") from err
        self.solve_seconds += time.perf_counter() - start
        self.solve_cpu_seconds += time.process_time() - cpu
        self.solves += out["solved"]
        self.reused += self.n_rves - out["solved"]
        self.evaluations += 1
        self._last = (np.array(F, copy=True), out)
        previous, self._latest = self._latest, out
        self._recycle(previous)
        return out

    def _recycle(self, out: dict | None) -> None:
        """Keep the packed arrays of an evaluation that is neither committed nor the latest for the next one."""
        if out is not None and out is not self.batch.accepted and out is not self._latest:
            self._spare = out

    def _where(self, err: Exception) -> str:
        """Error text with the RVE index translated to element and quadrature point."""
        text = str(err)
        if text.startswith("RVE "):
            r = int(text.split()[1].rstrip(":"))
            return f"RVE of element {r // self.n_points}, quadrature point {r % self.n_points}: {text}"
        return text

    def _fiber_fields(self, out: dict, tangent: bool):
        """σ_fiber (3,3,nqp,nel) and dσ/dF (3,3,3,3,nqp,nel) from the RVE batch arrays."""
        shape = (self.n_elements, self.n_points)
        sigma = out["cauchy"].reshape(*shape, 3, 3).transpose(2, 3, 1, 0)
        if not tangent:
            return sigma, None
        return sigma, out["tangent"].reshape(*shape, 3, 3, 3, 3).transpose(2, 3, 4, 5, 1, 0)

    def fiber_cauchy(self, F: np.ndarray) -> np.ndarray:
        """Volume-averaged fiber Cauchy stress σ^c (Eq. 8), shape (3, 3, nqp, nel)."""
        return self._fiber_fields(self._solve(F), False)[0]

    def cauchy(self, F: np.ndarray) -> np.ndarray:
        """σ = σ^m (Eq. 10) + σ^c (Eq. 8), shape (3, 3, nqp, nel)."""
        sigma_fiber = self.fiber_cauchy(F)  # checks F first, naming element and point
        return self.matrix.cauchy(F) + sigma_fiber

    def pk1(self, F: np.ndarray) -> np.ndarray:
        """First Piola–Kirchhoff stress of matrix plus fibers, shape (3, 3, nqp, nel)."""
        F = as_tensor_field(F)
        sigma, _ = self._fiber_fields(self._solve(F), False)
        return self.matrix.pk1(F) + cauchy_to_pk1(F, sigma, None)[0]

    def pk1_and_tangent(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(P, dP/dF) of matrix plus fibers; dP/dF has shape (3, 3, 3, 3, nqp, nel)."""
        F = as_tensor_field(F)
        sigma, dsigma = self._fiber_fields(self._solve(F), True)
        P_fiber, A_fiber = cauchy_to_pk1(F, sigma, dsigma)
        P_matrix, A_matrix = self.matrix.pk1_and_tangent(F)
        return P_matrix + P_fiber, A_matrix + A_fiber

    # ------------------------------------------------------------------ state
    def _accept(self, out: dict) -> None:
        previous = self.batch.accepted
        self.batch.accept(out)
        self._stretch = out["stretch"]
        self._last = None
        self._latest = None
        self._recycle(previous)

    def commit(self) -> None:
        """Accept the RVE states of the last evaluation (call after a converged load step)."""
        if self._last is not None:
            self._accept(self._last[1])

    def rewind(self) -> None:
        """Forget every evaluation since the last commit (the committed arrays are not touched)."""
        latest, self._latest, self._last = self._latest, None, None
        self._recycle(latest)

    def state(self) -> RVEMaterialState:
        """Copy of the committed state (for checkpoints)."""
        b = self.batch
        return RVEMaterialState(b.positions.copy(), b.F_state.copy(), b.sensitivity.copy(), self._stretch.copy())

    def checkpoint_arrays(self) -> dict[str, np.ndarray]:
        """The committed state as named arrays (what :class:`skvalve.fem.HyperelasticTerm` checkpoints)."""
        return dict(vars(self.state()))

    def restore_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore arrays from :meth:`checkpoint_arrays` (same networks)."""
        self.set_state(RVEMaterialState(**arrays))

    def set_state(self, state: RVEMaterialState) -> None:
        """Restore a committed state saved by :meth:`state` (same networks)."""
        b = self.batch
        for name, new, old in (
            ("positions", state.positions, b.positions),
            ("F", state.F, b.F_state),
            ("sensitivity", state.sensitivity, b.sensitivity),
            ("fiber_stretch", state.fiber_stretch, self._stretch),
        ):
            if np.shape(new) != old.shape:
                raise ValueError(f"RVEMaterial.set_state: {name} has shape {np.shape(new)}, expected {old.shape}")
        b.positions = np.array(state.positions, dtype=float)
        b.F_state = np.array(state.F, dtype=float)
        b.sensitivity = np.array(state.sensitivity, dtype=float)
        b.has_state[:] = True
        b.accepted = None  # no results stored for a restored state: the first evaluation solves every RVE
        self._stretch = np.array(state.fiber_stretch, dtype=float)
        self._last = None
        self._latest = None

    # ------------------------------------------------------------------ per-RVE access (post-processing)
    def rve_index(self, element: int, point: int = 0) -> int:
        if not (0 <= element < self.n_elements and 0 <= point < self.n_points):
            raise IndexError(f"RVEMaterial: no RVE at element {element}, point {point}")
        return element * self.n_points + point

    def committed_nodes(self, element: int, point: int = 0) -> np.ndarray:
        """Deformed cross-link positions of one RVE in its committed state, (n_nodes, 3)."""
        r = self.rve_index(element, point)
        return self.batch.positions[self.batch.node_start[r] : self.batch.node_start[r + 1]].copy()

    def committed_fiber_stretch(self, element: int, point: int = 0) -> np.ndarray:
        """Fiber stretches λ_f of one RVE in its committed state."""
        r = self.rve_index(element, point)
        return self._stretch[self.batch.fiber_start[r] : self.batch.fiber_start[r + 1]].copy()
