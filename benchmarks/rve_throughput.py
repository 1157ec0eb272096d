"""Warm-started RVE solves per core-second (Thomas 2019 microscale, issue 5).

B networks of ~450 fibers (α = 41 %, several seeds) are equilibrated at an equibiaxial
stretch F0; then each is re-solved, warm-started, at F0 + ΔF (a small load increment of
0.2 % stretch plus a little shear, as one macro Newton iteration would request) — Newton to
1e-10 relative residual, stress and consistent tangent included.  Timed with 1 thread and with
all numba threads; the per-core figure divides by the thread count.  A breakdown times the
kernel parts on one RVE to show what dominates, and compares the hand-written numba Cholesky
with LAPACK's (scipy ``cho_factor``) on the same matrix in the same process.
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np
from scipy.linalg import cho_factor

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks import rve_kernels as kernels
from skvalve.networks.dense_cholesky import cholesky_in_place
from skvalve.networks.generate import generate
from skvalve.networks.rve import RVEBatch


def timed_solves(batch: RVEBatch, F: np.ndarray, repeats: int) -> float:
    """Best of ``repeats`` wall times of one batch solve (the machine may be shared)."""
    batch.solve(F, update_state=False)  # warm-up (compilation, caches)
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        out = batch.solve(F, update_state=False)
        best = min(best, time.perf_counter() - start)
    assert np.all(out["status"] == 0)
    return best


def breakdown(batch: RVEBatch, F: np.ndarray, repeats: int = 200) -> dict:
    """Seconds per call of assembly, Cholesky, 9-RHS sensitivity and stress/tangent (RVE 0)."""
    n0, n1 = batch.node_start[0], batch.node_start[1]
    m0, m1 = batch.fiber_start[0], batch.fiber_start[1]
    X, fibers = batch.X[n0:n1], batch.fibers[m0:m1]
    rest, dof, n_free = batch.rest_length[m0:m1], batch.dof[n0:n1], batch.n_free[0]
    x = batch.positions[n0:n1].copy()
    n = 3 * n_free
    residual, matrix, work = np.empty(n), np.empty((n, n)), np.empty((n, n))
    blocks = np.empty((len(fibers), 3, 3))
    sens = batch.sensitivity[batch.free_start[0] : batch.free_start[1]].copy()
    cauchy, tangent, stretch = np.empty((3, 3)), np.empty((3, 3, 3, 3)), np.empty(len(fibers))
    parts = {
        "assemble residual+K": lambda: kernels.assemble(
            x, fibers, rest, dof, batch.params, residual, matrix, blocks, True
        ),
        "Cholesky": lambda: (work.__setitem__(slice(None), matrix), cholesky_in_place(work, n)),
        "Cholesky, LAPACK (ref.)": lambda: cho_factor(matrix, lower=True, check_finite=False),
        "9 sensitivity solves": lambda: kernels._sensitivities(X, fibers, dof, n_free, work, blocks, sens),
        "stress + tangent": lambda: kernels.stress_and_tangent(
            X, x, fibers, rest, dof, F[0], batch.params, batch.scale[0], sens, cauchy, tangent, stretch
        ),
    }
    times = {}
    for name, fn in parts.items():
        fn()
        best = np.inf
        for _ in range(5):
            start = time.perf_counter()
            for _ in range(repeats):
                fn()
            best = min(best, (time.perf_counter() - start) / repeats)
        times[name] = best
    return times, n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rves", type=int, default=64)
    parser.add_argument("--networks", type=int, default=8, help="distinct networks (seeds)")
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()

    fiber = ExponentialFiber.from_diameter(10.5e3, 450e-9, 50.5, 1.12)
    library = [generate(41.0, 0.0, seed=s) for s in range(args.networks)]
    networks = [library[i % len(library)] for i in range(args.rves)]
    batch = RVEBatch(networks, fiber)
    F0 = np.tile(np.diag([1.10, 1.10, 1 / 1.21]), (args.rves, 1, 1))
    batch.solve(F0)  # converged reference states
    increment = np.array([[2e-3, 5e-4, 0.0], [0.0, 2e-3, 0.0], [0.0, 0.0, -4e-3]])
    F1 = F0 + increment
    out = batch.solve(F1, update_state=False)
    iterations = out["iterations"].mean()
    n_fib = np.diff(batch.fiber_start).mean()
    print(
        f"RVEs: {args.rves}, fibers/RVE: {n_fib:.0f}, interior DOFs/RVE: "
        f"{3 * batch.n_free.mean():.0f}, Newton iterations: {out['iterations'].mean():.2f} "
        f"(+1 factorisation at the converged state)"
    )

    threads = numba.config.NUMBA_NUM_THREADS
    numba.set_num_threads(1)
    single = args.rves / timed_solves(batch, F1, args.repeats)
    numba.set_num_threads(threads)
    multi = args.rves / timed_solves(batch, F1, args.repeats)
    print(f"single thread : {single:8.0f} solves/s = {single:8.0f} per core-second")
    print(
        f"{threads:2d} threads    : {multi:8.0f} solves/s = {multi / threads:8.0f} per core-second"
        f" (parallel efficiency {multi / threads / single:.2f})"
    )
    times, n = breakdown(batch, F1)
    reference = times.pop("Cholesky, LAPACK (ref.)")
    total = sum(times.values())
    print(f"per-RVE kernel parts ({n} interior DOFs), one call each:")
    for name, t in times.items():
        print(f"  {name:22s} {t * 1e6:8.1f} us  ({100 * t / total:4.1f} % of one pass)")
    print(f"  LAPACK Cholesky (scipy cho_factor, reference): {reference * 1e6:8.1f} us")
    print(f"cholesky_numba_over_lapack_time_ratio={times['Cholesky'] / reference:.2f}")
    print(
        f"one solve = {iterations + 1:.2f} assemblies (+ line-search residuals), a Cholesky "
        "for each refactorised Newton step and one at convergence, 1 sensitivity + 1 stress pass"
    )
    print(f"rve_solves_per_core_second={single:.0f}")


if __name__ == "__main__":
    main()
