"""Benchmark: assembly throughput per law (fused kernel vs generic path) and one Texas TriValve iteration.

Part 1 — Gauss points per second of stress + tangent + element forces/stiffness on a block of
trilinear hexahedra (8 points each), for every law the papers use, through the fused kernel of
``skvalve.fem.elements.fused`` and through the generic path (``law.pk1_and_tangent`` with
``kernels.element_forces/element_stiffness``), with their ratio in the same run; the two agree
to 1e-12 (checked here on the first element too, fully in tests/test_fem_fused.py).

Part 2 — one Newton iteration on the Texas TriValve 1.0 leaflets (Diseased_QuasiStatic.inp, the
C3D8R leaflet elements with full 2x2x2 integration, the file's Lee–Sacks parameters per leaflet,
annulus nodes fixed, a smooth trial displacement): assembly (F, fused stress/tangent/element
matrices per leaflet, forces, CSR values) and the sparse solve of ``skvalve.fem.solvers.linsolve.LinearSolver``
(symmetric PARDISO; the analysis is done once per pattern, so the first solve also reports it).
The generic assembly is timed too, and so is the F-bar term of the same leaflets
(``skvalve.fem.elements.fbar.FBarTerm``, residual + tangent) with P and dP/dF at F_bar from the compiled laws
(``fused.point_response_regions``) against the generic ``MaterialRegions.evaluate``.
Last line ``trivalve_iteration_seconds=<assembly + solve>``.
Data: Texas TriValve (set ``SKVALVE_TRIVALVE`` or place it under shared/data); skipped if absent.

Run:  python benchmarks/assembly.py [block_n]   (default 16, i.e. 4096 elements, 32768 points)
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.io.meshio import from_meshio

from skvalve.fem.elements.fbar import FBarTerm
from skvalve.fem.elements.fused import fused_response
from skvalve.fem.kernels import csr_pattern, element_forces, element_gradients, element_stiffness, scatter_add
from skvalve.fem.solvers.linsolve import LinearSolver
from skvalve.fem.space import Space
from skvalve.io.abaqus import read_model
from skvalve.kinematics import determinant
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden

LAWS = {
    "neo-Hookean (compressible)": NeoHookean(1.0, 3.0),
    "incompressible neo-Hookean (isochoric)": IncompressibleNeoHookean(1.0),
    "Lee-Sacks (shipped)": LeeSacks(1.0, 0.5, 2.0, D=0.2),
    "Lee-Sacks (published Eq. 1)": LeeSacks(1.0, 0.5, 2.0, D=0.2, published_equation=True),
    "Ogden 3-term": Ogden(mu=(1.0, 0.2, 0.1), alpha=(2.5, 5.0, -2.0), D=(0.1,)),
    "bimodular neo-Hookean (smoothed)": BimodularNeoHookean(2.0, 1.0, [1.0, 1.0, 0.0], smoothing=0.05),
}


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.2f} (1 min) {five:.2f} (5 min) on {os.cpu_count()} cores"


def shape_gradients(mesh: fem.Mesh):
    """dN (nel, nqp, nb, 3), dx (nel, nqp) and element dofs (nel, 3 nb) of Q1 with 2x2x2 Gauss points."""
    basis = fem.CellBasis(mesh, fem.ElementHex1(), intorder=3)
    grads = np.stack([basis.basis[a][0].grad for a in range(basis.Nbfun)])
    dN = np.ascontiguousarray(grads.transpose(2, 3, 0, 1))
    scalar = basis.element_dofs.T
    dofs = np.ascontiguousarray((3 * scalar[:, :, None] + np.arange(3)).reshape(mesh.nelements, -1))
    return basis, dN, np.ascontiguousarray(basis.dx), dofs


def deformation(mesh: fem.Mesh, dN: np.ndarray, dofs: np.ndarray, amplitude: float) -> tuple[np.ndarray, np.ndarray]:
    """A smooth displacement (sines of the coordinates) and its F at the points."""
    X = mesh.p
    size = np.ptp(X, axis=1).max()
    u = amplitude * size * np.sin(2.0 * np.pi * X[[1, 2, 0]] / size).T.ravel()
    u_elem = u[dofs].reshape(dofs.shape[0], -1, 3)
    return u, element_gradients(u_elem, dN) + np.eye(3)[:, :, None, None]


def generic(law, F, dN, dx, ndofe):
    P, A = law.pk1_and_tangent(F)
    fe = element_forces(np.ascontiguousarray(P), dN, dx)
    ke = np.zeros((dN.shape[0], ndofe, ndofe))
    element_stiffness(A.transpose(5, 4, 0, 1, 2, 3), dN, dx, ke)
    return fe, ke


def best_of(function, repeats: int) -> float:
    """Shortest wall time of ``repeats`` calls (the machine is shared: the minimum is the least disturbed)."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def cpu_seconds(function) -> tuple[float, float]:
    """Wall and process CPU seconds (all threads) of one call."""
    wall, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - wall, time.process_time() - cpu


