"""Warm-started RVE solves per core-second (Thomas 2019 microscale; issue 13 item 3).

B networks of ~450 fibers (α = 41 %, several seeds) are equilibrated at an equibiaxial
stretch F0; then each is re-solved, warm-started, at F0 + ΔF (a small load increment of
0.2 % stretch plus a little shear, as one macro Newton iteration would request) — Newton to
1e-10 relative residual, stress and consistent tangent included.  Timed with 1 thread and with
2 numba threads, as solves per CPU-second of the process (all threads; the per-core figure, robust
on a shared machine) and per wall-second and thread (what a user waits for).  Parallel efficiency is
the 2-thread figure over the 1-thread one.

Before/after in the same run: ``--reference REV`` (default ``DEFAULT_REFERENCE``, the last
revision with the dense-Cholesky kernels) extracts that
revision's ``skvalve`` package with ``git archive`` into a temporary folder and runs the same
measurement on it in a subprocess, then on the working tree; the stresses and tangents of the
two are compared.  A breakdown times the kernel parts of the current code on one RVE.
The machine may be shared: the 1-minute load average is printed with every figure.

Last line: ``rve_solves_per_core_second=<single-thread solves per second>``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
# the last revision with the dense-Cholesky RVE kernels (before issue 13 item 3)
DEFAULT_REFERENCE = "ea7883b"
THOMAS_FIBER = dict(E_f=10.5e3, diameter=450e-9, beta=50.5, lambda_c=1.12)  # thomas2019 values,
PSI = 0.43  # passed explicitly so that the reference revision and the working tree get the same


def load() -> float:
    return os.getloadavg()[0]


def build(rves: int, n_networks: int):
    """(batch, F1) for the current ``skvalve`` on sys.path; the batch is at F0 (warm states)."""
    from skvalve.materials.exponential_fiber import ExponentialFiber
    from skvalve.networks.generate import generate
    from skvalve.networks.rve import RVEBatch

    p = THOMAS_FIBER
    fiber = ExponentialFiber.from_diameter(p["E_f"], p["diameter"], p["beta"], p["lambda_c"])
    library = [generate(41.0, 0.0, n_fibers=450, seed=s) for s in range(n_networks)]
    networks = [library[i % len(library)] for i in range(rves)]
    batch = RVEBatch(networks, fiber, psi=PSI, fiber_diameter=p["diameter"])
    F0 = np.tile(np.diag([1.10, 1.10, 1 / 1.21]), (rves, 1, 1))
    batch.solve(F0)  # converged reference states
    increment = np.array([[2e-3, 5e-4, 0.0], [0.0, 2e-3, 0.0], [0.0, 0.0, -4e-3]])
    return batch, F0 + increment


def timed_solves(batch, F: np.ndarray, repeats: int) -> tuple[float, float]:
    """Best of ``repeats`` (wall seconds, CPU seconds of all threads) of one batch solve.

    On a shared machine the wall time includes waiting for the CPU; the process CPU time does
    not, so solves per CPU-second is the per-core figure and the one compared across threads.
    """
    batch.solve(F, update_state=False)  # warm-up (compilation, caches)
    best_wall = best_cpu = np.inf
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        out = batch.solve(F, update_state=False)
        best_wall = min(best_wall, time.perf_counter() - wall)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    assert np.all(out["status"] == 0)
    return best_wall, best_cpu


def worker(args) -> None:
    """Measure the ``skvalve`` found on sys.path; write figures and results to ``args.worker``."""
    import numba

    batch, F1 = build(args.rves, args.networks)
    out = batch.solve(F1, update_state=False)
    figures = {"iterations": float(out["iterations"].mean()), "fibers": float(np.diff(batch.fiber_start).mean())}
    figures["interior_dofs"] = float(3 * batch.n_free.mean())
    for threads in (1, 2):
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        before = load()
        wall, cpu = timed_solves(batch, F1, args.repeats)
        figures[f"cpu{threads}"] = args.rves / cpu  # solves per CPU-second (all threads)
        figures[f"wall{threads}"] = args.rves / wall / threads  # solves per wall-second per thread
        figures[f"load{threads}"] = max(before, load())
    figures["threading_layer"] = numba.threading_layer()
    np.savez(args.worker, cauchy=out["cauchy"], tangent=out["tangent"], figures=json.dumps(figures))


def run_worker(pythonpath: Path, args) -> tuple[dict, np.ndarray, np.ndarray]:
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "result.npz"
        env = dict(os.environ, PYTHONPATH=str(pythonpath), NUMBA_NUM_THREADS="2")
        command = [sys.executable, __file__, "--worker", str(result), "--rves", str(args.rves)]
        command += ["--networks", str(args.networks), "--repeats", str(args.repeats)]
        subprocess.run(command, env=env, check=True, cwd=tmp)
        with np.load(result) as data:
            return json.loads(str(data["figures"])), data["cauchy"], data["tangent"]


def extract(revision: str, folder: Path) -> None:
    """``skvalve`` of ``revision`` into ``folder`` (git archive; nothing in the work tree changes)."""
    archive = subprocess.run(
        ["git", "archive", "--format=tar", revision, "skvalve"], cwd=ROOT, check=True, capture_output=True
    ).stdout
    with tarfile.open(fileobj=BytesIO(archive)) as tar:
        tar.extractall(folder, filter="data")


def breakdown(batch, F: np.ndarray, repeats: int = 300) -> dict:
    """Seconds per call of the kernel parts of the current code on RVE 0."""
    from skvalve.networks import rve_kernels as kernels
    from skvalve.networks.dense_cholesky import cholesky_in_place

    X, fibers, rest, dof, first, n_free = batch._network_arrays(0)
    n0, n1 = batch.node_start[0], batch.node_start[1]
    x = batch.positions[n0:n1].copy()
    n = 3 * n_free
    ws = kernels.workspace(n, len(fibers), len(X))
    residual, matrix, work = ws[0], ws[2].reshape((n, n)), ws[3].reshape((n, n))
    sens = batch.sensitivity[batch.free_start[0] : batch.free_start[1]].copy()
    cauchy, tangent, stretch = np.empty((3, 3)), np.empty((3, 3, 3, 3)), np.empty(len(fibers))
    kernels.assemble(x, fibers, rest, dof, first, batch.params, residual, matrix, ws[6], True, False)
    parts = {
        "assemble residual+K": lambda: kernels.assemble(
            x, fibers, rest, dof, first, batch.params, residual, matrix, ws[6], True, False
        ),
        "Cholesky (envelope)": lambda: (work.__setitem__(slice(None), matrix), cholesky_in_place(work, n, first)),
        "9 sensitivity solves": lambda: kernels._sensitivities(X, x, fibers, dof, first, n_free, work, ws[6], sens),
        "stress + tangent": lambda: kernels.stress_and_tangent(
            X, x, fibers, rest, dof, F[0], batch.scale[0], sens, ws[6], ws[7][:n_free], cauchy, tangent, stretch
        ),
    }
    times = {}
    for name, fn in parts.items():
        fn()
        best = np.inf
        for _ in range(5):
            start = time.thread_time()
            for _ in range(repeats):
                fn()
            best = min(best, (time.thread_time() - start) / repeats)
        times[name] = best
    return times


def report(label: str, figures: dict) -> None:
    print(
        f"{label:12s}: 1 thread {figures['cpu1']:6.0f} solves/CPU-s ({figures['wall1']:6.0f}/wall-s, load "
        f"{figures['load1']:.2f}); 2 threads {figures['cpu2']:6.0f} solves/CPU-s ({figures['wall2']:6.0f}/wall-s "
        f"per thread, load {figures['load2']:.2f}); parallel efficiency CPU {figures['cpu2'] / figures['cpu1']:.2f}, "
        f"wall {figures['wall2'] / figures['wall1']:.2f}; Newton iterations {figures['iterations']:.2f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rves", type=int, default=64)
    parser.add_argument("--networks", type=int, default=8, help="distinct networks (seeds)")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--reference", default=DEFAULT_REFERENCE, help="git revision to compare with ('' = none)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args)
        return
    print(f"machine: {os.cpu_count()} CPUs, load average at start {os.getloadavg()}")
    reference = None
    if args.reference:
        with tempfile.TemporaryDirectory() as tmp:
            extract(args.reference, Path(tmp))
            reference = run_worker(Path(tmp), args)
    current = run_worker(ROOT, args)
    print(
        f"RVEs: {args.rves}, fibers/RVE: {current[0]['fibers']:.0f}, interior DOFs/RVE: "
        f"{current[0]['interior_dofs']:.0f}"
    )
    if reference is not None:
        report(f"ref {args.reference}", reference[0])
    report("current", current[0])
    if reference is not None:
        stress_diff = np.abs(current[1] - reference[1]).max() / np.abs(reference[1]).max()
        tangent_diff = np.abs(current[2] - reference[2]).max() / np.abs(reference[2]).max()
        print(f"current vs reference: max |Δσ|/max|σ| = {stress_diff:.1e}, max |ΔC|/max|C| = {tangent_diff:.1e}")
        print(f"speed-up single thread (CPU time): {current[0]['cpu1'] / reference[0]['cpu1']:.2f}x")

    sys.path.insert(0, str(ROOT))
    batch, F1 = build(args.rves, args.networks)
    times = breakdown(batch, F1)
    total = sum(times.values())
    print(f"current kernel parts on RVE 0, one call each (load {load():.2f}):")
    for name, t in times.items():
        print(f"  {name:22s} {t * 1e6:8.1f} us  ({100 * t / total:4.1f} % of one pass)")
    print(f"numba threading layer: {current[0]['threading_layer']}")
    print(f"rve_solves_per_core_second={current[0]['cpu1']:.0f}")


if __name__ == "__main__":
    main()
