"""Benchmark: one call of :func:`skvalve.valve.run.close_valve` on a Texas TriValve input, timed and split.

Closes ``--input`` (default the 1.0 diseased valve, :func:`skvalve.io.abaqus.trivalve_input`) with the defaults of
:mod:`skvalve.valve.options` from the open valve (or ``--resume`` from ``--out/state.npz``) to ``--end`` (default the
input's step time, then the held load; an earlier ``--end`` runs the load path only). Prints the machine's load
before and after (the machine may be shared), wall time, path and held steps, iterations, cut-backs, final static
residual, intersection, smallest corner Jacobian, contact pairs and where the time went, measured by wrapping the
calls with timers (no profiler): each term's assembly and energy by term type, the tangent's assembly (of which its
pattern's growths), CCD (``IPCContact.step_fraction``), the intersection checks and the collision counts of the step
records, and the pattern set-up, factorisation (of which PARDISO's reordering, once per new pattern) and solve of
:class:`skvalve.fem.solvers.linsolve.LinearSolver`. Target for the 1.0 diseased
valve from the open state: <= 1800 s on 2 cores. Needs the input (``$SKVALVE_TRIVALVE``; Mathur et al. 2022, CC BY-NC-SA
4.0); exits 2 without it.

Last line: ``trivalve_closure_seconds=<x>`` (the wall time of the set-up and ``close_valve``).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections import defaultdict
from pathlib import Path

from skvalve.fem.solvers.linsolve import LinearSolver
from skvalve.fem.sparse_layout import GrowingPattern
from skvalve.io.abaqus import trivalve_input
from skvalve.valve.options import CloseOptions, HoldOptions
from skvalve.valve.run import STATE_FILE, CloseReport, ClosureFailed, close_valve
from skvalve.valve.setup import valve_setup
from skvalve.valve.state import KeptState, StateError, read_state

EXIT_NO_INPUT = 2
EXIT_INTERRUPTED = 130


def load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} (1, 5, 15 min) on {os.cpu_count()} cores"


class Timers:
    """Seconds and calls per label, accumulated by wrapped callables (:meth:`wrap`)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self.within: dict[str, str] = {}  # a nested label -> the label whose time includes it

    def wrap(self, owner, name: str, label: str, within: str | None = None) -> None:
        """Replace ``owner.name`` (an instance's method or a class's function) by a timed call of it; ``within``: the
        label of the wrapped call that makes this one (its time is a part of that label's, listed under it)."""
        original = getattr(owner, name)
        if within is not None:
            self.within[label] = within

        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                self.seconds[label] += time.perf_counter() - start
                self.calls[label] += 1

        setattr(owner, name, timed)

    def lines(self, wall: float) -> list[str]:
        """One line per label, largest first, and the rest of ``wall`` (controller, line-search arithmetic, output)."""
        rows = sorted(((label, seconds) for label, seconds in self.seconds.items() if label not in self.within),
                      key=lambda item: -item[1])
        out = []
        for label, seconds in rows:
            out.append(f"  {label:44s} {seconds:9.1f} s {100 * seconds / wall:5.1f} %  {self.calls[label]:7d} calls")
            for part, parent in self.within.items():
                if parent == label and part in self.seconds:
                    share = self.seconds[part]
                    out.append(f"    {'of which ' + part:42s} {share:9.1f} s {100 * share / wall:5.1f} %  "
                               f"{self.calls[part]:7d} calls")
        rest = wall - sum(seconds for label, seconds in self.seconds.items() if label not in self.within)
        out.append(f"  {'other (controller, vector algebra, output)':44s} {rest:9.1f} s {100 * rest / wall:5.1f} %")
        return out


def instrument(setup, timers: Timers) -> None:
    """Wrap the calls whose time is reported (the wrapped calls do not nest: their sums add up)."""
    for term in setup.problem.terms:
        kind = type(term).__name__
        timers.wrap(term, "assemble", f"assembly {kind}")
        if getattr(term, "energy", None) is not None:
            timers.wrap(term, "energy", f"energy {kind}")
    tangent = "tangent assembly (Problem.tangent_matrix)"
    timers.wrap(setup.problem, "tangent_matrix", tangent)
    timers.wrap(GrowingPattern, "_insert", "pattern growth (GrowingPattern)", within=tangent)
    timers.wrap(setup.contact, "step_fraction", "CCD (IPCContact.step_fraction)")
    timers.wrap(setup.contact, "intersects", "intersection checks (IPCContact.intersects)")
    timers.wrap(setup.contact, "active_pairs", "collision counts (IPCContact.active_pairs)")
    timers.wrap(LinearSolver, "analyse", "linsolve pattern (LinearSolver.analyse)")
    timers.wrap(LinearSolver, "factorize", "linsolve factorisation")
    timers.wrap(LinearSolver, "_reorder_pardiso", "PARDISO reordering (phase 11)", within="linsolve factorisation")
    timers.wrap(LinearSolver, "solve", "linsolve solve")