def throughput(n: int) -> None:
    mesh = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, n + 1)] * 3)
    _, dN, dx, dofs = shape_gradients(mesh)
    _, F = deformation(mesh, dN, dofs, 0.02)
    points = dx.size
    print(f"Part 1: {mesh.nelements} Q1 hexahedra, {points} Gauss points; {load()}")
    for name, law in LAWS.items():
        fused = fused_response(law)
        got = fused(F, dN, dx)  # compiles (or loads the numba cache) outside the timing
        fe, ke = generic(law, F[..., :1], dN[:1], dx[:1], 24)
        deviation = np.abs(got.stiffness[:1] - ke).max() / np.abs(ke).max()
        t_fused = best_of(lambda law=law, fused=fused: fused(F, dN, dx), 3)
        t_generic = best_of(lambda law=law: generic(law, F, dN, dx, 24), 2)
        print(f"  {name:40s} fused {points / t_fused:12.0f} pts/s | generic {points / t_generic:10.0f} pts/s | "
              f"speed-up {t_generic / t_fused:6.1f}x | first element rel. diff {deviation:.1e}")
        sys.stdout.flush()


def trivalve_input() -> Path | None:
    candidates = [os.environ.get("SKVALVE_TRIVALVE", "")]
    here = Path(__file__).resolve()
    candidates += [str(p / "shared/data/texas_trivalve") for p in here.parents]
    for candidate in filter(None, candidates):
        path = Path(candidate)
        path = path / "Diseased_QuasiStatic.inp" if path.is_dir() else path
        if path.is_file():
            return path
    return None


def leaflet_model(path: Path):
    """Leaflet hexahedra as a scikit-fem mesh, element regions with their Lee–Sacks laws, annulus nodes."""
    model = read_model(path)
    blocks = model.blocks_of_type("C3D8R")
    connectivity = np.concatenate([b.connectivity for b in blocks])
    global_elements = np.concatenate([b.indices for b in blocks])
    used, local = np.unique(connectivity, return_inverse=True)
    mesh = from_meshio(meshio.Mesh(model.nodes[used], [("hexahedron", local.reshape(connectivity.shape))]))
    position = {int(g): i for i, g in enumerate(global_elements)}
    regions = []
    for section in model.sections:
        option = model.material(section.material).options
        data = next((o.data for o in option if o.keyword.startswith("anisotropic hyperelastic")), None)
        if data is None:
            continue
        c0, D, c1, c2 = data[:4]  # VUANISO_ISO properties C0, D, C1, C2
        elements = np.array([position[int(g)] for g in section.elements if int(g) in position])
        regions.append((section.material, LeeSacks(c0, c1, c2, D=D), elements))
    annulus = np.searchsorted(used, model.node_set("Leaflet_Instance.Outer_Annular_Nodes").indices)
    return mesh, regions, annulus


def fbar_assembly(mesh: fem.Mesh, regions, u: np.ndarray) -> None:
    """F-bar residual + tangent of the leaflets: compiled laws against the generic path, same run."""
    space = Space(mesh)
    index = np.empty(mesh.nelements, dtype=int)
    for r, (_, _, elements) in enumerate(regions):
        index[elements] = r
    laws = [law for _, law, _ in regions]
    fused, generic_term = FBarTerm(space, laws, index), FBarTerm(space, laws, index, fused=False)
    got = fused.assemble(u, 0.0, True, None)  # compile / load cache
    expected = generic_term.assemble(u, 0.0, True, None)
    deviation = np.abs(got.blocks[0].matrices - expected.blocks[0].matrices).max() / np.abs(
        expected.blocks[0].matrices).max()
    t_fused = best_of(lambda: fused.assemble(u, 0.0, True, None), 3)
    t_generic = best_of(lambda: generic_term.assemble(u, 0.0, True, None), 1)
    print(f"  F-bar term (residual + tangent): compiled laws {t_fused:.3f} s | generic MaterialRegions.evaluate "
          f"{t_generic:.3f} s | speed-up {t_generic / t_fused:.1f}x | element matrices rel. diff {deviation:.1e} | "
          f"{load()}")


