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

``state=FILE`` (``skvalve reproduce mathur2022 --state FILE``): the same rows for a kept state of a closure run
(``benchmarks/trivalve_closure.py`` writes ``last_state.npz`` and ``best_state.npz``: step time ``t``, displacement
``u`` and, from this version on, the run's ``ClosureOptions`` as JSON ``options`` and its ``input`` file's name,
checked against the diseased input: the repairs share its mesh), without solving; the
undamped residual of the state is printed, and a state short of the end time or above the residual asked for is
marked incomplete. A state without ``options`` is measured with :data:`KEPT_STATE_OPTIONS`, those with which the
held 1.0 diseased valve converged (docs/mathur2022.md).

The model files (Mathur et al. 2022, CC BY-NC-SA 4.0) are never copied; without them the run ends with a
message and exit code 2 (``$SKVALVE_TRIVALVE`` names the .inp file or its folder).
"""

from __future__ import annotations

import json
import sys
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...fem.damping import undamped_residual
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
from ..table import InputError, Reason, Row, Stage, Written
from .data import CREDIT, TABLE2_AREAS, TABLE3_CENTRE_STRESS
from .figures import write_figures

__all__ = ["DESCRIPTION", "EXIT_NO_INPUT", "KEPT_STATE_OPTIONS", "KeptState", "read_kept_state", "reproduce"]

DESCRIPTION = "Tables 2–3 (diseased column) of the Texas TriValve 1.0 closed implicitly with leaflet contact"
EXIT_NO_INPUT = 2
MPA_TO_KPA = 1e3
SURFACE = "mid"  # which leaflet surface the areas are measured on (the paper does not say)
#: ClosureOptions overrides for a kept state that does not list its own: the contact with which the held 1.0 diseased
#: valve converged (search depth half the leaflet, depth barrier from 0.4 of it, the loaded skins in contact).
KEPT_STATE_OPTIONS = {"contact_depth": 0.2, "contact_barrier": 0.4, "contact_loaded_faces": True}


@dataclass
class KeptState:
    """A closure state kept on disk: step time, displacement and the ClosureOptions fields it was computed with (None
    when the file does not record them)."""

    t: float
    u: np.ndarray
    options: dict | None
    input: str | None = None  # the name of the input file the state was computed from, when recorded

    def closure_options(self, model) -> ClosureOptions:
        """The recorded options, or :meth:`ClosureOptions.for_relaxation` with :data:`KEPT_STATE_OPTIONS`."""
        if self.options is None:
            return ClosureOptions.for_relaxation(model, **KEPT_STATE_OPTIONS)
        return ClosureOptions(**{key: tuple(value) if isinstance(value, list) else value
                                 for key, value in self.options.items()})


def read_kept_state(path: Path) -> KeptState:
    """Read ``t``, ``u``, ``options`` (JSON of the ClosureOptions fields) and ``input`` (the input file's name; both
    None when absent) from an ``.npz`` file; :class:`InputError` naming the file for anything else."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"kept state {path} not found (benchmarks/trivalve_closure.py writes "
                                "last_state.npz and best_state.npz in its --out folder)")
    try:
        with np.load(path, allow_pickle=False) as data:
            missing = {"t", "u"} - set(data.files)
            if missing:
                raise InputError(f"kept state {path}: no {', '.join(sorted(missing))} in it (has {data.files})")
            t, u = float(data["t"]), np.asarray(data["u"], dtype=float)
            options = json.loads(str(data["options"])) if "options" in data.files else None
            source = str(data["input"]) if "input" in data.files else None
    except InputError:
        raise
    except (OSError, ValueError, zipfile.BadZipFile) as err:
        raise InputError(f"kept state {path}: not a readable .npz state ({err})") from err
    if u.ndim != 1 or not np.all(np.isfinite(u)) or not np.isfinite(t):
        raise InputError(f"kept state {path}: t and u must be finite and u one-dimensional")
    if options is not None and not isinstance(options, dict):
        raise InputError(f"kept state {path}: options must be a JSON object of ClosureOptions fields")
    return KeptState(t, u, options, source)


def _require_input() -> Path:
    path = trivalve_input()
    if path is None:
        print("skvalve reproduce mathur2022: the Texas TriValve 1.0 input (Diseased_QuasiStatic.inp) was not found. "
              "Set $SKVALVE_TRIVALVE to the .inp file or its folder (model files of " + CREDIT + ", "
              "not shipped with skvalve).", file=sys.stderr)
        raise SystemExit(EXIT_NO_INPUT)
    return path


