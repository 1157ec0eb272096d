"""Full implicit closure of the Texas TriValve 1.0 diseased valve (mathur2022): wall time and solver effort.

Runs :func:`skvalve.valve.closure.run_closure` from the open configuration to end-systole (step time 1.5)
with leaflet self-contact and the vanishing pseudo-transient damping, and prints wall time, load steps,
Newton iterations, active contact pairs, peak memory, the undamped residual at the last converged state,
and where it stopped if it did not reach the end. The last converged displacement is kept in
``--out`` (``last_state.npz``, written atomically after every step and, at the end, replaced by the run's kept
state: the held state with the smallest residual when the relaxation gave up; ``--resume`` restarts from it), and the
held state with the smallest relative residual in ``best_state.npz``.
Target: <= 1800 s on 2 cores. Needs the shipped inputs (``$SKVALVE_TRIVALVE``); exits 2 without them.

Last line: ``trivalve_closure_seconds=<x>``.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from skvalve.fem import linsolve
from skvalve.fem.contact.blend import DEEP_FADE
from skvalve.fem.damping import undamped_residual
from skvalve.fem.soft_modes import soft_modes
from skvalve.fem.taylor import taylor_test
from skvalve.fem.trust_steps import step_matrix
from skvalve.io.abaqus import read_model, trivalve_input
from skvalve.io.files import replace_atomically
from skvalve.papers.mathur2022.figures import write_figures
from skvalve.valve.closure import (
    ClosureOptions,
    ClosureRun,
    closure_setup,
    run_closure,
    write_log,
)
from skvalve.valve.contact_lift import closure_held_nodes, force_limit, lift_parked_nodes
from skvalve.valve.extrude import hex_corner_jacobians
from skvalve.valve.model import ABAQUS_TO_SKFEM_HEX, valve_model
from skvalve.valve.outputs import ClosureWriter, closure_measures
from skvalve.valve.relaxation import (
    HELD_PROJECTED_STEPS,
    held_stages,
    relax_closure,
    relaxation_options,
)

#: flags that override a ClosureOptions field of the same name: type and help
OPTION_FLAGS = {
    "damping": (float, "damping coefficient c0 of the papillary stage"),
    "pressure_damping": (float, "damping coefficient of the pressure stage (decays to 0 at damping_off)"),
    "papillary_steps": (int, "nominal load steps of the papillary stage"),
    "path_atol": (float, "absolute residual tolerance (N) of the damped steps"),
    "max_increment": (float, "cap (mm) on a node's displacement change per Newton iteration; 0: none"),
    "regularization": (float, "initial Levenberg-Marquardt shift of the tangent per step (0: plain Newton)"),
    "cable_softening": (float, "initial scale of the chordae's taut law (1: none)"),
    "cable_slack_fraction": (float, "cable stiffness below the slack length, relative to the small-strain modulus"),
    "contact_from": (float, "step time from which the contact penalty acts"),
    "contact_exclude_within": (float, "node-face pairs closer than this (mm) in the reference never contact"),
    "contact_blend": (float, "blended contact band beta (0: closest triangle)"),
    "contact_barrier": (float, "overlap (fraction of the search depth) from which the depth barrier acts; -1: none"),
    "contact_depth": (float, "contact search depth (mm): deeper passes are ignored (default: bricks' mean face edge)"),
    "contact_ramp": (float, "step-time interval over which the contact penalty rises smoothly to its value"),
    "penalty": (float, "contact penalty (MPa/mm)"),
    "cable_compression": (int, "1: cables that are one input truss carry their law in compression too"),
    "contact_loaded_faces": (int, "1: the pressure-loaded (ventricular) skins are in contact too"),
    "contact_smoothing": (float, "overlap (mm) over which the contact pressure is rounded as a pair switches on"),
}


class LastState:
    """Callback keeping the last converged (t, u) on disk, atomically, with what ``recorded`` holds (the run's
    ClosureOptions as JSON ``options`` and the ``input`` file's name: ``skvalve reproduce mathur2022 --state``
    rebuilds the model with them and refuses a state of another input)."""

    def __init__(self, folder: Path, recorded: dict | None = None) -> None:
        self.path, self.recorded = folder / "last_state.npz", recorded or {}

    def __call__(self, event) -> None:
        replace_atomically(self.path, lambda temporary: np.savez(temporary, t=event.load_factor, u=event.u,
                                                                  **self.recorded))

class BestState:
    """Callback keeping the state with the smallest relative residual at the held load on disk (``best_state.npz``):
    the held residual of a valve with contact rises and falls from step to step."""

    def __init__(self, folder: Path, end: float, recorded: dict | None = None) -> None:
        self.path, self.end, self.best, self.recorded = folder / "best_state.npz", end, np.inf, recorded or {}

    def __call__(self, event) -> None:
        if event.load_factor >= self.end and event.relative_residual < self.best:
            self.best = float(event.relative_residual)
            replace_atomically(self.path, lambda temporary: np.savez(temporary, t=event.load_factor, u=event.u,
                                                                      relative_residual=self.best,
                                                                      **self.recorded))

#: flags --ptc-<name> that override a PseudoTransientOptions field
PTC_FLAGS = {
    "damping": (float, "damping coefficient c of the pseudo-time flow (N s/mm^4)"),
    "max_load_step": (float, "largest pseudo-time step while the load moves"),
    "max_increment": (float, "trust region: largest nodal displacement change per step (mm)"),
    "fill": (float, "grow the pseudo-time step only to fill this share of the trust regions (0: off)"),
    "first_step": (float, "first pseudo-time step"),
    "max_steps": (int, "the most accepted pseudo-steps"),
    "stiffness_damping": (float, "stiffness-proportional damping beta |diag K| / dtau"),
    "held_stiffness_damping": (float, "stiffness-proportional damping once the load is held"),
    "blow_up": (float, "reject a step whose residual grows more than this factor"),
    "local_damping": (float, "factor on the damping of nodes that break a trust region (1: off)"),
    "max_strain_increment": (float, "trust region: largest change of an edge's or cable's tensile stretch per step"),
    "held_growth": (float, "smallest growth of the pseudo-time step per accepted step at the held load"),
    "local_decay": (float, "factor by which local damping fades per accepted step"),
    "stall_steps": (int, "give up when the held residual has not halved in this many steps (0: never)"),
}

#: flags --tr-<name> that override a TrustRegionOptions field (with --held trust-region)
TR_FLAGS = {
    "radius": (float, "first trust-region radius: the most a node may move in one step (mm)"),
    "max_radius": (float, "largest trust-region radius (mm; default: the contact search depth)"),
    "max_strain_increment": (float, "largest change of an edge's or cable's tensile stretch per step"),
    "shift": (float, "first shift of the step matrix, relative to its diagonal"),
    "project": (int, "1: project the solid's and cables' element blocks onto positive semidefinite ones"),
    "max_steps": (int, "the most accepted trust-region steps"),
    "newton_below": (float, "relative residual below which a full-tangent Newton step is tried first (0: never)"),
    "fit_radius": (int, "refactorisations with a raised shift for a step longer than the radius (0: scale it)"),
    "shift_scaling": (str, "D of the shift alpha D: diagonal (Marquardt) or uniform (Levenberg)"),
    "project_terms": (str, "comma-separated names of terms whose element blocks are projected (e.g. chordae)"),
    "shift_terms": (str, "comma-separated names of terms whose indefinite blocks are shifted semidefinite (contact)"),
}


def _add_flags(parser: argparse.ArgumentParser, table: dict, prefix: str, defaults: str) -> None:
    """``--<prefix><name>`` for each entry of a flag table (default None: the options' own value)."""
    for name, (kind, text) in table.items():
        parser.add_argument("--" + prefix + name.replace("_", "-"), type=kind, default=None,
                            help=f"{text} (default: {defaults})")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("trivalve_closure_out"))
    parser.add_argument("--end", type=float, default=None, help="last step time (default: the input's step time)")
    parser.add_argument("--verbose", action="store_true", help="one line per Newton iteration")
    parser.add_argument("--resume", action="store_true", help="start from --out/last_state.npz")
    parser.add_argument("--report", action="store_true",
                        help="with --resume: measure and draw the kept state (Table 2-3 rows, figures, VTU), no solve")
    parser.add_argument("--lift-parked", default=None, metavar="LEVEL,TARGET[,MAX_FORCE]",
                        help="with --resume: first lift the contact nodes parked deeper than LEVEL of the search "
                             "depth to TARGET of it, each node alone, halving a lift while it folds or squeezes a hex "
                             "or (with MAX_FORCE, N) loads a vertex of its hexes beyond MAX_FORCE "
                             "(valve.contact_lift; e.g. 0.7,0.6 or 0.7,0.6,10)")
    parser.add_argument("--soft-modes", type=int, default=0, metavar="K",
                        help="also print the K softest modes of the symmetric tangent at the end (fem.soft_modes)")
    parser.add_argument("--taylor", action="store_true",
                        help="also print each term's linearisation remainder along the held stage's step at the end "
                             "(fem.taylor_test)")
    parser.add_argument("--held-projected-steps", type=int, default=HELD_PROJECTED_STEPS, metavar="N",
                        help="the held load's first stage: at most N projected steps, until its energy drop stalls "
                             "(0: none; --tr-* flags set the last stage) (default: %(default)s)")
    _add_flags(parser, OPTION_FLAGS, "", "ClosureOptions.for_model")
    parser.add_argument("--hold-papillary", action="store_true",
                        help="a variant: papillary tips held where they are (no tethering), pressure stage only")
    parser.add_argument("--method", choices=("newton", "ptc"), default="ptc",
                        help="load-stepped Newton with damped steps, or pseudo-transient continuation (default)")
    _add_flags(parser, PTC_FLAGS, "ptc-", "skvalve.valve.closure.relaxation_options")
    parser.add_argument("--held", choices=("ptc", "trust-region"), default="trust-region",
                        help="at the held load: switch to the energy trust region (default), or keep relaxing by Ψtc")
    _add_flags(parser, TR_FLAGS, "tr-", "skvalve.valve.closure.held_options")
    parser.add_argument("--input", type=Path, default=None,
                        help="another TriValve input (.inp; default: the 1.0 diseased valve, $SKVALVE_TRIVALVE)")
    args = parser.parse_args()
    if args.report and not args.resume:
        parser.error("--report needs --resume")
    if args.lift_parked is not None:
        if not args.resume or args.report:
            parser.error("--lift-parked needs --resume (and no --report)")
        try:
            level, target, *max_force = (float(value) for value in args.lift_parked.split(","))
            if len(max_force) > 1:
                raise ValueError
        except ValueError:
            parser.error(f"--lift-parked wants LEVEL,TARGET[,MAX_FORCE] (two or three numbers); got "
                         f"{args.lift_parked!r}")
    path = trivalve_input() if args.input is None else args.input
    if path is None or not Path(path).exists():
        print("Texas TriValve input not found: set $SKVALVE_TRIVALVE (Mathur et al. 2022, CC BY-NC-SA 4.0)")
        return 2
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(message)s")
    args.out.mkdir(parents=True, exist_ok=True)
    abaqus = read_model(path)
    u0, t0 = None, 0.0
    if args.resume:
        state = np.load(args.out / "last_state.npz")
        u0, t0 = state["u"], float(state["t"])
        print(f"resuming from step time {t0:.5g}", flush=True)
    model = valve_model(abaqus)
    if args.hold_papillary:  # the conditions that start moving before the pressure: the papillary tips
        pressure_start = ClosureOptions.for_model(model).pressure_start
        model.conditions = [replace(c, value=0.0) if c.amplitude is not None and c.amplitude.times[0] < pressure_start
                            and c.value != 0.0 else c for c in model.conditions]
        print("variant: papillary tips held in place (no tethering)", flush=True)
    overrides = {name: getattr(args, name) for name in ("end", *OPTION_FLAGS) if getattr(args, name) is not None}
    if overrides.get("max_increment") == 0.0:
        overrides["max_increment"] = None
    if overrides.get("contact_barrier", 0.0) < 0.0:
        overrides["contact_barrier"] = None
    for flag in ("cable_compression", "contact_loaded_faces"):
        if flag in overrides:
            overrides[flag] = bool(overrides[flag])
    if args.method == "ptc":
        options = ClosureOptions.for_relaxation(model, **overrides)
    else:
        options = ClosureOptions.for_model(model, **overrides)
    print(f"input {Path(path).name}: {options}", flush=True)
    setup = closure_setup(options=options, abaqus=abaqus, model=model)
    recorded = {"options": json.dumps(asdict(options)), "input": Path(path).name}  # kept with every state
    print("model:", setup.model.counts(), "contact faces:", setup.contact.surface.quads.shape[0], flush=True)
    if args.verbose:
        search = setup.contact.active_pairs

        def logged_search(u):
            pairs = search(u)
            logging.info("contact pairs %d", pairs.size)
            return pairs

        setup.contact.active_pairs = logged_search
    if args.lift_parked is not None:
        accept = force_limit(setup.problem, t0, max_force[0], setup.model.mesh) if max_force else None
        lift = lift_parked_nodes(setup.contact, u0, setup.model.mesh, level=level, target=target,
                                 held=closure_held_nodes(setup), accept=accept)
        u0 = lift.u
        print(f"{lift}; undamped residual after it (norm, relative): {undamped_residual(setup.problem, u0, t0)}",
              flush=True)
    if args.report:  # the kept state, measured and drawn, no solve
        run = ClosureRun(load_factors=[t0], iterations=[0], u=u0)
        setup.contact.assemble(u0, t0, False, None)
        run.contact_pairs = [setup.contact.last_pairs.touching]
        run.undamped_residual = undamped_residual(setup.problem, u0, t0)
    elif args.method == "ptc":
        ptc = {name: getattr(args, "ptc_" + name) for name in PTC_FLAGS if getattr(args, "ptc_" + name) is not None}
        if ptc.get("fill") == 0.0:
            ptc["fill"] = None
        ptc_options = relaxation_options(options.pressure_start, rtol=options.rtol, atol=options.atol, **ptc)
        if ptc:  # flags set every stage's controls
            ptc_options = [(until, replace(stage, **ptc)) for until, stage in ptc_options]
        print(f"pseudo-transient continuation: {ptc_options}", flush=True)
        held = None
        if args.held == "trust-region":
            tr = {name: getattr(args, "tr_" + name) for name in TR_FLAGS if getattr(args, "tr_" + name) is not None}
            if "project" in tr:
                tr["project"] = bool(tr["project"])
            for key in ("project_terms", "shift_terms"):
                if key in tr:
                    tr[key] = tuple(name for name in tr[key].split(",") if name)
            held = held_stages(setup, args.held_projected_steps, rtol=options.rtol, atol=options.atol, **tr)
            print(f"held load: {held}", flush=True)
        run = relax_closure(setup, options.end, ptc_options, callbacks=[LastState(args.out, recorded),
                                                                         BestState(args.out, options.end, recorded)],
                            progress=False, verbose=args.verbose, u0=u0, t0=t0, held=held)
    else:
        run = run_closure(setup, options, callbacks=[LastState(args.out, recorded)], progress=False,
                          verbose=args.verbose, u0=u0, t0=t0)
    if run.u is not None and not args.report:  # the kept state: the best held one when the relaxation gave up
        replace_atomically(args.out / "last_state.npz",
                           lambda temporary: np.savez(temporary, t=run.load_factors[-1], u=run.u, **recorded))
    write_log(run, args.out / ("report_log.txt" if args.report else "closure_log.txt"))
    print(f"wall time {run.seconds:.1f} s, load steps {len(run.load_factors) - 1}, "
          f"Newton iterations {sum(run.iterations)}, contact pairs at the end "
          f"{run.contact_pairs[-1] if run.contact_pairs else 0}, peak memory {run.peak_memory_mb:.0f} MB")
    print("where the time went (s): " + ", ".join(f"{key} {value:.1f}" for key, value in run.timings.items()))
    print(f"last converged step time {run.load_factors[-1]:.5g} of {options.end}; undamped residual "
          f"(norm, relative) {run.undamped_residual}")
    if run.negative_eigenvalues is not None:
        print(f"negative eigenvalues of the symmetric tangent at the converged state: {run.negative_eigenvalues}")
    if run.error:
        print(f"stopped: {run.error}")
    if run.u is not None:
        t = run.load_factors[-1]
        measures = closure_measures(setup, run.u, t)
        print(f"Table 2-3 measures at step time {t:.5g} (mid surface; mm², kPa): orifice "
              f"{measures.orifice['mid']:.1f}, leaflets {measures.leaflet_area['mid']:.1f}, coaptation "
              f"{measures.coaptation_area:.1f}; centre max principal Cauchy stress "
              + ", ".join(f"{name} {1e3 * value:.2f}" for name, value in measures.centre_stress.items()))
        pairs = setup.contact.active_pairs(run.u)
        depth = setup.contact.max_penetration
        deepest = np.zeros(setup.problem.space.n_scalar)
        np.maximum.at(deepest, pairs.node, np.maximum(-pairs.gap, 0.0))
        print(f"contact overlap: deepest {deepest.max(initial=0.0):.3g} mm of the search depth {depth:.3g} mm; nodes "
              f"deeper than half of it: {int((deepest > 0.5 * depth).sum())}, in its fade-out (deeper than "
              f"{DEEP_FADE} of it, where the penalty energy falls with depth): "
              f"{int((deepest > DEEP_FADE * depth).sum())}")
        mesh = setup.model.mesh
        corners = hex_corner_jacobians(mesh.p.T + run.u[: setup.problem.space.n_u].reshape(-1, 3),
                                       mesh.t.T[:, np.argsort(ABAQUS_TO_SKFEM_HEX)])  # det(dx/dxi) at each corner
        print(f"hexes with a folded corner (corner Jacobian <= 0): {int((corners <= 0.0).any(axis=1).sum())} of "
              f"{corners.shape[0]}; smallest corner Jacobian {corners.min():.3g} (det dx/dxi)")
        if args.soft_modes > 0:
            _print_soft_modes(setup, run.u, t, args.soft_modes)
        if args.taylor:
            _print_taylor(setup, run.u, t)
        ClosureWriter(args.out / "final_state.pvd", setup).write(t, run.u)
        credit = "Texas TriValve " + ("1.1" if "1.1" in str(path) else "1.0") + " (Mathur et al. 2022), " + \
                 ("CC BY 4.0" if "1.1" in str(path) else "CC BY-NC-SA 4.0")
        for figure in write_figures(setup, run.u, t, args.out, credit=credit):
            print(f"wrote {figure}")
    print(f"trivalve_closure_seconds={run.seconds:.1f}")
    return 0 if run.error is None else 1


