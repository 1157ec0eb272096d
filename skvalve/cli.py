"""Command-line interface: ``skvalve materials``, ``skvalve reproduce <paper>``, ``skvalve valve info|close FILE``.

Exit codes: 0 done; 1 ``--strict`` and a row is a regression or an unexplained disagreement; 2 bad
arguments, an unusable ``--out``, a paper not available yet, its input data not found (a
``FileNotFoundError`` from ``reproduce``) or a ``--state`` file it cannot use (``InputError``); 130 interrupted
(Ctrl-C).
The heavy modules (numpy, scikit-fem, matplotlib, the papers) are imported inside the commands, so
``skvalve --help`` and ``--version`` start fast — the one place skvalve imports inside functions.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import sys
import tempfile
import time
from pathlib import Path

from . import __version__
from .papers.registry import PAPERS, Paper
from .papers.table import InputError, Row, Stage, Status, Written, format_header, format_row

EXIT_STRICT, EXIT_USAGE, EXIT_INTERRUPTED = 1, 2, 130


def _error(message: str) -> int:
    print(f"skvalve: {message}", file=sys.stderr)
    return EXIT_USAGE


def check_out(out: Path) -> str | None:
    """Create the output folder ``out`` if needed and check that it is writable; the problem, or None."""
    if out.exists() and not out.is_dir():
        return f"--out {out} exists and is not a folder"
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as err:
        return f"--out {out} is not a writable folder ({err.strerror or err})"
    return None


def _cmd_materials(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if not args.no_plot and (problem := check_out(out)):
        return _error(problem)
    from .papers.catalogue import catalogue, print_catalogue

    entries = catalogue()
    print_catalogue(entries)
    if not args.no_plot:
        from .papers.catalogue_figures import write_catalogue_figures

        for path in write_catalogue_figures(entries, out):
            print(f"wrote {path}")
    return 0


def _load_reproduce(paper: Paper):
    """The paper's ``reproduce`` function, or None when its module does not exist yet."""
    try:
        module = importlib.import_module(paper.module)
    except ModuleNotFoundError as err:
        parents = {paper.module.rsplit(".", k)[0] for k in range(2)}
        if err.name in parents:
            return None
        raise
    return module.reproduce


def _summary(rows: list[Row]) -> str:
    count = {status: sum(r.status is status for r in rows) for status in Status}
    return (f"{len(rows)} rows: {count[Status.AGREES]} agree within tolerance, {count[Status.DIFFERS]} differ for "
            f"the reason in their note, {count[Status.UNEXPLAINED]} unexplained, "
            f"{count[Status.REGRESSION]} regressions")


def _cmd_reproduce(args: argparse.Namespace) -> int:
    paper = PAPERS[args.paper]
    reproduce = _load_reproduce(paper)
    if reproduce is None:
        return _error(f"reproduce {paper.key} is not available yet. When it is, it will compute: {paper.plan} "
                      f"({paper.citation}).")
    out = Path(args.out)
    if problem := check_out(out):
        return _error(problem)
    rows: list[Row] = []
    written: list[Path] = []
    start = time.perf_counter()
    print(f"skvalve reproduce {paper.key}{' --full' if args.full else ''}: {paper.citation}")
    print(format_header(), flush=True)
    extra = {}
    if args.state is not None:
        if "state" not in inspect.signature(reproduce).parameters:
            return _error(f"reproduce {paper.key} does not take --state (only papers whose full runs take hours do)")
        extra["state"] = Path(args.state)
    try:
        for item in reproduce(out=out, full=args.full, **extra):
            if isinstance(item, Row):
                rows.append(item)
                print(format_row(item), flush=True)
            elif isinstance(item, Stage):
                print(f"[{time.perf_counter() - start:6.1f} s] {item.text} ...", file=sys.stderr, flush=True)
            elif isinstance(item, Written):
                written.append(item.path)
                print(f"[{time.perf_counter() - start:6.1f} s] wrote {item.path}", file=sys.stderr, flush=True)
    except (FileNotFoundError, InputError) as err:  # data not shipped with skvalve, or a kept state it cannot use
        return _error(f"reproduce {paper.key}: {err}")
    except KeyboardInterrupt:
        figures = ", ".join(p.name for p in written) or "none"
        print(f"\nskvalve: interrupted after {time.perf_counter() - start:.0f} s. Finished: {len(rows)} rows "
              f"(printed above), figures: {figures}.", file=sys.stderr)
        return EXIT_INTERRUPTED
    print(f"\n{_summary(rows)}. Reference column: the paper's value, or * an exact one. Figures: {out}/")
    failing = [r.quantity for r in rows if r.status.fails_strict]
    if args.strict and failing:
        print(f"skvalve: --strict: {len(failing)} rows are regressions or unexplained: {'; '.join(failing)}",
              file=sys.stderr)
        return EXIT_STRICT
    return 0


