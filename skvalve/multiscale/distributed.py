r"""FE² RVEs evaluated on Dask distributed workers, with every RVE state resident on its worker.

:class:`DistributedRVEMaterial` is the quadrature-point material of :class:`~skvalve.multiscale.RVEMaterial`
(σ = σ^m (Eq. 10) + σ^c (Eq. 8) of Thomas et al. 2019 and dP/dF) with the fiber-network solves farmed out to
the workers of a user-supplied ``distributed.Client``. The in-process :class:`RVEMaterial` (numba threads) stays
the default; this module does not import Dask — it only calls the client it is given.

Layout. The elements are cut into ``chunks`` contiguous ranges (default: one per worker), each holding
``n_points`` RVEs per element — thousands of RVEs per task at the paper's scale, never one task per RVE.
Chunk ``c`` is owned by worker ``c mod n_workers``: its :class:`~skvalve.networks.RVEBatch` is built there
once and every task touching the chunk is pinned to that worker (``workers=[owner]``,
``allow_other_workers=False``), so the batch and the RVE states never travel.

State, as futures. Each chunk has a *committed* state future (positions, F, dx/dF, fiber stretches) living on
its worker. An evaluation at F submits, per chunk, ``solve(batch, committed, F_chunk, latest)`` → a *trial*
future on the same worker (the new state plus σ and dσ/dF) and gathers only σ and dσ/dF of every RVE
(9 + 81 numbers per RVE). As in-process, each RVE starts from the committed state or from the previous trial
(``latest``, on the same worker), whichever has the nearer F, and an RVE whose F is unchanged is copied, not
solved. :meth:`commit` makes the trial futures the committed ones (nothing moves; the worker keeps the trial's
arrays); :meth:`rewind` releases them and the workers drop them. Tasks never mutate their inputs, so a stress is
a function of (committed state, previous trial, F) exactly as in-process, and the results equal the in-process
material's bit for bit (each RVE is solved by the same kernel from the same data).
No actors are used: a future's data stays on its worker until the client releases it.

Running on a cluster (see ``docs/thomas2019_distributed.md``)::

    from distributed import Client, LocalCluster
    client = Client(LocalCluster(n_workers=2, threads_per_worker=1, processes=True))
    material = DistributedRVEMaterial.from_material(fe2_material(sample), client, numba_threads=1)
    run_protocol(sample, material, (1.0, 1.0))

With dask-jobqueue (SLURM) use ``SLURMCluster(cores=..., processes=1, memory=...)`` and
``cluster.scale(jobs=n)``; with dask-mpi call ``dask_mpi.initialize()`` and ``Client()`` in a script started
by ``mpirun``. One worker process per node with all of its cores as numba threads (``threads_per_worker=1``,
numba's default thread count) is the efficient layout: the chunk's solve is already multithreaded. Workers
sharing a machine split its cores with ``numba_threads``.

If a worker is lost its RVE states are lost with it; :meth:`state` (e.g. the checkpoint of every converged
load step) and :meth:`set_state` restart the run. Post-processing that needs the packed arrays of an
in-process batch (:mod:`skvalve.multiscale.correction`) takes an :class:`RVEMaterial` given
``material.set_state(distributed.state())``.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np

from ..materials.exponential_fiber import ExponentialFiber
from ..materials.neo_hookean import NeoHookean
from ..networks.network import Network
from ..networks.rve import RVEBatch
from .material import RVEFailure, RVEMaterial, RVEMaterialState, checked_inputs

if TYPE_CHECKING:  # only for the annotation: the module runs on whatever client it is handed
    from distributed import Client, Future

__all__ = ["DistributedRVEMaterial", "ChunkState", "ChunkTrial"]


@dataclass
class ChunkState:
    """Committed state of one chunk of RVEs (the per-chunk slice of :class:`RVEMaterialState`)."""

    positions: np.ndarray
    F: np.ndarray
    sensitivity: np.ndarray
    fiber_stretch: np.ndarray


@dataclass
class ChunkTrial:
    """Result of one chunk's solve at a trial F: the state it would commit plus σ^c and dσ^c/dF per RVE."""

    state: ChunkState
    cauchy: np.ndarray  # (n, 3, 3)
    tangent: np.ndarray  # (n, 3, 3, 3, 3)
    seconds: float = 0.0  # the solve's wall time on the worker
    results: dict | None = None  # the batch output (RVEBatch.solve): warm start and reuse of unchanged RVEs


