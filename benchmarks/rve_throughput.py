"""Warm-started RVE solves per core-second (Thomas 2019 microscale; issue 13 item 3).

B networks of ~450 fibers (α = 41 %, several seeds) are equilibrated at an equibiaxial
stretch F0; then each is re-solved, warm-started, at F0 + ΔF (a small load increment of
0.2 % stretch plus a little shear, as one macro Newton iteration would request) — Newton to
1e-10 relative residual, stress and consistent tangent included.

Before/after in the same process: the RVE kernels of ``--reference`` (default
``DEFAULT_REFERENCE``, the last revision with the dense-Cholesky kernels) are read with
``git show`` into a temporary folder and compiled next to today's; both solve the same batch
(each in its own DOF numbering, from its own converged state at F0), alternately, and the best
of ``--repeats`` rounds is kept for each.  Timed with 1 and 2 numba threads, as solves per
CPU-second of the process (all threads; the per-core figure, less sensitive to a shared
machine) and per wall-second and thread.  Parallel efficiency is the 2-thread figure over the
1-thread one.  The machine may be shared: the 1-minute load average is printed with every
figure.  A breakdown times the parts of today's kernels on one RVE.

Last line: ``rve_solves_per_core_second=<today's single-thread solves per CPU-second>``.
"""

from __future__ import annotations

import argparse
import importlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks import rve_kernels as kernels
from skvalve.networks.dense_cholesky import node_cholesky_in_place
from skvalve.networks.generate import generate
from skvalve.networks.rve import CHUNKS_PER_THREAD, RVEBatch
from skvalve.papers.thomas2019.data import FIBER, NETWORK

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_REFERENCE = "ea7883b"  # the last revision with the dense-Cholesky RVE kernels (before issue 13 item 3)


def load() -> float:
    return os.getloadavg()[0]


