"""FE² RVEs in-process (numba threads) against a 2-worker Dask LocalCluster on the same cores.

Runs thomas2019's equibiaxial protocol (1:1, 40 N/m, edge displacements tuned to the tensions) on the coarse
sample (8 × 8 × 1 hexes, 512 RVEs of ~450 fibers; ``--divisions`` to change) twice: with the in-process
:class:`~skvalve.multiscale.RVEMaterial` (``--threads`` numba threads, default all cores) and with
:class:`~skvalve.multiscale.distributed.DistributedRVEMaterial` on a LocalCluster of ``--workers`` processes of
one numba thread each (one chunk per worker). Prints both wall times, their ratio, the RVE-evaluation time per
macro Newton iteration of each and the difference, split into the slowest chunk's solve on its worker and
the Dask overhead (tasks, F out, σ and dσ/dF back), the cost of one evaluation of a 2-RVE material both ways
(the dispatch latency alone), and checks that the two final displacements agree. Last line
``fe2_distributed_ratio=<distributed wall / in-process wall>``.
"""

from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np
from distributed import Client, LocalCluster

from skvalve.multiscale.distributed import DistributedRVEMaterial
from skvalve.multiscale.material import RVEMaterial
from skvalve.papers.thomas2019.models import fe2_material
from skvalve.papers.thomas2019.protocols import run_protocol
from skvalve.papers.thomas2019.sample import build_sample


class EvaluationCounter:
    """Counts RVE batch evaluations (calls of the material's ``_solve`` that solved RVEs)."""

    def __init__(self, material) -> None:
        self.calls = 0
        solve = material._solve

        def counted(F):
            before = material.solves
            out = solve(F)
            self.calls += material.solves > before
            return out

        material._solve = counted


def timed_protocol(sample, material):
    counter = EvaluationCounter(material)
    start = time.perf_counter()
    run = run_protocol(sample, material, (1.0, 1.0))
    return run, time.perf_counter() - start, counter.calls


def dispatch_latency(sample, client, repeats: int = 20) -> tuple[float, float]:
    """Seconds per evaluation of a 2-RVE material, in-process and on the workers (pure dispatch cost)."""
    reference = fe2_material(sample)
    settings = dict(n_points=1, psi=reference.psi, fiber_diameter=reference.fiber_diameter)
    local = RVEMaterial(sample.networks[:2], reference.matrix, reference.fiber, **settings)
    remote = DistributedRVEMaterial(sample.networks[:2], reference.matrix, reference.fiber, client, numba_threads=1,
                                    **settings)
    F = [np.broadcast_to(np.diag([1.0 + 1e-3 * k, 1.0, 1.0])[:, :, None, None], (3, 3, 1, 2)).copy() for k in (1, 2)]
    seconds = []
    for material in (local, remote):
        material.pk1_and_tangent(F[1])
        start = time.perf_counter()
        for k in range(repeats):
            material.pk1_and_tangent(F[k % 2])  # alternate: no cached result
        seconds.append((time.perf_counter() - start) / repeats)
    return seconds[0], seconds[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", type=int, nargs=3, default=(8, 8, 1))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--threads", type=int, default=len(os.sched_getaffinity(0)), help="in-process numba threads")
    args = parser.parse_args()
    numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))
    sample = build_sample(tuple(args.divisions))
    print(f"sample {args.divisions}: {sample.n_elements} elements, cores {len(os.sched_getaffinity(0))}")

    local = fe2_material(sample)
    run_local, wall_local, calls_local = timed_protocol(sample, local)
    print(f"in-process ({numba.get_num_threads()} numba threads): wall {wall_local:.1f} s, "
          f"{run_local.iterations} macro iterations, {calls_local} RVE batch evaluations of {local.n_rves} RVEs, "
          f"RVE time {local.solve_seconds:.1f} s")

    cluster_options = dict(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=":0")
    with LocalCluster(**cluster_options) as cluster, Client(cluster) as client:
        # first: the latency check, which also loads the compiled kernels on the workers (as fe2_material did here)
        latency_local, latency_remote = dispatch_latency(sample, client)
        start = time.perf_counter()
        remote = DistributedRVEMaterial.from_material(fe2_material(sample), client, numba_threads=1)
        setup = time.perf_counter() - start
        run_remote, wall_remote, calls_remote = timed_protocol(sample, remote)
        print(f"LocalCluster ({args.workers} workers x 1 numba thread, chunks of "
              f"{np.diff(remote.rve_bounds).max()} RVEs): wall {wall_remote:.1f} s (+ set-up {setup:.1f} s), "
              f"{run_remote.iterations} macro iterations, {calls_remote} RVE batch evaluations, "
              f"RVE time {remote.solve_seconds:.1f} s")
        difference = np.abs(run_remote.u - run_local.u).max() / np.abs(run_local.u).max()
        print(f"final displacement, max relative difference distributed vs in-process: {difference:.1e}")
        print(f"one evaluation of 2 RVEs (dispatch cost): in-process {latency_local * 1e3:.1f} ms, "
              f"distributed {latency_remote * 1e3:.1f} ms")

    per_local = local.solve_seconds / max(calls_local, 1)
    per_remote = remote.solve_seconds / max(calls_remote, 1)
    on_workers = remote.worker_seconds / max(calls_remote, 1)
    print(f"RVE evaluation per macro Newton iteration: in-process {per_local * 1e3:.0f} ms, distributed "
          f"{per_remote * 1e3:.0f} ms (difference {(per_remote - per_local) * 1e3:+.0f} ms), of which the slowest "
          f"chunk's solve on its worker {on_workers * 1e3:.0f} ms and Dask overhead (tasks, F out, stresses and "
          f"tangents back) {(per_remote - on_workers) * 1e3:.0f} ms")
    print(f"fe2_distributed_ratio={wall_remote / wall_local:.3f}")


if __name__ == "__main__":
    main()