def trivalve_iteration(path: Path) -> None:
    start = time.perf_counter()
    mesh, regions, annulus = leaflet_model(path)
    _, dN, dx, dofs = shape_gradients(mesh)
    n = 3 * mesh.nvertices
    fixed = (3 * annulus[:, None] + np.arange(3)).ravel()
    reduced = np.full(n, -1, dtype=np.int64)
    free = np.setdiff1d(np.arange(n), fixed)
    reduced[free] = np.arange(free.size)
    indptr, indices, positions = csr_pattern(np.ascontiguousarray(reduced[dofs]), free.size)
    for amplitude in (1e-3, 1e-4, 1e-5, 0.0):  # a smooth trial displacement that keeps det F > 0 everywhere
        u, F = deformation(mesh, dN, dofs, amplitude)
        if np.all(determinant(F) > 0.0):
            break
    u[fixed] = 0.0
    laws = [(law, elements, fused_response(law)) for _, law, elements in regions]
    setup = time.perf_counter() - start
    print(f"Part 2: Texas TriValve 1.0 leaflets {path.name}: {mesh.nelements} C3D8R as Q1 (2x2x2), "
          f"{dx.size} Gauss points, {free.size} free of {n} DOF, {indices.size} nonzeros; trial |u| ~ {amplitude:g} "
          f"x size; "
          f"{len(regions)} Lee–Sacks regions ({', '.join(r[0] for r in regions)}); setup {setup:.1f} s; {load()}")

    def assemble(use_fused: bool):
        u_elem = u[dofs].reshape(dofs.shape[0], -1, 3)
        F = element_gradients(u_elem, dN) + np.eye(3)[:, :, None, None]
        fe = np.empty((mesh.nelements, 24))
        ke = np.empty((mesh.nelements, 24, 24))
        for law, elements, fused in laws:
            if use_fused:
                response = fused(F[..., elements], dN[elements], dx[elements])
                fe[elements], ke[elements] = response.forces, response.stiffness
            else:
                fe[elements], ke[elements] = generic(law, F[..., elements], dN[elements], dx[elements], 24)
        internal = np.bincount(dofs.ravel(), fe.ravel(), minlength=n)
        data = np.zeros(indices.size)
        scatter_add(ke, positions, data)
        return internal, data

    assemble(True)  # compile / load cache
    t_generic = best_of(lambda: assemble(False), 1)
    times = []
    for _ in range(3):
        start = time.perf_counter()
        internal, data = assemble(True)
        times.append(time.perf_counter() - start)
    t_assembly = min(times)
    wall, cpu = cpu_seconds(lambda: assemble(True))
    print(f"  fused assembly once more: wall {wall:.3f} s, CPU {cpu:.3f} s over all threads")
    solver = LinearSolver(None, symmetric=True).analyse((indptr, indices))
    rhs = -internal[free]
    start = time.perf_counter()
    x = solver.factorize(data).solve(rhs)
    t_first = time.perf_counter() - start
    K = sp.csr_matrix((data, indices, indptr), shape=(free.size, free.size))
    residual = np.linalg.norm(K @ x - rhs) / np.linalg.norm(rhs)
    solves = []
    for k in range(2):  # later iterations: new values on the same pattern, the analysis is kept
        start = time.perf_counter()
        solver.factorize(data * (1.0 + 1e-9 * (k + 1))).solve(rhs)
        solves.append(time.perf_counter() - start)
    t_solve = min(solves)
    wall, cpu = cpu_seconds(lambda: solver.factorize(data * (1.0 + 4e-9)).solve(rhs))
    print(f"  refactorisation + solve once more: wall {wall:.3f} s, CPU {cpu:.3f} s over all threads")
    print(f"  assembly fused {t_assembly:.3f} s (generic {t_generic:.3f} s, {t_generic / t_assembly:.1f}x) | "
          f"solve ({solver.name}, symmetric) first {t_first:.3f} s incl. analysis, then {t_solve:.3f} s | "
          f"relative residual {residual:.1e} | {load()}")
    print(f"  iteration = assembly {t_assembly:.3f} s + solve {t_solve:.3f} s (targets 0.5 s / 2 s in total)")
    fbar_assembly(mesh, regions, u)
    print(f"trivalve_iteration_seconds={t_assembly + t_solve:.3f}")


def main(argv: list[str]) -> None:
    throughput(int(argv[0]) if argv else 16)
    path = trivalve_input()
    if path is None:
        print("Texas TriValve data not found: set SKVALVE_TRIVALVE to Diseased_QuasiStatic.inp; part 2 skipped")
        print("trivalve_iteration_seconds=nan")
        return
    trivalve_iteration(path)


if __name__ == "__main__":
    main(sys.argv[1:])