@dataclass(frozen=True)
class _ChunkInput:
    """What a worker needs to build its chunk's batch (sent once; one object, not a list to scatter)."""

    networks: list[Network]  # one per RVE of the chunk
    fiber: ExponentialFiber
    psi: float
    fiber_diameter: float | None
    tol: float
    max_iter: int
    first_rve: int  # global index of the chunk's first RVE (for error messages)
    n_points: int
    numba_threads: int | None  # numba threads of the worker's solves (None: numba's default)


# ---------------------------------------------------------------------- worker-side functions
def _build_batch(spec: _ChunkInput) -> tuple[RVEBatch, _ChunkInput]:
    batch = RVEBatch(spec.networks, spec.fiber, spec.psi, spec.fiber_diameter, spec.tol, spec.max_iter)
    return batch, spec


def _solve_chunk(built: tuple[RVEBatch, _ChunkInput], committed: ChunkTrial | None, F: np.ndarray,
                 latest: ChunkTrial | None = None) -> ChunkTrial:
    """Solve the chunk's RVEs at F from ``committed.state`` (None: cold, the reference solve) or, RVE by RVE, from
    the ``latest`` trial where its F is nearer (as the in-process material does); inputs not mutated."""
    resident, spec = built
    if spec.numba_threads is not None:  # per calling thread in numba: set in the task itself
        numba.set_num_threads(min(spec.numba_threads, numba.config.NUMBA_NUM_THREADS))
    batch = copy.copy(resident)  # shallow: the state arrays are rebound below, never written in place
    if committed is not None:
        state = committed.state
        batch.positions, batch.F_state, batch.sensitivity = state.positions, state.F, state.sensitivity
        batch.has_state = np.ones(len(batch.networks), dtype=bool)
        batch.accepted = committed.results
    else:
        batch.has_state = np.zeros(len(batch.networks), dtype=bool)
        batch.accepted = None
    start = time.perf_counter()
    try:
        out = batch.solve(F, update_state=False, alternate=None if latest is None else latest.results)
    except RuntimeError as err:
        text = str(err)
        if not text.startswith("RVE "):  # not a force-balance failure (e.g. numba): no cut-back can help
            raise
        r = spec.first_rve + int(text.split()[1].rstrip(":"))
        where = f"RVE of element {r // spec.n_points}, quadrature point {r % spec.n_points}"
        raise RVEFailure(f"DistributedRVEMaterial: {where}: {text}") from err
    state = ChunkState(out["x"], np.array(F, copy=True), out["sensitivity"], out["stretch"])
    return ChunkTrial(state, out["cauchy"], out["tangent"], time.perf_counter() - start, out)


def _stresses(trial: ChunkTrial) -> tuple[np.ndarray, np.ndarray, float, int]:
    return trial.cauchy, trial.tangent, trial.seconds, trial.results["solved"]


def _state_of(trial: ChunkTrial) -> ChunkState:
    return trial.state


def _size(trial: ChunkTrial) -> int:
    return len(trial.cauchy)


def _one_rve(built: tuple[RVEBatch, _ChunkInput], trial: ChunkTrial, local: int) -> tuple[np.ndarray, np.ndarray]:
    """Committed node positions and fiber stretches of the chunk's RVE ``local``."""
    batch = built[0]
    n0, n1 = batch.node_start[local], batch.node_start[local + 1]
    m0, m1 = batch.fiber_start[local], batch.fiber_start[local + 1]
    return trial.state.positions[n0:n1].copy(), trial.state.fiber_stretch[m0:m1].copy()