def reproduce(out: Path | None = None, full: bool = False,
              state: Path | None = None) -> Iterator[Row | Stage | Written]:
    """Yield the Table 2–3 rows (module docstring); exits with code 2 when the shipped input is absent."""
    path = _require_input()
    kept = read_kept_state(state) if state is not None else None
    if kept is not None and kept.input is not None and kept.input != path.name:
        raise InputError(f"kept state {state} was computed from {kept.input}, not {path.name} (Table 2-3 rows here "
                         "are of the diseased valve; measure other valves with benchmarks/trivalve_closure.py "
                         "--resume --report --input FILE)")
    yield Stage(f"reading {path.name} and building the implicit model with contact ({CREDIT})")
    abaqus = read_model(path)
    model = valve_model(abaqus)
    try:
        options = ClosureOptions.for_relaxation(model) if kept is None else kept.closure_options(model)
    except (TypeError, ValueError) as err:
        raise InputError(f"kept state {state}: its options do not make ClosureOptions ({err})") from err
    setup = closure_setup(options=options, abaqus=abaqus, model=model)
    if kept is not None and kept.u.size != setup.problem.space.n_dofs:
        raise InputError(f"kept state {state}: u has {kept.u.size} values, the model of {path.name} has "
                         f"{setup.problem.space.n_dofs} dofs (a state of another valve?)")
    yield Stage("Table 2 measures of the open (reference) configuration")
    reference = closure_measures(setup, np.zeros(setup.problem.space.n_dofs), 0.0)
    yield Row("Table 2 orifice area, diseased (mm²; annulus held)", TABLE2_AREAS["orifice"].diseased,
              reference.orifice[SURFACE], 0.03, relative=True,
              note="annulus loop of the mid surface projected on its best-fit plane, open configuration; the input "
                   "holds the ring 0.78 mm across the thickness from the annulus set, so it barely moves")
    if kept is not None:
        residual = undamped_residual(setup.problem, kept.u, kept.t)
        complete = kept.t >= options.end and residual[1] <= options.rtol
        state_text = (f"kept state {Path(state).name} at step time {kept.t:.3g}, relative residual {residual[1]:.3g}"
                      f" ({'converged' if complete else 'not converged: rtol ' + format(options.rtol, 'g')})")
        source = f"input {kept.input}" if kept.input else f"input not recorded in the state: taken to be {path.name}"
        yield Stage(f"{state_text}; {source}; contact {options.contact_depth} mm deep, barrier "
                    f"{options.contact_barrier}, loaded skins {options.contact_loaded_faces}")
        if out is not None:
            ClosureWriter(Path(out) / "mathur2022_kept_state.pvd", setup).write(kept.t, kept.u)
            yield Written(Path(out) / "mathur2022_kept_state.pvd")
            yield from (Written(p) for p in write_figures(setup, kept.u, kept.t, out))
        yield from _closure_rows(closure_measures(setup, kept.u, kept.t), reference, options, complete, state_text)
        return
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
    reached_text = "end-systole" if complete else f"stopped at step time {reached:.3g} of 1.5 ({run.error})"
    yield Stage(f"closure {reached_text}; undamped residual (norm, relative) {run.undamped_residual}")
    if out is not None and run.u is not None:
        yield from (Written(path) for path in write_figures(setup, run.u, reached, out))
    yield from _closure_rows(closure_measures(setup, run.u, reached), reference, options, complete,
                             "closure incomplete: " + reached_text)


def _closure_rows(measures, reference, options: ClosureOptions, complete: bool, state: str) -> Iterator[Row]:
    """The end-systolic Table 2–3 rows of a closed (or, marked ``state``, incomplete) valve; ``reference``: the
    measures of the open configuration."""
    suffix = "" if complete else f"; {state}"
    yield Row("Table 2 orifice area, diseased (mm²; closed valve)", TABLE2_AREAS["orifice"].diseased,
              measures.orifice[SURFACE], 0.03, relative=True,
              note="annulus loop of the mid surface at the closed state, projected on its best-fit plane" + suffix)
    paper_area = TABLE2_AREAS["leaflet"].diseased
    open_area = reference.leaflet_area[SURFACE]
    yield Row("Table 2 leaflet area, diseased (mm²)", paper_area, measures.leaflet_area[SURFACE], 0.1, relative=True,
              expected_difference=Reason.MODEL_DIFFERENCE,
              note=f"mid surface of all leaflets; areal stretch from the open configuration ({open_area:.0f} mm²) "
                   f"{measures.leaflet_area[SURFACE] / open_area:.2f} here against {paper_area / open_area:.2f} in "
                   "the paper: the implicit equilibrium carries the whole pressure without the explicit run's "
                   "inertia and bulk viscosity, and the paper does not say which surface it measured" + suffix)
    skins = "inner and pressure-loaded skins" if options.contact_loaded_faces else "inner skins, as the input's pairs"
    yield Row("Table 2 coaptation area, diseased (mm²)", TABLE2_AREAS["coaptation"].diseased,
              measures.coaptation_area, 0.3, relative=True, expected_difference=Reason.MODEL_DIFFERENCE,
              note=f"faces of the contact surface ({skins}) with positive penalty pressure, as CAREA counts its "
                   "pairs' faces; frictionless penalty contact presses over a wider band than Abaqus's kinematic "
                   "contact" + suffix)
    for name, value in measures.centre_stress.items():
        leaflet = name.lower()
        yield Row(f"Table 3 centre max principal Cauchy stress, {leaflet}, diseased (kPa)",
                  TABLE3_CENTRE_STRESS[leaflet].diseased, value * MPA_TO_KPA, 0.25, relative=True,
                  expected_difference=Reason.MODEL_DIFFERENCE,
                  note="mean over the hexes at the leaflet centre region (10 % of the leaflet's mid-surface area, "
                       "the paper's Fig. 4d region is not given in numbers); quasi-static implicit vs explicit "
                       "dynamics with mass scaling" + suffix)

