"""``skvalve reproduce mathur2022``: Tables 2–3 of the diseased Texas TriValve 1.0 at end-systole.

Default run (a few minutes): reads the shipped diseased input, builds the implicit model (F-bar leaflet
hexes, collapsed chordae cables, amplitudes, follower pressure, leaflet self-contact) and compares the
**orifice area** with Table 2: the input holds the ring of nodes one leaflet thickness (0.78 mm) from the
annulus node set, so the orifice of the open configuration is, to within the motion of that thin rim, the
end-systolic one; it measures the leaflet areas of the open configuration (reported beside the paper's
end-systolic values, with that difference stated). It does **not** close the valve: on 2 cores the full
closure takes far longer than a default run (``benchmarks/trivalve_closure.py``).

``full=True``: the implicit closure from the open configuration to end-systole by pseudo-transient continuation
(:func:`skvalve.valve.closure.relax_closure`), relaxed at the held load by the energy trust region
(:mod:`skvalve.fem.trust_region`), and all Table 2 (orifice, leaflet, coaptation area) and
Table 3 (centre stresses) rows of the diseased column, with a VTU series and the figures of
:mod:`skvalve.papers.mathur2022.figures` in ``out``. When the closure stops
early, the rows are those of the last converged state, marked with the step time reached.

The model files (Mathur et al. 2022, CC BY-NC-SA 4.0) are never copied; without them the run ends with a
message and exit code 2 (``$SKVALVE_TRIVALVE`` names the .inp file or its folder).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ...io.abaqus import read_model, trivalve_input
from ...valve.closure import (
    ClosureOptions,
    closure_setup,
    write_log,
)
from ...valve.model import valve_model
from ...valve.outputs import ClosureWriter, closure_measures
from ...valve.relaxation import (
    EveryLoadFactor,
    held_stages,
    relax_closure,
    relaxation_options,
)
from ..table import Reason, Row, Stage, Written
from .data import CREDIT, TABLE2_AREAS, TABLE3_CENTRE_STRESS
from .figures import write_figures

__all__ = ["DESCRIPTION", "reproduce", "EXIT_NO_INPUT"]

DESCRIPTION = "Tables 2–3 (diseased column) of the Texas TriValve 1.0 closed implicitly with leaflet contact"
EXIT_NO_INPUT = 2
MPA_TO_KPA = 1e3
SURFACE = "mid"  # which leaflet surface the areas are measured on (the paper does not say)


def _require_input() -> Path:
    path = trivalve_input()
    if path is None:
        print("skvalve reproduce mathur2022: the Texas TriValve 1.0 input (Diseased_QuasiStatic.inp) was not found. "
              "Set $SKVALVE_TRIVALVE to the .inp file or its folder (model files of " + CREDIT + ", "
              "not shipped with skvalve).", file=sys.stderr)
        raise SystemExit(EXIT_NO_INPUT)
    return path


def reproduce(out: Path | None = None, full: bool = False) -> Iterator[Row | Stage | Written]:
    """Yield the Table 2–3 rows (module docstring); exits with code 2 when the shipped input is absent."""
    path = _require_input()
    yield Stage(f"reading {path.name} and building the implicit model with contact ({CREDIT})")
    abaqus = read_model(path)
    model = valve_model(abaqus)
    options = ClosureOptions.for_relaxation(model)
    setup = closure_setup(options=options, abaqus=abaqus, model=model)
    yield Stage("Table 2 measures of the open (reference) configuration")
    reference = closure_measures(setup, np.zeros(setup.problem.space.n_dofs), 0.0)
    yield Row("Table 2 orifice area, diseased (mm²; annulus held)", TABLE2_AREAS["orifice"].diseased,
              reference.orifice[SURFACE], 0.03, relative=True,
              note="annulus loop of the mid surface projected on its best-fit plane, open configuration; the input "
                   "holds the ring 0.78 mm across the thickness from the annulus set, so it barely moves")
    if not full:
        yield Row("Table 2 leaflet area, diseased (mm²; open configuration)", TABLE2_AREAS["leaflet"].diseased,
                  reference.leaflet_area[SURFACE], 0.05, relative=True, expected_difference=Reason.MODEL_DIFFERENCE,
                  note="mid-surface area of the open, unloaded leaflets: the default run does not close the valve "
                       "(use --full); the paper's value is at end-systole")
        return
    yield Stage("implicit closure by pseudo-transient continuation: papillary motion 0-0.5, pressure 0.5-1.5, "
                "then an energy trust region at the held load (long: see benchmarks/trivalve_closure.py)")
    writer = None if out is None else ClosureWriter(Path(out) / "mathur2022_closure.pvd", setup)
    callbacks = [] if writer is None else [EveryLoadFactor(writer, 0.05)]
    controls = relaxation_options(options.pressure_start, rtol=options.rtol, atol=options.atol)
    held = held_stages(setup, rtol=options.rtol, atol=options.atol)  # the held load: energy trust region, staged
    run = relax_closure(setup, options.end, controls, callbacks=callbacks, progress=True, held=held)
    reached = run.load_factors[-1] if run.load_factors else 0.0
    if out is not None:
        write_log(run, Path(out) / "mathur2022_closure_log.txt")
        if run.u is not None:
            writer.write(reached, run.u)  # the last state, whatever the sampling kept
    complete = run.error is None and reached >= options.end
    state = "end-systole" if complete else f"stopped at step time {reached:.3g} of 1.5 ({run.error})"
    yield Stage(f"closure {state}; undamped residual (norm, relative) {run.undamped_residual}")
    if out is not None and run.u is not None:
        yield from (Written(path) for path in write_figures(setup, run.u, reached, out))
    measures = closure_measures(setup, run.u, reached)
    reason = None if complete else Reason.MODEL_DIFFERENCE
    suffix = "" if complete else f"; closure incomplete: {state}"
    yield Row("Table 2 leaflet area, diseased (mm²)", TABLE2_AREAS["leaflet"].diseased,
              measures.leaflet_area[SURFACE], 0.1, relative=True, expected_difference=reason,
              note="mid surface of all leaflets" + suffix if reason else "")
    yield Row("Table 2 coaptation area, diseased (mm²)", TABLE2_AREAS["coaptation"].diseased,
              measures.coaptation_area, 0.3, relative=True, expected_difference=Reason.MODEL_DIFFERENCE,
              note="faces of the contact surface with positive penalty pressure (both sides, as CAREA); "
                   "frictionless penalty contact, not Abaqus's kinematic contact" + suffix)
    for name, value in measures.centre_stress.items():
        leaflet = name.lower()
        yield Row(f"Table 3 centre max principal Cauchy stress, {leaflet}, diseased (kPa)",
                  TABLE3_CENTRE_STRESS[leaflet].diseased, value * MPA_TO_KPA, 0.25, relative=True,
                  expected_difference=Reason.MODEL_DIFFERENCE,
                  note="mean over the hexes at the leaflet centre region (10 % of the leaflet's mid-surface area, "
                       "the paper's Fig. 4d region is not given in numbers); quasi-static implicit vs explicit "
                       "dynamics with mass scaling" + suffix)