# ---------------------------------------------------------------------- driver side
class DistributedRVEMaterial(RVEMaterial):
    """:class:`RVEMaterial` whose RVEs live and are solved on the workers of a Dask ``Client``.

    Parameters
    ----------
    networks, matrix, fiber, n_points, psi, fiber_diameter, tol, max_iter
        As :class:`RVEMaterial`; the fiber volume fraction ψ and the fiber diameter have no defaults here
        (pass the model's values).
    client : distributed.Client
        A connected client (LocalCluster, dask-jobqueue, dask-mpi, ...).
    chunks : int, optional
        Number of contiguous element ranges (tasks per evaluation); default one per worker.
    numba_threads : int, optional
        Numba threads of each chunk's solve on its worker (at most the worker's ``NUMBA_NUM_THREADS``);
        default numba's (all cores of the worker's machine).
    state : RVEMaterialState, optional
        A committed state to start from; default the reference state F = I, solved on the workers.

    Notes
    -----
    Same interface as :class:`RVEMaterial`: ``pk1``, ``pk1_and_tangent``, ``cauchy``, ``fiber_cauchy``,
    ``commit``, ``rewind``, ``state``, ``set_state``, ``committed_nodes``, ``committed_fiber_stretch``.
    ``worker_seconds`` sums, over the evaluations, the slowest chunk's solve time on its worker
    (``solve_seconds`` minus it is the Dask overhead).
    """

    def __init__(
        self,
        networks: Sequence[Network],
        matrix: NeoHookean,
        fiber: ExponentialFiber,
        client: Client,
        *,
        n_points: int,
        psi: float,
        fiber_diameter: float | None,
        tol: float = 1e-10,
        max_iter: int = 30,
        chunks: int | None = None,
        numba_threads: int | None = None,
        state: RVEMaterialState | None = None,
    ) -> None:
        # RVEMaterial.__init__ is not called: it would build and solve every RVE in this process
        networks = checked_inputs("DistributedRVEMaterial", networks, matrix, n_points)
        workers = sorted(client.nthreads())
        if not workers:
            raise ValueError("DistributedRVEMaterial: the client has no workers")
        n_chunks = len(workers) if chunks is None else chunks
        if isinstance(n_chunks, bool) or int(n_chunks) != n_chunks or not 1 <= n_chunks <= len(networks):
            raise ValueError(f"DistributedRVEMaterial: chunks must be an integer in 1..{len(networks)} "
                             f"(number of elements), got {chunks!r}")
        if numba_threads is not None and (isinstance(numba_threads, bool) or int(numba_threads) != numba_threads
                                          or numba_threads < 1):
            raise ValueError(f"DistributedRVEMaterial: numba_threads must be a positive integer, got {numba_threads!r}")
        self.matrix, self.fiber = matrix, fiber
        self.psi, self.fiber_diameter, self.tol, self.max_iter = psi, fiber_diameter, tol, int(max_iter)
        self.n_elements, self.n_points = len(networks), int(n_points)
        self.networks = networks
        self.n_rves = self.n_elements * self.n_points
        self.solves, self.reused, self.evaluations, self.solve_seconds = 0, 0, 0, 0.0
        self.worker_seconds = 0.0  # per evaluation the slowest chunk's solve time on its worker, summed
        self.client = client
        element_bounds = np.linspace(0, self.n_elements, int(n_chunks) + 1).round().astype(int)
        self.rve_bounds = element_bounds * self.n_points  # chunk c holds RVEs rve_bounds[c]:rve_bounds[c + 1]
        self.owners = [workers[c % len(workers)] for c in range(int(n_chunks))]
        self._offsets = self._packed_offsets()
        self._batches: list[Future] = []
        for c, (e0, e1) in enumerate(zip(element_bounds[:-1], element_bounds[1:], strict=True)):
            per_point = [net for net in networks[e0:e1] for _ in range(self.n_points)]
            spec = _ChunkInput(per_point, fiber, psi, fiber_diameter, tol, self.max_iter, int(self.rve_bounds[c]),
                               self.n_points, numba_threads)
            [spec_future] = client.scatter([spec], workers=[self.owners[c]], broadcast=False)
            self._batches.append(self._submit(c, _build_batch, spec_future))
        self._committed: list[Future] = []
        self._trial: tuple[np.ndarray, list[Future], dict] | None = None
        if state is None:
            reference = np.tile(np.eye(3), (self.n_rves, 1, 1))
            self._committed = [self._submit(c, _solve_chunk, self._batches[c], None, reference[s])
                               for c, s in enumerate(self._slices())]
            # wait (and surface a failure) here, without moving the states
            self.client.gather([self._submit(c, _size, f) for c, f in enumerate(self._committed)])
        else:
            self.set_state(state)

    @classmethod
    def from_material(cls, material: RVEMaterial, client: Client, chunks: int | None = None,
                      numba_threads: int | None = None) -> DistributedRVEMaterial:
        """The same model as ``material`` (settings and committed state), evaluated on ``client``'s workers."""
        if isinstance(material, DistributedRVEMaterial):
            raise TypeError("DistributedRVEMaterial.from_material: the material is already distributed")
        return cls(material.networks, material.matrix, material.fiber, client, n_points=material.n_points,
                   psi=material.psi, fiber_diameter=material.fiber_diameter, tol=material.tol,
                   max_iter=material.batch.max_iter, chunks=chunks, numba_threads=numba_threads,
                   state=material.state())

    @property
    def batch(self) -> RVEBatch:
        raise AttributeError(
            "DistributedRVEMaterial keeps its RVE batches on the Dask workers; for post-processing on packed "
            "arrays copy the state into an in-process RVEMaterial: local.set_state(distributed.state())"
        )

    # ------------------------------------------------------------------ helpers
    def _submit(self, c: int, function, *args) -> Future:
        return self.client.submit(function, *args, workers=[self.owners[c]], allow_other_workers=False, pure=False)

    def _slices(self) -> list[slice]:
        return [slice(int(a), int(b)) for a, b in zip(self.rve_bounds[:-1], self.rve_bounds[1:], strict=True)]

    def _packed_offsets(self) -> dict[str, np.ndarray]:
        """Start of each chunk in the packed node, free-dof and fiber arrays (the order RVEBatch packs them)."""
        per_element = {
            "positions": np.array([net.n_nodes for net in self.networks]),
            "sensitivity": np.array([3 * int((~net.boundary).sum()) for net in self.networks]),
            "fiber_stretch": np.array([net.n_fibers for net in self.networks]),
        }
        elements = self.rve_bounds // self.n_points
        return {name: self.n_points * np.concatenate([[0], np.cumsum(n)])[elements] for name, n in per_element.items()}

    # ------------------------------------------------------------------ evaluation
    def _solve(self, F: np.ndarray) -> dict:
        """σ^c and dσ^c/dF of every RVE at F (3,3,nqp,nel) from the committed states; cached for a repeated F."""
        if self._trial is not None and np.array_equal(self._trial[0], F):
            return self._trial[2]
        F_rve = self._rve_F(F)
        det = np.linalg.det(F_rve)
        if not np.all(np.isfinite(F_rve)) or np.any(~(det > 0.0)):
            r = int(np.flatnonzero(~(det > 0.0))[0]) if np.any(~(det > 0.0)) else 0
            raise RVEFailure(f"DistributedRVEMaterial: det F <= 0 or F not finite at element {r // self.n_points}, "
                             f"point {r % self.n_points}")
        latest = None if self._trial is None else self._trial[1]
        self._trial = None  # release the previous trial's stresses before the new one is computed
        start = time.perf_counter()
        trials = [self._submit(c, _solve_chunk, self._batches[c], self._committed[c], F_rve[s],
                               None if latest is None else latest[c])
                  for c, s in enumerate(self._slices())]
        del latest
        parts = self.client.gather([self._submit(c, _stresses, trial) for c, trial in enumerate(trials)])
        self.solve_seconds += time.perf_counter() - start
        self.worker_seconds += max(p[2] for p in parts)
        solved = sum(p[3] for p in parts)
        self.solves += solved
        self.reused += self.n_rves - solved
        self.evaluations += 1
        out = {"cauchy": np.concatenate([p[0] for p in parts]), "tangent": np.concatenate([p[1] for p in parts])}
        self._trial = (np.array(F, copy=True), trials, out)
        return out

    # ------------------------------------------------------------------ state
    def commit(self) -> None:
        """Accept the last evaluation: its trial futures become the committed states (on the same workers)."""
        if self._trial is not None:
            self._committed = self._trial[1]
            self._trial = None

    def rewind(self) -> None:
        """Forget every evaluation since the last commit; the workers drop the trial states."""
        self._trial = None

    def state(self) -> RVEMaterialState:
        """The committed state gathered from the workers, packed as :meth:`RVEMaterial.state`."""
        parts = self.client.gather([self._submit(c, _state_of, f) for c, f in enumerate(self._committed)])
        return RVEMaterialState(*(np.concatenate([getattr(p, name) for p in parts])
                                  for name in ("positions", "F", "sensitivity", "fiber_stretch")))

    def set_state(self, state: RVEMaterialState) -> None:
        """Send a committed state (from :meth:`state` or :meth:`RVEMaterial.state`) to the chunks' workers."""
        arrays = {"positions": np.asarray(state.positions, dtype=float), "F": np.asarray(state.F, dtype=float),
                  "sensitivity": np.asarray(state.sensitivity, dtype=float),
                  "fiber_stretch": np.asarray(state.fiber_stretch, dtype=float)}
        offsets = dict(self._offsets, F=self.rve_bounds)
        widths = {"positions": (3,), "F": (3, 3), "sensitivity": (9,), "fiber_stretch": ()}
        for name, value in arrays.items():
            expected = (int(offsets[name][-1]), *widths[name])
            if value.shape != expected:
                raise ValueError(f"DistributedRVEMaterial.set_state: {name} has shape {value.shape}, "
                                 f"expected {expected}")
        committed = []
        for c in range(len(self.owners)):
            part = ChunkState(*(arrays[name][offsets[name][c] : offsets[name][c + 1]].copy()
                                for name in ("positions", "F", "sensitivity", "fiber_stretch")))
            [future] = self.client.scatter([ChunkTrial(part, np.empty(0), np.empty(0))], workers=[self.owners[c]],
                                           broadcast=False, hash=False)
            committed.append(future)
        self._committed, self._trial = committed, None

    # ------------------------------------------------------------------ per-RVE access (post-processing)
    def _committed_rve(self, element: int, point: int) -> tuple[np.ndarray, np.ndarray]:
        r = self.rve_index(element, point)
        c = int(np.searchsorted(self.rve_bounds, r, side="right")) - 1
        return self._submit(c, _one_rve, self._batches[c], self._committed[c], r - int(self.rve_bounds[c])).result()

    def committed_nodes(self, element: int, point: int = 0) -> np.ndarray:
        """Deformed cross-link positions of one RVE in its committed state, (n_nodes, 3) (fetched from its worker)."""
        return self._committed_rve(element, point)[0]

    def committed_fiber_stretch(self, element: int, point: int = 0) -> np.ndarray:
        """Fiber stretches λ_f of one RVE in its committed state (fetched from its worker)."""
        return self._committed_rve(element, point)[1]

    def close(self) -> None:
        """Release every future of this material (the workers free the batches and states)."""
        self._batches, self._committed, self._trial = [], [], None
