"""Benchmark: uniaxial stretch of a unit cube, skvalve.fem vs felupe in the same process.

Unit cube of N x N x N trilinear hexahedra, compressible neo-Hookean (mu = 1, nu = 0.45),
symmetry conditions on x = 0, y = 0, z = 0, face x = 1 pulled to stretch 1.5 in 5 equal
steps, Newton converged to relative residual 1e-8 (|R_free| / |R_prescribed|, felupe's
criterion). Both codes run on the same mesh with the same sparse direct solver.
Prints per N: DOFs, Newton iterations, wall times, reaction forces (against each other and
against the closed form), the time of one bare sparse solve of the tangent (fresh: analysis,
factorisation and solve; skvalve keeps the analysis between iterations, felupe's ``pypardiso.spsolve``
redoes it each time), the machine's load average, and finally
``ratio_vs_felupe=<skvalve time / felupe time at the largest N>``.

Run:  python benchmarks/block_vs_felupe.py [N ...]     (default 8 16 24)
felupe is a benchmark-only dependency (extra ``bench``); the library never imports it.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np
import skfem as fem
from scipy.optimize import brentq
from skfem.io.meshio import to_meshio

from skvalve.fem import Solid
from skvalve.fem.solvers import linsolve
from skvalve.materials import NeoHookean

STRETCH, STEPS, RTOL = 1.5, 5, 1e-8


def closed_form_force(material: NeoHookean, stretch: float) -> float:
    """Axial force on the unit face: P11 with lateral stretch from sigma22 = 0."""
    mu, lm = material.mu, material.lmbda
    lateral = brentq(lambda s: mu * (s**2 - 1.0) + lm * np.log(stretch * s**2), 0.1, 1.0)
    J = stretch * lateral**2
    sigma11 = (mu * (stretch**2 - 1.0) + lm * np.log(J)) / J
    return sigma11 * lateral**2


def run_skvalve(mesh: fem.Mesh, material: NeoHookean):
    start, cpu = time.perf_counter(), time.process_time()
    solid = Solid(mesh, material)
    solid.add_dirichlet("left", 0.0, components=[0]).add_dirichlet("bottom", 0.0, components=[1])
    solid.add_dirichlet("front", 0.0, components=[2]).add_dirichlet("right", STRETCH - 1.0, components=[0])
    result = solid.solve(steps=STEPS, rtol=RTOL, progress=False)
    elapsed = time.perf_counter() - start
    return solid, result, elapsed, time.process_time() - cpu


def run_felupe(mesh: fem.Mesh, material: NeoHookean, solver):
    import felupe as fe

    start, cpu = time.perf_counter(), time.process_time()
    m = to_meshio(mesh)
    fmesh = fe.Mesh(m.points, m.cells_dict["hexahedron"], "hexahedron")
    region = fe.RegionHexahedron(fmesh)
    field = fe.FieldContainer([fe.Field(region, dim=3)])
    boundaries = {
        "x0": fe.Boundary(field[0], fx=0.0, skip=(0, 1, 1)),
        "y0": fe.Boundary(field[0], fy=0.0, skip=(1, 0, 1)),
        "z0": fe.Boundary(field[0], fz=0.0, skip=(1, 1, 0)),
        "move": fe.Boundary(field[0], fx=1.0, skip=(0, 1, 1)),
    }
    umat = fe.NeoHookeCompressible(mu=material.mu, lmbda=material.lmbda)
    body = fe.SolidBody(umat, field)
    ramp = np.linspace(0.0, STRETCH - 1.0, STEPS + 1)[1:]
    step = fe.Step(items=[body], ramp={boundaries["move"]: ramp}, boundaries=boundaries)
    job = fe.Job(steps=[step])
    job.evaluate(tol=RTOL, solver=solver, verbose=0)
    elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    forces = np.asarray(body.assemble.vector(field).todense()).reshape(-1, 3)
    reaction = forces[fmesh.points[:, 0] == 1.0].sum(axis=0)
    iterations = sum(len(f) for f in job.fnorms)
    return reaction, iterations, elapsed, cpu


def bare_solve_time(solid: Solid, result, solver: str, symmetric: bool) -> tuple[float, float]:
    """A fresh solve of the final tangent (analysis + factorisation + solve), and a refactorisation + solve.

    The first is what one isolated sparse solve costs; the second what a later Newton iteration pays
    with the analysis kept (``linsolve.LinearSolver``). Symmetric: upper triangle, as skvalve does.
    """
    _, matrices = solid.assemble(result.u(), 1.0, tangent=True)
    K = solid.tangent_matrix(matrices)
    K.sort_indices()
    rhs = np.ones(K.shape[0])
    start = time.perf_counter()
    fresh = linsolve.LinearSolver(solver, symmetric=symmetric).analyse(K)
    fresh.factorize(K.data).solve(rhs)
    t_fresh = time.perf_counter() - start
    start = time.perf_counter()
    fresh.factorize(K.data * (1.0 + 1e-9)).solve(rhs)
    return t_fresh, time.perf_counter() - start


def main(sizes: list[int]) -> None:
    solver = linsolve.solver_name()
    if solver == "pardiso":
        import pypardiso

        felupe_solver = pypardiso.spsolve
    else:
        from scipy.sparse.linalg import spsolve as felupe_solver
    print(f"sparse solver: {solver} (both codes; skvalve factorises the symmetric tangent as symmetric "
          "indefinite when PARDISO is available, felupe uses the general unsymmetric mode)")
    material = NeoHookean.from_shear_poisson(1.0, 0.45)
    exact = closed_form_force(material, STRETCH)
    # warm up the compiled kernels (numba cache) outside the timings
    run_skvalve(fem.MeshHex.init_tensor(*[np.linspace(0, 1, 3)] * 3).with_defaults(), material)
    ratio = np.nan
    for N in sizes:
        mesh = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, N + 1)] * 3).with_defaults()
        solid, result, t_sk, cpu_sk = run_skvalve(mesh, material)
        r_sk = result.reaction("right")
        r_fe, it_fe, t_fe, cpu_fe = run_felupe(mesh, material, felupe_solver)
        t_solve, t_refactor = bare_solve_time(solid, result, solver, symmetric=True)
        t_solve_general, _ = bare_solve_time(solid, result, solver, symmetric=False)
        agree = abs(r_sk[0] - r_fe[0]) / abs(r_fe[0])
        print(
            f"N={N:3d} dofs={solid.space.n_dofs:7d} | skvalve: {result.iterations:3d} it {t_sk:8.2f} s "
            f"Fx={r_sk[0]:.10f} | felupe: {it_fe:3d} it {t_fe:8.2f} s Fx={r_fe[0]:.10f} | "
            f"rel.diff={agree:.1e} closed form={exact:.10f} (skvalve err {abs(r_sk[0] - exact) / exact:.1e}) | "
            f"bare solve {t_solve:.3f} s (symmetric; {t_refactor:.3f} s refactorised with the analysis kept) / "
            f"{t_solve_general:.3f} s (general), "
            f"skvalve / (iterations x bare symmetric solve) = {t_sk / (result.iterations * t_solve):.2f}"
        )
        tm = result.timings
        print(f"        skvalve split: pattern {tm['setup']:.2f} s, assembly {tm['assembly']:.2f} s, "
              f"solves {tm['solve']:.2f} s, rest {t_sk - sum(tm.values()):.2f} s | process CPU seconds (all "
              f"threads): skvalve {cpu_sk:.1f}, felupe {cpu_fe:.1f}, ratio {cpu_sk / cpu_fe:.3f}")
        if agree > 1e-6:
            print(f"  WARNING: reactions differ by {agree:.2e} > 1e-6")
        ratio = t_sk / t_fe
        sys.stdout.flush()
    one, five, _ = os.getloadavg()
    print(f"machine load average {one:.2f} (1 min) {five:.2f} (5 min) on {os.cpu_count()} cores")
    print(f"ratio_vs_felupe={ratio:.3f}")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [8, 16, 24])
