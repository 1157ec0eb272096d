"""Locking study at nu = 0.495: F-bar (mean dilatation) Q1 and full-integration Q1 against Q2/Q1.

Two plane-strain strips of the Texas TriValve leaflet's thickness (0.78 mm, 4 mm long, u_y = 0) with the
shipped anterior-leaflet law (LeeSacks C0 = 1e-3 MPa, D = 20.0669 /MPa: K/mu ~ 100, nu ~ 0.495):

* cantilever: clamped at x = 0, end face moved across by 1 % of the thickness -> end force;
* plate strip: clamped at both ends, follower pressure 1e-7 MPa on top -> mid-span mid-plane deflection.

Each element is run on a sequence of meshes; the reference is the finest Q2/Q1 (``Solid(formulation="up")``).
Prints one row per run with the ratio to the reference and, last, ``locking_fbar_worst_error=<x>`` (the worst
relative error of F-bar with 4 layers, x >= 20 elements along).

    python benchmarks/locking.py          # about a minute on 2 cores
"""

from __future__ import annotations

import time

import numpy as np
import skfem

from skvalve.fem import FollowerPressure, Problem, Solid, Space, solve
from skvalve.fem.elements.fbar import FBarTerm
from skvalve.materials import LeeSacks

LEAFLET = LeeSacks(1.0e-3, 1.188659e-4, 15.260081, 20.0669)
LENGTH, THICKNESS, WIDTH = 4.0, 0.78, 0.2


def strip_problem(kind: str, nx: int, nz: int) -> Problem:
    mesh = skfem.MeshHex.init_tensor(np.linspace(0, LENGTH, nx + 1), np.linspace(0, WIDTH, 2),
                                     np.linspace(0, THICKNESS, nz + 1))
    if kind == "F-bar Q1":
        space = Space(mesh)
        problem = Problem(space, [FBarTerm(space, LEAFLET)])
    else:
        problem = Solid(mesh, LEAFLET, formulation="up" if kind == "Q2/Q1" else "u")
    problem.add_dirichlet(lambda X: np.isclose(X[0], 0.0), 0.0)
    problem.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), 0.0, components=[1])
    return problem


def cantilever(kind: str, nx: int, nz: int) -> float:
    problem = strip_problem(kind, nx, nz)
    problem.add_dirichlet(lambda X: np.isclose(X[0], LENGTH), 0.01 * THICKNESS, components=[2])
    return float(solve(problem, steps=1, progress=False).reaction(lambda X: np.isclose(X[0], LENGTH))[2])


def plate(kind: str, nx: int, nz: int) -> float:
    problem = strip_problem(kind, nx, nz)
    problem.add_dirichlet(lambda X: np.isclose(X[0], LENGTH), 0.0)
    top = problem.mesh.facets_satisfying(lambda x: np.isclose(x[2], THICKNESS), boundaries_only=True)
    problem.add_term(FollowerPressure(problem.space, top, 1e-7))
    u = solve(problem, steps=1, progress=False).u()
    X = problem.space.dof_coordinates if kind == "Q2/Q1" else problem.mesh.p
    mid = np.flatnonzero(np.isclose(X[0], LENGTH / 2) & np.isclose(X[2], THICKNESS / 2))
    return float(u[3 * mid + 2].mean())


MESHES = {"Q2/Q1": [(10, 2), (20, 4), (40, 8)], "Q1": [(20, 4), (40, 4), (80, 8)],
          "F-bar Q1": [(20, 4), (40, 4), (80, 4), (80, 8)]}


def main() -> None:
    worst = 0.0
    for name, run in (("cantilever end force", cantilever), ("plate mid-span deflection", plate)):
        rows = []
        for kind, meshes in MESHES.items():
            for nx, nz in meshes:
                start = time.perf_counter()
                rows.append((kind, nx, nz, run(kind, nx, nz), time.perf_counter() - start))
        reference = rows[len(MESHES["Q2/Q1"]) - 1][3]
        print(f"\n{name} (reference: Q2/Q1 {MESHES['Q2/Q1'][-1]} = {reference:.6e})")
        print(f"{'element':10s} {'nx x nz':>8s} {'value':>14s} {'/reference':>11s} {'seconds':>8s}")
        for kind, nx, nz, value, seconds in rows:
            ratio = value / reference
            print(f"{kind:10s} {nx:>3d} x {nz:<3d} {value:14.6e} {ratio:11.4f} {seconds:8.1f}")
            if kind == "F-bar Q1" and nz == 4:
                worst = max(worst, abs(ratio - 1.0))
    print(f"locking_fbar_worst_error={worst:.4f}")


if __name__ == "__main__":
    main()
