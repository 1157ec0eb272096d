"""FE² leaflet sample at the paper's scale (thomas2019 §2.5): 2352 hexes, 18 816 RVEs of ~450 fibers.

Runs the equibiaxial protocol (1:1, 40 N/m, uniform edges; edge displacements tuned to the tensions) and prints
wall and CPU time with the load average, macro Newton iterations, RVE batch evaluations, RVEs solved and copied,
in-situ RVE solves per core-second beside a warm reference measured in the same run, peak memory and the
breakdown (RVE solves, macro assembly, sparse solve); last line ``fe2_paper_scale_seconds=<x>``.

Solves per core-second are solves per CPU-second of the process (all threads), which a shared machine disturbs
less than wall time. The reference is what ``benchmarks/rve_throughput.py`` measures: 64 of the sample's RVEs
warm-started at 0.2 % increments (one to two RVE Newton iterations each); in situ, a load step's first macro
iterate moves every RVE by a whole step (five to eight iterations), the later ones by little.

``--extrapolate`` (for a busy machine): the same protocol is run in full on the 28 × 28 × 1 mesh of the sample
(the paper's in-plane mesh, one of its three layers: 6272 RVEs, the same grips and boundary band), which gives the
iterations, evaluations and RVE time per RVE; at paper scale the sample and its 18 816 RVEs are built (memory,
set-up) and one macro iteration is timed without its RVE solves (assembly of the matrix terms and the sparse
solve). The paper-scale time is then set-up + 3 × (RVE time of the one-layer run) + iterations × (assembly +
sparse solve) — an extrapolation, printed as such. The speed-up column compares with the paper's 15 h on 200
cores (§2.5).
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numba
import numpy as np

from skvalve.fem.solvers import linsolve
from skvalve.networks.rve import RVEBatch
from skvalve.papers.thomas2019 import data
from skvalve.papers.thomas2019.models import fe2_material
from skvalve.papers.thomas2019.protocols import biaxial_problem, run_protocol
from skvalve.papers.thomas2019.sample import build_sample


def load() -> str:
    return "/".join(f"{v:.2f}" for v in os.getloadavg())


def reference_throughput(sample, material, count: int = 64, repeats: int = 5) -> float:
    """Warm-started RVE solves per CPU-second after a 0.2 % increment (as benchmarks/rve_throughput.py)."""
    networks = [sample.networks[e] for e in np.linspace(0, sample.n_elements - 1, count).round().astype(int)]
    batch = RVEBatch(networks, material.fiber, material.psi, material.fiber_diameter)
    F0 = np.tile(np.diag([1.10, 1.10, 1 / 1.21]), (count, 1, 1))
    batch.solve(F0)
    F1 = F0 + np.diag([0.002, 0.001, -0.002])
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        batch.solve(F1, update_state=False)
        best = min(best, time.process_time() - start)
    return count / best


def peak_memory_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2


def run_full(divisions, n_fibers, progress):
    """Build the sample and its material, run the 1:1 protocol; the times of both."""
    wall, cpu = time.perf_counter(), time.process_time()
    sample = build_sample(divisions, n_fibers=n_fibers)
    material = fe2_material(sample)
    setup = (time.perf_counter() - wall, time.process_time() - cpu)
    wall, cpu = time.perf_counter(), time.process_time()
    run = run_protocol(sample, material, (1.0, 1.0), progress=progress)
    protocol = (time.perf_counter() - wall, time.process_time() - cpu)
    return sample, material, run, setup, protocol


def report_run(label, sample, material, run, setup, protocol) -> None:
    print(f"{label}: {sample.n_elements} elements, {material.n_rves} RVEs; set-up {setup[0]:.1f} s "
          f"(CPU {setup[1]:.1f} s); protocol 1:1 wall {protocol[0]:.1f} s (CPU {protocol[1]:.1f} s)")
    print(f"  macro iterations {run.iterations}, corrections {run.corrections}, RVE batch evaluations "
          f"{material.evaluations}: {material.solves} RVEs solved, {material.reused} copied (F unchanged)")
    sparse = run.timings.get("solve", 0.0)
    rest = protocol[0] - material.solve_seconds - sparse
    print(f"  breakdown: RVE solves {material.solve_seconds:.1f} s (CPU {material.solve_cpu_seconds:.1f} s), "
          f"sparse solves {sparse:.1f} s, macro assembly and the rest {rest:.1f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--extrapolate", action="store_true", help="one-layer full run + one paper-scale iteration")
    parser.add_argument("--fibers", type=int, default=data.FIBERS_PER_RVE)
    args = parser.parse_args()
    threads = numba.get_num_threads()
    print(f"numba threads {threads}, cores available {len(os.sched_getaffinity(0))}, load average {load()}")
    if not args.extrapolate:
        sample, material, run, setup, protocol = run_full(data.MESH_DIVISIONS, args.fibers, True)
        report_run("paper scale", sample, material, run, setup, protocol)
        in_situ = material.solves / material.solve_cpu_seconds
        reference = reference_throughput(sample, material)
        print(f"in-situ RVE solves per core-second {in_situ:.0f}; reference warm 0.2 % increments in this run "
              f"{reference:.0f}; ratio {in_situ / reference:.2f}")
        total = setup[0] + protocol[0]
        cpu = setup[1] + protocol[1]
        print(f"peak memory {peak_memory_gb():.2f} GB; load average at the end {load()}")
        print(f"wall {total:.1f} s, CPU {cpu:.1f} s ({cpu / total:.2f} cores busy on average of {threads} threads)")
        print(f"speed-up over the paper's {data.PAPER_WALL_HOURS} h x {data.PAPER_CORES} cores: "
              f"{data.PAPER_WALL_HOURS * 3600 * data.PAPER_CORES / cpu:.0f} x in core-seconds")
        print(f"fe2_paper_scale_seconds={total:.1f}")
        return

    nx, ny, nz = data.MESH_DIVISIONS
    sample, material, run, setup, protocol = run_full((nx, ny, 1), args.fibers, False)
    report_run("one layer", sample, material, run, setup, protocol)
    in_situ = material.solves / material.solve_cpu_seconds
    reference = reference_throughput(sample, material)
    print(f"in-situ RVE solves per core-second {in_situ:.0f}; reference warm 0.2 % increments in this run "
          f"{reference:.0f}; ratio {in_situ / reference:.2f}")
    # paper scale: set-up, and one macro iteration's assembly (RVE solves excluded) and sparse solve
    wall, cpu = time.perf_counter(), time.process_time()
    big = build_sample(data.MESH_DIVISIONS, n_fibers=args.fibers)
    big_material = fe2_material(big)
    big_setup = time.perf_counter() - wall
    print(f"paper scale: {big.n_elements} elements, {big_material.n_rves} RVEs, set-up {big_setup:.1f} s "
          f"(CPU {time.process_time() - cpu:.1f} s)")
    solid, schedule, _ = biaxial_problem(big, big_material)
    schedule.add(1.0, run.delta)
    u = np.zeros(solid.space.n_dofs)
    fixed, values = solid.constrained(1.0 / 6)
    u[fixed] = values
    rve_before = big_material.solve_seconds
    start = time.perf_counter()
    residual, tangent = solid.assemble(u, 1.0 / 6, tangent=True, step=1)
    macro_assembly = time.perf_counter() - start - (big_material.solve_seconds - rve_before)
    start = time.perf_counter()
    K = solid.tangent_matrix(tangent)
    linsolve.solve(K, -residual[solid.pattern.free], linsolve.solver_name(None), symmetric=True)
    sparse_time = time.perf_counter() - start
    layers = big_material.n_rves / material.n_rves
    total = big_setup + layers * material.solve_seconds + run.iterations * (macro_assembly + sparse_time)
    print(f"extrapolated: set-up {big_setup:.1f} s + {layers:.0f} x RVE solves {material.solve_seconds:.1f} s + "
          f"{run.iterations} iterations x (assembly {macro_assembly:.2f} s + sparse solve {sparse_time:.2f} s)")
    print(f"peak memory {peak_memory_gb():.2f} GB (paper-scale material built and evaluated); load average {load()}")
    print("NOTE: extrapolated from a one-layer full run and one paper-scale iteration (machine shared)")
    print(f"fe2_paper_scale_seconds={total:.1f}")


if __name__ == "__main__":
    main()
