"""Benchmark: IPC barrier contact (:class:`skvalve.fem.contact.IPCContact`, ipctk) on the Texas TriValve 1.0 diseased
valve's whole hex boundary, against the penalty contact the held valve converged with, in the same run.

Times, best of ``--repeats``: the term's set-up (collision mesh, filters), the collision set's build, the barrier's
assembly at a new state (build, gradient, exact and per-stencil PSD Hessians), the collision-free step of a random
move of every surface vertex (``--move`` mm, continuous collision detection), an intersection check, and the penalty
term's assembly with tangent (:class:`~skvalve.fem.contact.SurfaceContact` on the input's contact surfaces and its
pressure-loaded skins: blended, search depth 0.2 mm, depth barrier, switched on by a smooth step over 0.1 of step
time from the pressure's start; built here by :func:`penalty_contact`). ``--state FILE``: a kept closure state
instead of the open valve. Needs the shipped input (``$SKVALVE_TRIVALVE``, Mathur et al. 2022, CC BY-NC-SA 4.0);
exits 2 without it.

Last line: ``ipc_assembly_ratio=<IPC assembly time / penalty assembly time>``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
from assembly import best_of  # benchmarks/ is on the path when a script in it runs

from skvalve.fem.amplitudes import SmoothStep
from skvalve.fem.contact import IPCContact, SurfaceContact
from skvalve.fem.problem import Problem
from skvalve.io.abaqus import AbaqusModel, read_model, trivalve_input
from skvalve.valve.model import ValveModel, valve_model
from skvalve.valve.state import read_state
from skvalve.valve.surfaces import contact_surface, contact_surface_names

#: the penalty contact the held 1.0 diseased valve converged with on the penalty path that the IPC closure replaced
#: (search depth half the leaflet, depth barrier from 0.4 of it, loaded skins in contact, blended, no pairs closer than
#: 1 mm in the reference, the penalty switched on over 0.1 of step time from the pressure's start): the reference this
#: benchmark measures against
PENALTY = 1.0  # MPa/mm
PENALTY_DEPTH, PENALTY_BARRIER, PENALTY_BLEND, PENALTY_EXCLUDE_WITHIN, PENALTY_RAMP = 0.2, 0.4, 0.1, 1.0, 0.1


def penalty_contact(abaqus: AbaqusModel, model: ValveModel, problem: Problem) -> SurfaceContact:
    """The penalty reference term on ``problem``: the union of the input's contact surfaces and the skins it loads
    with pressure (each face once), the penalty rising from zero at the pressure amplitude's start by a smooth step."""
    names = contact_surface_names(abaqus) + tuple(dict.fromkeys(load.surface for load in model.pressures))
    starts = [float(load.amplitude.times[0]) for load in model.pressures if load.amplitude is not None]
    start = min(starts) if starts else 0.0
    penalty = SmoothStep((start, start + PENALTY_RAMP), (0.0, PENALTY), "penalty")
    return problem.add_term(SurfaceContact(problem.space, contact_surface(abaqus, model, names), penalty,
                                           max_penetration=PENALTY_DEPTH, exclude_within=PENALTY_EXCLUDE_WITHIN,
                                           blend=PENALTY_BLEND, barrier=PENALTY_BARRIER))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--state", type=Path, default=None, help="a kept closure state (t, u) to measure at")
    parser.add_argument("--dhat", type=float, default=0.1, help="barrier range (mm)")
    parser.add_argument("--stiffness", type=float, default=100.0, help="barrier stiffness (kPa)")
    parser.add_argument("--move", type=float, default=0.3, help="random move of every surface vertex (mm)")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    path = trivalve_input()
    if path is None:
        print("Texas TriValve input not found: set $SKVALVE_TRIVALVE (Mathur et al. 2022, CC BY-NC-SA 4.0)")
        return 2
    print(f"machine: {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}", flush=True)
    abaqus = read_model(path)
    model = valve_model(abaqus)
    problem = model.problem(insertion="patch", compression=True)
    penalty = penalty_contact(abaqus, model, problem)
    space = problem.space
    if args.state is None:
        u, t = np.zeros(space.n_dofs), float(model.end_time)
    else:
        state = read_state(args.state)
        u, t = state.u, state.t
    clock = time.perf_counter()
    ipc = IPCContact(space, dhat=args.dhat, stiffness=args.stiffness)
    set_up = time.perf_counter() - clock
    V = ipc.positions(u, t)
    print(f"collision mesh: {ipc.n_body} surface vertices, {ipc.mesh.num_faces} triangles, {ipc.mesh.num_edges} "
          f"edges; set-up {set_up:.3f} s", flush=True)
    rng = np.random.default_rng(0)
    moved = u.copy()
    moved[: space.n_u].reshape(-1, 3)[ipc.nodes] += args.move * rng.uniform(-1.0, 1.0, (ipc.n_body, 3))

    def build() -> None:
        ipc.collisions.build(ipc.mesh, V, ipc.dhat)

    def assemble() -> None:  # at a new state, as in a solve: the collision set is built again
        ipc.forget_collisions()
        ipc.assemble(u, t, True, None)

    timings = {
        "collision build": best_of(build, args.repeats),
        "IPC assembly (build, gradient, both Hessians)": best_of(assemble, args.repeats),
        f"CCD step fraction ({args.move:g} mm move)": best_of(lambda: ipc.step_fraction(u, t, moved, t), args.repeats),
        "has_intersections": best_of(lambda: ipc.intersects(u, t), args.repeats),
        "penalty assembly with tangent": best_of(lambda: penalty.assemble(u, t, True, None), args.repeats),
    }
    pairs = ipc.active_pairs(u, t)
    for label, seconds in timings.items():
        print(f"{label:48s} {seconds:8.3f} s", flush=True)
    print(f"IPC pairs within dhat {args.dhat:g} mm: {pairs}; collision-free share of the move: "
          f"{ipc.step_fraction(u, t, moved, t):.3f}; intersecting: {ipc.intersects(u, t)}")
    ratio = timings["IPC assembly (build, gradient, both Hessians)"] / timings["penalty assembly with tangent"]
    print(f"ipc_assembly_ratio={ratio:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
