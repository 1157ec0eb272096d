"""Benchmark: the contact search and assembly of the Texas TriValve 1.0 diseased valve, each triangle's own search
radius against one radius for all (the largest triangle's, the rule before), in the same run.

The leaflet contact (:class:`skvalve.fem.contact.SurfaceContact`, blended, search depth 0.2 mm, barrier, loaded
skins in contact: the options the held valve converged with) searches, for every triangle of its 10 628 faces, the
surface nodes within its search radius. With the largest triangle's radius for every triangle the tree lists
millions of candidates for a few hundred pairs. Times ``active_pairs`` (the search and its filters) and the contact
term's assembly (residual + tangent) both ways, checks that the pairs are identical, and prints the ratios.
``--state FILE``: a kept closure state (``state.npz`` of ``skvalve valve close``) instead of the
open configuration. Needs the shipped input (``$SKVALVE_TRIVALVE``); exits 2 without it.

Last line: ``contact_search_speedup=<largest-radius time / own-radius time>``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from assembly import best_of  # benchmarks/ is on the path when a script in it runs

from skvalve.io.abaqus import read_model, trivalve_input
from skvalve.valve.closure import ClosureOptions, closure_setup
from skvalve.valve.model import valve_model
from skvalve.valve.state import read_state

#: the penalty contact the held 1.0 diseased valve converged with (search depth half the leaflet, depth barrier from
#: 0.4 of it, loaded skins in contact): the reference this benchmark measures against
PENALTY_CONTACT = {"contact_depth": 0.2, "contact_barrier": 0.4, "contact_loaded_faces": True}

def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--state", type=Path, default=None, help="a kept closure state (t, u) to search at")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    path = trivalve_input()
    if path is None:
        print("Texas TriValve input not found: set $SKVALVE_TRIVALVE (Mathur et al. 2022, CC BY-NC-SA 4.0)")
        return 2
    model = valve_model(read_model(path))
    options = ClosureOptions.for_relaxation(model, **PENALTY_CONTACT)  # the contact the held valve converged with
    setup = closure_setup(options=options, model=model)
    contact = setup.contact
    if args.state is None:
        u, t = np.zeros(setup.problem.space.n_dofs), options.end
    else:
        state = read_state(args.state)
        u, t = state.u, state.t
    setup.problem.assemble(u, t, tangent=False)
    setup.problem.commit()
    own = contact.search_radius

    def largest(corners, centroid):
        return float(own(corners, centroid).max())

    timings = {}
    for label, radius in (("own radius", own), ("largest radius", largest)):
        contact.search_radius = radius
        pairs = contact.active_pairs(u)
        timings[label] = (best_of(lambda: contact.active_pairs(u), args.repeats),
                          best_of(lambda: contact.assemble(u, t, True, None), args.repeats), pairs)
        print(f"{label:15s}: search {timings[label][0]:.3f} s, contact assembly with tangent "
              f"{timings[label][1]:.3f} s, {pairs.size} pairs", flush=True)
    del contact.search_radius
    a, b = timings["own radius"][2], timings["largest radius"][2]
    same = all(np.array_equal(getattr(a, key), getattr(b, key)) for key in ("node", "triangle", "gap", "weights"))
    print(f"pairs identical: {same}; faces {contact.surface.quads.shape[0]}; at step time {t:g}")
    if not same:
        raise SystemExit("the two searches found different pairs")
    search = timings["largest radius"][0] / timings["own radius"][0]
    assembly = timings["largest radius"][1] / timings["own radius"][1]
    print(f"ratios (largest radius / own radius): search {search:.1f}, contact assembly {assembly:.1f}")
    print(f"contact_search_speedup={search:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