def _print_soft_modes(setup, u: np.ndarray, t: float, count: int) -> None:
    """The ``count`` softest modes at ``u``: stiffness, residual along the mode, Newton's reach along it, and the nodes
    it moves most with their leaflet region (-1: a chordae branch point or a node of no leaflet)."""
    problem = setup.problem
    modes = soft_modes(problem, u, t, k=count)
    n_nodes = problem.space.n_scalar
    region = np.full(n_nodes, -1)
    region[: setup.leaflet_of_vertex.size] = setup.leaflet_of_vertex
    print(f"softest modes of the symmetric tangent at t={t:.5g} (stiffness N/mm, residual along it N, Newton's reach "
          "mm, the nodes it moves most with their region):")
    for j, (value, along, reach) in enumerate(zip(modes.values, modes.residual_along, modes.newton_reach,
                                                  strict=True)):
        nodes = modes.moving_nodes(j, problem.space.dim, n_nodes, count=5)
        print(f"  mode {j}: {value:.3e}  {along:+.3e}  {reach:+.3g}  nodes "
              + ", ".join(f"{node} ({region[node]})" for node in nodes))


def _print_taylor(setup, u: np.ndarray, t: float, shift: float = 0.01) -> None:
    """Each term's linearisation remainder (fem.taylor_test) along the held stage's step at ``u``: the symmetric
    tangent with the contact's indefinite blocks shifted, plus ``shift`` times its median diagonal, solved for -R."""
    problem = setup.problem
    free = problem.pattern.free
    residual, tangent = problem.assemble(u, t)
    problem.commit()  # the state a held step starts from (the contact's facing factors are taken there)
    matrix = step_matrix(problem, tangent, project=False, shifted=("contact",))
    diagonal = np.abs(matrix.diagonal())
    matrix = matrix + shift * float(np.median(diagonal[diagonal > 0])) * sp.identity(matrix.shape[0], format="csr")
    direction = np.zeros(problem.space.n_dofs)
    direction[free] = linsolve.solve(matrix.tocsr(), -residual[free], symmetric=True)
    region = np.full(problem.space.n_scalar, -1)
    region[: setup.leaflet_of_vertex.size] = setup.leaflet_of_vertex
    print(f"linearisation remainders along the held step (|R_f| {np.linalg.norm(residual[free]):.3e} N; step length = "
          "largest nodal motion, mm; the nodes with the largest remainder and their region):")
    for term in taylor_test(problem, u, t, direction, lengths=(0.003, 0.01, 0.03, 0.1)):
        cells = ", ".join(f"{h:g}: {e:.2e}" for h, e in zip(term.lengths, term.errors, strict=True))
        print(f"  {term.name:18s} {cells}; orders {np.round(term.orders, 2).tolist()}; at 0.01 mm nodes "
              + ", ".join(f"{node} ({region[node]})" for node in term.worst_nodes[1]))


if __name__ == "__main__":
    sys.exit(main())