def progress_line(state: KeptState) -> None:
    """One line per accepted step (the callback of :func:`close_valve`)."""
    print(f"  {state.phase:4s} step {state.steps}+{state.held_steps}: t={state.t:.6g} next={state.increment:.3g} "
          f"iterations so far {state.iterations}, relative residual {state.relative_residual:.3e}", flush=True)


def print_report(report: CloseReport, path_only: bool) -> None:
    print(f"wall time of close_valve {report.seconds:.1f} s; {report.steps} path steps, {report.held_steps} held "
          f"steps, {report.iterations} iterations, {report.failed_steps} cut-backs")
    state = "load path only" if path_only else "converged" if report.converged else "not converged"
    print(f"final step time {report.t:.6g} ({state}); relative "
          f"residual {report.relative_residual:.3e}; intersection {'YES' if report.intersects else 'none'}; smallest "
          f"corner Jacobian {report.smallest_jacobian:.3g}; contact pairs {report.contact_pairs}, contact area "
          f"{report.contact_area:.1f} mm^2")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--input", type=Path, default=None,
                        help="Texas TriValve input (.inp; default: the 1.0 diseased valve, $SKVALVE_TRIVALVE)")
    parser.add_argument("--out", type=Path, default=Path("trivalve_closure_out"),
                        help="folder of state.npz, closure.log and closure.pvd")
    parser.add_argument("--resume", action="store_true", help="continue from --out/state.npz (its own options)")
    parser.add_argument("--end", type=float, default=None,
                        help="last step time (default: the input's step time); before it, the load path only")
    args = parser.parse_args()
    path = trivalve_input() if args.input is None else args.input
    if path is None or not Path(path).is_file():
        print(f"Texas TriValve input not found ({path or 'searched $SKVALVE_TRIVALVE and ../shared/data'}): set "
              "$SKVALVE_TRIVALVE or give --input (Mathur et al. 2022, CC BY-NC-SA 4.0)", file=sys.stderr)
        return EXIT_NO_INPUT
    print(f"machine at the start: {load()}", flush=True)
    clock = time.perf_counter()
    try:
        options = read_state(args.out / STATE_FILE, input_name=Path(path).name).options if args.resume else None
    except StateError as err:
        print(f"cannot resume: {err}", file=sys.stderr)
        return EXIT_NO_INPUT
    if args.resume and args.end is not None and args.end != options.end:
        print(f"--end {args.end} ignored: a resumed run keeps its state's options (end {options.end})")
    setup = valve_setup(path, options)
    if options is None:
        partial = args.end is not None and args.end < setup.model.end_time
        options = CloseOptions(end=args.end, hold=HoldOptions(max_steps=0) if partial else HoldOptions())
        if partial:
            print(f"--end {args.end} before the input's end {setup.model.end_time}: the load path only (the held "
                  "phase solves the end load)", flush=True)
    set_up = time.perf_counter() - clock
    print(f"input {setup.input_name}: {setup.problem.space.n_dofs} dofs, terms "
          f"{', '.join(type(term).__name__ for term in setup.problem.terms)}; set-up {set_up:.1f} s; end "
          f"{options.end if options.end is not None else setup.model.end_time}", flush=True)
    timers = Timers()
    timers.seconds["set-up (read, model, contact)"], timers.calls["set-up (read, model, contact)"] = set_up, 1
    instrument(setup, timers)
    status = 0
    try:
        report = close_valve(path, options, out=args.out, resume=args.resume, progress=False, setup=setup,
                             callbacks=[progress_line])
        print_report(report, options.hold.max_steps == 0)
    except ClosureFailed as err:
        print(f"stopped: {err}")
        status = 1
    except KeyboardInterrupt:
        print(f"\ninterrupted; continue with --resume --out {args.out}")
        status = EXIT_INTERRUPTED
    wall = time.perf_counter() - clock
    print(f"where the time went (wall time {wall:.1f} s):")
    print("\n".join(timers.lines(wall)))
    print(f"machine at the end: {load()}")
    print(f"trivalve_closure_seconds={wall:.1f}")
    return status


if __name__ == "__main__":
    sys.exit(main())