def reference_kernels(revision: str, folder: Path):
    """``rve_kernels`` (and its ``dense_cholesky``) of ``revision`` as a separate module, today's fiber law."""
    for name in ("dense_cholesky", "rve_kernels"):
        source = subprocess.run(
            ["git", "show", f"{revision}:skvalve/networks/{name}.py"],
            cwd=ROOT,
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        source = source.replace("from skvalve.networks.dense_cholesky import", "from reference_dense_cholesky import")
        (folder / f"reference_{name}.py").write_text(source)
    sys.path.insert(0, str(folder))
    return importlib.import_module("reference_rve_kernels")


class Solver:
    """One kernel version on one batch: its numbering, its warm state at F0, a timed warm solve at F1."""

    def __init__(self, name: str, batch: RVEBatch, module, F0: np.ndarray, reference: bool):
        self.name, self.batch, self.module, self.reference = name, batch, module, reference
        self.dof = batch.dof.copy()
        if reference:  # the old natural numbering of the interior nodes
            for r in range(len(batch.networks)):
                n0, n1 = batch.node_start[r], batch.node_start[r + 1]
                interior = batch.dof[n0:n1] >= 0
                self.dof[n0:n1][interior] = np.arange(interior.sum())
        B = F0.shape[0]
        self.x0 = batch.X @ np.eye(3)
        for r in range(B):  # affine cold start at F0
            n0, n1 = batch.node_start[r], batch.node_start[r + 1]
            self.x0[n0:n1] = batch.X[n0:n1] @ F0[r].T
        self.F0 = F0
        self.sensitivity0 = np.zeros_like(batch.sensitivity)
        out = self.solve(F0, self.x0, F0, self.sensitivity0)
        self.x0, self.sensitivity0 = out["x"], out["sensitivity"]

    def solve(self, F, x_previous, F_previous, sensitivity0) -> dict:
        b, B = self.batch, F.shape[0]
        out = dict(x=np.empty_like(b.X), cauchy=np.zeros((B, 3, 3)), tangent=np.zeros((B, 3, 3, 3, 3)))
        out.update(stretch=np.empty(len(b.fibers)), status=np.empty(B, np.int64), iterations=np.empty(B, np.int64))
        out.update(relative=np.empty(B), sensitivity=sensitivity0.copy())
        head = (b.node_start, b.fiber_start, b.free_start, b.X, b.fibers, b.rest_length, self.dof)
        middle = (b.n_free, x_previous, F_previous, out["sensitivity"], F, b.params, b.scale, b.tol, b.max_iter)
        tail = (out["x"], out["cauchy"], out["tangent"], out["stretch"], out["status"], out["iterations"])
        if self.reference:
            self.module.solve_many(*head, *middle, *tail, out["relative"])
        else:  # every RVE from the given start (stored = alternate), tangents computed, into new arrays
            chunks = min(B, CHUNKS_PER_THREAD * numba.get_num_threads())
            active, keep, start = np.arange(B, dtype=np.int64), np.zeros(B, dtype=bool), np.zeros(B, dtype=np.int64)
            sensitivity = np.empty_like(sensitivity0)
            self.module.solve_many(*head, b.first, b.n_free, x_previous, F_previous, sensitivity0, x_previous,
                                   F_previous, sensitivity0, start, F, b.params, b.scale, b.tol, b.max_iter,
                                   out["x"], sensitivity, out["cauchy"], out["tangent"], out["stretch"],
                                   out["status"], out["iterations"], out["relative"], active, keep, chunks)
            out["sensitivity"] = sensitivity
        assert np.all(out["status"] == 0), f"{self.name}: not every RVE converged"
        return out

    def warm(self, F1) -> tuple[float, float, dict]:
        """(wall, CPU) seconds of one warm-started batch solve at F1."""
        wall, cpu = time.perf_counter(), time.process_time()
        out = self.solve(F1, self.x0, self.F0, self.sensitivity0)
        return time.perf_counter() - wall, time.process_time() - cpu, out


def breakdown(batch: RVEBatch, F: np.ndarray, repeats: int = 300) -> dict:
    """Seconds per call of the parts of today's kernels on RVE 0 (thread CPU time)."""
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
        "Cholesky (envelope, node rows)": lambda: (
            work.__setitem__(slice(None), matrix),
            node_cholesky_in_place(work, n, first),
        ),
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rves", type=int, default=64)
    parser.add_argument("--networks", type=int, default=8, help="distinct networks (seeds)")
    parser.add_argument("--repeats", type=int, default=9, help="alternating rounds; the best of each is kept")
    parser.add_argument("--reference", default=DEFAULT_REFERENCE, help="git revision to compare with")
    args = parser.parse_args()
    print(f"machine: {os.cpu_count()} CPUs, load average at start {os.getloadavg()}")

    fiber = ExponentialFiber.from_diameter(FIBER.E_f, FIBER.diameter, FIBER.beta, FIBER.lambda_c)
    library = [generate(41.0, 0.0, n_fibers=NETWORK.fibers_per_rve, seed=s) for s in range(args.networks)]
    batch = RVEBatch(
        [library[i % len(library)] for i in range(args.rves)], fiber, NETWORK.volume_fraction, FIBER.diameter
    )
    F0 = np.tile(np.diag([1.10, 1.10, 1 / 1.21]), (args.rves, 1, 1))
    F1 = F0 + np.array([[2e-3, 5e-4, 0.0], [0.0, 2e-3, 0.0], [0.0, 0.0, -4e-3]])
    with tempfile.TemporaryDirectory() as tmp:
        solvers = [
            Solver(f"ref {args.reference}", batch, reference_kernels(args.reference, Path(tmp)), F0, reference=True),
            Solver("current", batch, kernels, F0, reference=False),
        ]
        figures = {s.name: {} for s in solvers}
        for threads in (1, 2):
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            best = {s.name: [np.inf, np.inf] for s in solvers}
            before = load()
            for _ in range(args.repeats + 1):  # the first round compiles and warms the caches
                for s in solvers:
                    wall, cpu, out = s.warm(F1)
                    best[s.name] = [min(best[s.name][0], wall), min(best[s.name][1], cpu)]
                    figures[s.name]["out"], figures[s.name]["iterations"] = out, out["iterations"].mean()
                if _ == 0:
                    best = {s.name: [np.inf, np.inf] for s in solvers}
            for s in solvers:
                figures[s.name][f"cpu{threads}"] = args.rves / best[s.name][1]
                figures[s.name][f"wall{threads}"] = args.rves / best[s.name][0] / threads
                figures[s.name][f"load{threads}"] = max(before, load())
    print(
        f"RVEs: {args.rves}, fibers/RVE: {np.diff(batch.fiber_start).mean():.0f}, interior DOFs/RVE: "
        f"{3 * batch.n_free.mean():.0f}, threading layer {numba.threading_layer()}"
    )
    for name, f in figures.items():
        print(
            f"{name:12s}: 1 thread {f['cpu1']:6.0f} solves/CPU-s ({f['wall1']:6.0f}/wall-s, load {f['load1']:.2f}); "
            f"2 threads {f['cpu2']:6.0f} solves/CPU-s ({f['wall2']:6.0f}/wall-s per thread, load {f['load2']:.2f}); "
            f"parallel efficiency CPU {f['cpu2'] / f['cpu1']:.2f}, wall {f['wall2'] / f['wall1']:.2f}; "
            f"Newton iterations {f['iterations']:.2f}"
        )
    ref, cur = (figures[s.name] for s in solvers)
    for key, label in (("cauchy", "σ"), ("tangent", "dσ/dF")):
        a, b = ref["out"][key], cur["out"][key]
        print(f"current vs reference: max |Δ{label}| / max |{label}| = {np.abs(a - b).max() / np.abs(a).max():.1e}")
    print(f"speed-up single thread (CPU time): {cur['cpu1'] / ref['cpu1']:.2f}x")

    batch.solve(F0)
    times = breakdown(batch, F1)
    total = sum(times.values())
    print(f"current kernel parts on RVE 0, one call each (load {load():.2f}):")
    for name, t in times.items():
        print(f"  {name:30s} {t * 1e6:8.1f} us  ({100 * t / total:4.1f} % of one pass)")
    print(f"rve_solves_per_core_second={cur['cpu1']:.0f}")


if __name__ == "__main__":
    main()
