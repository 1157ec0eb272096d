"""FE² leaflet sample at the paper's scale (thomas2019 §2.5): 2352 hexes, 18 816 RVEs of ~450 fibers.

Runs the equibiaxial protocol (1:1, 40 N/m; edge displacements tuned to the tensions) and prints wall
time, macro Newton iterations, in-situ RVE solves per core-second, peak memory and the breakdown
(RVE solves, macro assembly, sparse solve); last line ``fe2_paper_scale_seconds=<x>``.

``--extrapolate`` (for a busy machine): the same protocol is run in full on a coarse mesh of the same
sample (8 × 8 × 1, same networks, same edge conditions), which gives the number of RVE batch evaluations
and macro iterations; at paper scale the sample and its 18 816 RVEs are built (memory, set-up) and one
macro iteration is timed (all RVEs solved warm from the committed reference state at the first ramp
step's deformation, the assembly and one sparse solve). The paper-scale time is then
evaluations × (RVE batch time) + iterations × (assembly + sparse solve) — an extrapolation, printed as such.
The ratio column compares with the paper's 15 h on 200 cores (§2.5).
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numba
import numpy as np

from skvalve.fem import linsolve
from skvalve.networks.rve import RVEBatch
from skvalve.papers.thomas2019 import data
from skvalve.papers.thomas2019.models import fe2_material
from skvalve.papers.thomas2019.protocols import biaxial_problem, run_protocol
from skvalve.papers.thomas2019.sample import build_sample


def reference_throughput(sample, material, count: int = 64) -> float:
    """Warm-started RVE solves per core-second after a 0.2 % increment (as benchmarks/rve_throughput.py)."""
    batch = RVEBatch(sample.networks[:count], material.fiber, material.psi, material.fiber_diameter)
    F0 = np.tile(np.diag([1.10, 1.10, 1 / 1.21]), (batch.scale.size, 1, 1))
    batch.solve(F0)
    F1 = F0 + np.diag([0.002, 0.001, -0.002])
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        batch.solve(F1, update_state=False)
        best = min(best, time.perf_counter() - start)
    return batch.scale.size / best / numba.get_num_threads()


def peak_memory_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2


class CountingSolve:
    """Counts material evaluations (RVE batch solves) and their time."""

    def __init__(self, material):
        self.material = material
        self.calls, self.seconds = 0, 0.0
        self._solve = material._solve

        def counted(F):
            before = self.material.solves
            out = self._solve(F)
            if self.material.solves > before:
                self.calls += 1
            return out

        material._solve = counted


def run_full(divisions, n_fibers, progress):
    start = time.perf_counter()
    sample = build_sample(divisions, n_fibers=n_fibers)
    material = fe2_material(sample)
    setup = time.perf_counter() - start
    counter = CountingSolve(material)
    start = time.perf_counter()
    run = run_protocol(sample, material, (1.0, 1.0), progress=progress)
    wall = time.perf_counter() - start
    return sample, material, run, counter, setup, wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--extrapolate", action="store_true", help="coarse full run + one paper-scale iteration")
    parser.add_argument("--fibers", type=int, default=data.FIBERS_PER_RVE)
    args = parser.parse_args()
    threads = numba.get_num_threads()
    cores = len(os.sched_getaffinity(0))
    print(f"numba threads {threads}, cores available {cores}")
    if not args.extrapolate:
        sample, material, run, counter, setup, wall = run_full(data.MESH_DIVISIONS, args.fibers, True)
        rve_time = material.solve_seconds
        print(f"elements {sample.n_elements}, RVEs {material.n_rves}, set-up {setup:.1f} s")
        print(f"protocol 1:1 wall {wall:.1f} s, macro iterations {run.iterations}, corrections {run.corrections}, "
              f"RVE batch evaluations {counter.calls}")
        sparse = run.timings.get("solve", 0.0)
        print(f"breakdown: RVE solves {rve_time:.1f} s, sparse solves {sparse:.1f} s, macro assembly and the rest "
              f"{wall - rve_time - sparse:.1f} s, set-up {setup:.1f} s")
        in_situ = material.solves / rve_time / threads
        reference = reference_throughput(sample, material)
        print(f"in-situ RVE solves per core-second {in_situ:.0f} (reference warm 0.2 % increments in this run "
              f"{reference:.0f}; ratio {in_situ / reference:.2f})")
        print(f"peak memory {peak_memory_gb():.2f} GB")
        print(f"speed-up over the paper's {data.PAPER_WALL_HOURS} h x {data.PAPER_CORES} cores: "
              f"{data.PAPER_WALL_HOURS * 3600 * data.PAPER_CORES / (wall * threads):.0f} x in core-seconds")
        print(f"fe2_paper_scale_seconds={wall + setup:.1f}")
        return

    # 1. coarse full run: evaluations and iterations of the protocol
    sample, material, run, counter, setup, wall = run_full((8, 8, 1), args.fibers, False)
    print(f"coarse 8x8x1: {material.n_rves} RVEs, wall {wall:.1f} s, macro iterations {run.iterations}, "
          f"corrections {run.corrections}, RVE batch evaluations {counter.calls}, "
          f"in-situ RVE solves/core-s {material.solves / material.solve_seconds / threads:.0f}")
    reference = reference_throughput(sample, material)
    print(f"reference warm-start throughput in this run (0.2 % increments, 64 RVEs): {reference:.0f} solves/core-s")
    # 2. paper scale: build, one macro iteration at the first ramp step
    start = time.perf_counter()
    big = build_sample(data.MESH_DIVISIONS, n_fibers=args.fibers)
    library_time = time.perf_counter() - start
    start = time.perf_counter()
    big_material = fe2_material(big)
    big_setup = time.perf_counter() - start
    print(f"paper-scale networks from the library {library_time:.1f} s (generation is cached), "
          f"RVE material set-up {big_setup:.1f} s")
    solid, schedule = biaxial_problem(big, big_material)
    schedule.add(1.0, run.delta)
    steps = 6
    factors = [1.0 / steps]
    rve_before = big_material.solve_seconds
    u = np.zeros(solid.space.n_dofs)
    fixed, values = solid.constrained(factors[0])
    u[fixed] = values
    start = time.perf_counter()
    residual, tangent = solid.assemble(u, factors[0], tangent=True, step=1)
    assemble_time = time.perf_counter() - start
    rve_eval = big_material.solve_seconds - rve_before
    start = time.perf_counter()
    K = solid.tangent_matrix(tangent)
    free = solid.pattern.free
    linsolve.solve(K, -residual[free], linsolve.solver_name(None), symmetric=True)
    sparse_time = time.perf_counter() - start
    macro_assembly = assemble_time - rve_eval
    total = counter.calls * rve_eval + run.iterations * (macro_assembly + sparse_time) + big_setup
    print(f"paper scale: {big.n_elements} elements, {big_material.n_rves} RVEs, set-up {big_setup:.1f} s, "
          f"one RVE batch {rve_eval:.1f} s ({big_material.n_rves / rve_eval / threads:.0f} solves/core-s), "
          f"macro assembly {macro_assembly:.2f} s, sparse solve {sparse_time:.2f} s")
    print(f"extrapolated: {counter.calls} batch evaluations x {rve_eval:.1f} s + {run.iterations} iterations x "
          f"{macro_assembly + sparse_time:.2f} s + set-up {big_setup:.1f} s")
    print(f"breakdown (extrapolated): RVE solves {counter.calls * rve_eval:.0f} s, macro assembly "
          f"{run.iterations * macro_assembly:.0f} s, sparse solves {run.iterations * sparse_time:.0f} s")
    print(f"peak memory {peak_memory_gb():.2f} GB (paper-scale material built and evaluated)")
    print(f"speed-up over the paper's {data.PAPER_WALL_HOURS} h x {data.PAPER_CORES} cores: "
          f"{data.PAPER_WALL_HOURS * 3600 * data.PAPER_CORES / (total * threads):.0f} x in core-seconds")
    print("NOTE: extrapolated from a coarse full run and one paper-scale iteration (machine shared)")
    print(f"fe2_paper_scale_seconds={total:.1f}")


if __name__ == "__main__":
    main()
