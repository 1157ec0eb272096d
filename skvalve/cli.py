"""Command-line interface: ``skvalve materials`` and ``skvalve reproduce <paper>``."""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

PAPERS = ("buchanan2014", "thomas2019", "mathur2022")


def _cmd_materials(args: argparse.Namespace) -> int:
    from .materials.catalogue import main as materials_main

    return materials_main(out=Path(args.out), show=not args.no_plot)


def _cmd_reproduce(args: argparse.Namespace) -> int:
    try:
        module = importlib.import_module(f"skvalve.papers.{args.paper}")
    except ModuleNotFoundError as err:
        if err.name == f"skvalve.papers.{args.paper}":
            print(f"skvalve: paper {args.paper!r} is not reproduced yet", file=sys.stderr)
            return 2
        raise
    from .papers.table import print_table

    out = Path(args.out)
    rows = module.reproduce(out=out, full=args.full)
    print_table(rows, title=f"skvalve reproduce {args.paper}")
    n_ok = sum(row.ok for row in rows)
    print(
        f"\n{n_ok} of {len(rows)} quantities within tolerance of the paper; the note under each other row "
        f"says why it differs. Figures: {out}/"
    )
    # A disagreement with a paper is a finding, not a crash: only --strict turns it into exit 1.
    return 1 if args.strict and n_ok < len(rows) else 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="skvalve", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    mat = sub.add_parser("materials", help="list the material laws with the papers' parameters and plot them")
    mat.add_argument("--out", default="skvalve_out/materials", help="folder for the figures")
    mat.add_argument("--no-plot", action="store_true", help="print the table only")
    mat.set_defaults(func=_cmd_materials)

    rep = sub.add_parser("reproduce", help="reproduce a paper's tables and figures")
    rep.add_argument("paper", choices=PAPERS)
    rep.add_argument("--out", default="skvalve_out", help="folder for the figures")
    rep.add_argument("--full", action="store_true", help="converged meshes (slow)")
    rep.add_argument("--strict", action="store_true", help="exit 1 if any quantity is outside its tolerance")
    rep.set_defaults(func=_cmd_reproduce)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