def _cmd_valve_info(args: argparse.Namespace) -> int:
    path = Path(args.file)
    if not path.is_file():
        return _error(f"valve info: {path} is not a file (give an Abaqus .inp, e.g. "
                      "../shared/data/texas_trivalve/Diseased_QuasiStatic.inp)")
    out = Path(args.out)
    if problem := check_out(out):
        return _error(problem)
    from .io.abaqus import AbaqusParseError
    from .valve.info import valve_info

    try:
        summary = valve_info(path, out)
    except AbaqusParseError as err:
        return _error(str(err))
    print(summary.to_text())
    for written in summary.outputs:
        print(f"wrote {written}")
    return 0


def _cmd_valve_close(args: argparse.Namespace) -> int:
    path = Path(args.file)
    if not path.is_file():
        return _error(f"valve close: {path} is not a file (give an Abaqus .inp, e.g. "
                      "../shared/data/texas_trivalve/Diseased_QuasiStatic.inp)")
    out = Path(args.out)
    if problem := check_out(out):
        return _error(problem)
    from .io.abaqus import AbaqusParseError
    from .valve.options import CloseOptions
    from .valve.run import ClosureFailed, close_valve
    from .valve.state import StateError
    from .valve.support import UnsupportedInputError

    options = CloseOptions(end=args.end)
    try:
        report = close_valve(path, options, out=out, resume=args.resume, progress=not args.quiet)
    except (AbaqusParseError, UnsupportedInputError, StateError) as err:
        return _error(f"valve close: {err}")
    except ClosureFailed as err:
        print(f"skvalve: valve close: {err}\nThe last accepted state is kept in {out / 'state.npz'}.",
              file=sys.stderr)
        return EXIT_STRICT
    except KeyboardInterrupt:
        print(f"\nskvalve: valve close interrupted; resume with: skvalve valve close {path} --out {out} --resume",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    print(report.summary())
    print(f"wrote {out / 'state.npz'}, {out / 'closure.log'}, {out / 'closure.pvd'}")
    return 0 if report.converged else EXIT_STRICT


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="skvalve", description=__doc__.split("\n")[0])
    parser.add_argument("--version", action="version", version=f"skvalve {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    mat = sub.add_parser("materials", help="list the material laws with the papers' parameters and plot them")
    mat.add_argument("--out", default="skvalve_out/materials", help="folder for the figures")
    mat.add_argument("--no-plot", action="store_true", help="print the table only")
    mat.set_defaults(func=_cmd_materials)

    lines = "\n".join(f"  {p.key}: {p.plan}" for p in PAPERS.values())
    rep = sub.add_parser("reproduce", help="reproduce a paper's tables and figures",
                         description=f"Reproduce a paper's tables and figures.\n\n{lines}",
                         formatter_class=argparse.RawDescriptionHelpFormatter)
    rep.add_argument("paper", choices=list(PAPERS))
    rep.add_argument("--out", default="skvalve_out", help="folder for the figures (created; must be writable)")
    rep.add_argument("--full", action="store_true", help="converged meshes and complete sweeps (slow)")
    rep.add_argument("--state", default=None, metavar="FILE",
                     help="mathur2022: measure a kept closure state (the state.npz of skvalve valve close) "
                          "instead of running the closure")
    rep.add_argument("--strict", action="store_true",
                     help="exit 1 if a row is a regression or an unexplained disagreement with the paper")
    rep.set_defaults(func=_cmd_reproduce)

    valve = sub.add_parser("valve", help="whole-valve models read from Abaqus inputs")
    valve_sub = valve.add_subparsers(dest="valve_command", required=True)
    info = valve_sub.add_parser("info", help="summarise an Abaqus valve input and draw the undeformed valve")
    info.add_argument("file", help="Abaqus input (.inp), e.g. a Texas TriValve model")
    info.add_argument("--out", default="skvalve_out/valve_info", help="folder for summary.txt and undeformed.png")
    info.set_defaults(func=_cmd_valve_info)
    close = valve_sub.add_parser("close", help="close a valve: open configuration to the converged end-systolic state",
                                 description="Close a Texas TriValve input with the defaults of "
                                             "skvalve.valve.options (IPC contact, incremental-potential steps, the "
                                             "held load solved to 1e-6).")
    close.add_argument("file", help="Abaqus input (.inp), e.g. ../shared/data/texas_trivalve/Diseased_QuasiStatic.inp")
    close.add_argument("--out", default="skvalve_out/valve_close",
                       help="folder for state.npz (kept after every step), closure.log and closure.pvd")
    close.add_argument("--resume", action="store_true", help="continue from --out/state.npz (its own options)")
    close.add_argument("--end", type=float, default=None, help="last step time (default: the input's step time)")
    close.add_argument("--quiet", action="store_true", help="no progress bar")
    close.set_defaults(func=_cmd_valve_close)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:  # reproduce reports its own progress; this catches the other commands
        print("\nskvalve: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
