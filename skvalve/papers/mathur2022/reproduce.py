"""``skvalve reproduce mathur2022``: Tables 2–3 of the Texas TriValve inputs at end-systole.

Default run (a few minutes at most): builds the 1.0 diseased input's closure model
(:func:`~skvalve.valve.setup.valve_setup`) and compares the **orifice area** with Table 2: the input holds the ring
of nodes one leaflet thickness (0.78 mm) from the annulus node set, so the orifice of the open configuration is, to
within the motion of that thin rim, the end-systolic one; it measures the leaflet area of the open configuration
(beside the paper's end-systolic value, with that difference stated). It does **not** close the valve.

``state=FILE`` (``--state``): a kept state of :func:`~skvalve.valve.run.close_valve` (``state.npz``, read by
:func:`~skvalve.valve.state.read_state`) is measured without solving. Its input is the Texas TriValve input present
whose file name the state records; the 1.0 and 1.1 diseased inputs share a name and are told apart by the state's
number of dofs. The model is rebuilt with the options the state records, the terms' state restored, the static
residual recomputed, and the rows of that input's column printed (:mod:`.columns`); a state whose phase is not
``done`` is marked incomplete in every note. With ``out``, its VTU file and the figures are written there.

``full=True`` (``--full``): every Texas TriValve input present is closed by :func:`~skvalve.valve.run.close_valve`
in ``out/<key>`` (``1.0-diseased``, ``1.1-healthy``, ...: the 1.0 and 1.1 diseased inputs share a file name), resumed
from the state kept there, so an interrupted ``--full`` goes on where it stopped; each input's run summary (wall
time, steps, iterations, residual, intersection, smallest Jacobian), figures and rows follow it. The clip input runs
its three steps in total time (0-2.5) with its four rigid arms as moving IPC obstacles (:mod:`skvalve.valve.clip`);
its rough, no-separation arm contact is the barrier with a tie after capture (the model's notes say so). An input the
model cannot represent is reported as not computed, with the keywords it refuses.

The model files (Mathur et al. 2022, CC BY-NC-SA 4.0; Texas TriValve 1.1, CC BY 4.0) are never copied; without them
the run ends with a message and exit code 2 (``$SKVALVE_TRIVALVE`` names the 1.0 diseased .inp file or its folder).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ...io.abaqus import trivalve_input, trivalve_inputs
from ...valve.options import CloseOptions
from ...valve.outputs import ClosureWriter, closure_measures
from ...valve.run import STATE_FILE, ClosureFailed, close_valve, relative_residual
from ...valve.setup import ValveSetup, valve_setup
from ...valve.state import KeptState, StateError, read_state
from ...valve.support import UnsupportedInputError
from ..table import InputError, Reason, Row, Stage, Written
from .columns import COLUMNS, SURFACE, Column, column_rows
from .data import CREDIT, TABLE2_AREAS
from .figures import write_figures

__all__ = ["DESCRIPTION", "EXIT_NO_INPUT", "present_inputs", "reproduce", "state_input"]

DESCRIPTION = "Tables 2–3 of the Texas TriValve inputs closed implicitly with IPC leaflet contact"
EXIT_NO_INPUT = 2


def _no_input() -> SystemExit:
    print("skvalve reproduce mathur2022: the Texas TriValve 1.0 input (Diseased_QuasiStatic.inp) was not found. "
          "Set $SKVALVE_TRIVALVE to the .inp file or its folder (model files of " + CREDIT + ", "
          "not shipped with skvalve).", file=sys.stderr)
    return SystemExit(EXIT_NO_INPUT)


def present_inputs() -> dict[str, Path]:
    """The Texas TriValve inputs present, by :data:`~.columns.COLUMNS` key, in that order
    (``$SKVALVE_TRIVALVE``, when set, names the 1.0 diseased one)."""
    found = trivalve_inputs()
    given = trivalve_input()
    if given is not None and given.resolve() not in {path.resolve() for path in found.values()}:
        found["1.0-diseased"] = given
    return {key: found[key] for key in COLUMNS if key in found}


def _setup(path: Path, options: CloseOptions | None, what: str) -> ValveSetup:
    """:func:`valve_setup`, the refusal of an input the model cannot represent as an :class:`InputError`."""
    try:
        return valve_setup(path, options)
    except UnsupportedInputError as err:
        raise InputError(f"{what}: {path.name} is an input the valve model does not represent ({err})") from err


def state_input(state: Path, inputs: dict[str, Path]) -> tuple[str, KeptState, ValveSetup]:
    """The input key, the kept state and the model of a state file (module docstring), its terms restored.

    Raises :class:`InputError` naming the file when it is not a readable kept state, names no input present, or
    its dof count fits none of the inputs of that name (or more than one).
    """
    try:
        kept = read_state(state)
    except StateError as err:
        raise InputError(str(err)) from err
    named = [key for key, path in inputs.items() if path.name == kept.input]
    if not named:
        present = ", ".join(f"{key} ({path.name})" for key, path in inputs.items()) or "none"
        raise InputError(f"kept state {state}: computed from {kept.input!r}, which is none of the Texas TriValve "
                         f"inputs present ({present})")
    fitting, sizes = [], []
    for key in named:
        setup = _setup(inputs[key], kept.options, f"kept state {state}")
        sizes.append(f"{key}: {setup.problem.space.n_dofs}")
        if setup.problem.space.n_dofs == kept.u.size:
            fitting.append((key, setup))
    if len(fitting) != 1:
        why = "fits none of" if not fitting else "cannot be told apart by its size among"
        raise InputError(f"kept state {state}: {kept.u.size} displacement values {why} the inputs named "
                         f"{kept.input} (dofs {', '.join(sizes)})")
    key, setup = fitting[0]
    try:
        setup.problem.restore(kept.terms)
    except (KeyError, ValueError, TypeError) as err:
        raise InputError(f"kept state {state}: its terms' state does not fit the model of {key} ({err})") from err
    return key, kept, setup


def static_residual(setup: ValveSetup, u: np.ndarray, t: float) -> float:
    """The static relative residual at ``(u, t)``, as :func:`~skvalve.valve.run.close_valve` measures it."""
    residual, _ = setup.problem.assemble(u, t, tangent=False)
    return relative_residual(setup, residual)


def _open(setup: ValveSetup):
    """The measures of the open (reference) configuration."""
    return closure_measures(setup, np.zeros(setup.problem.space.n_dofs), 0.0)


def _outputs(setup: ValveSetup, column: Column, u: np.ndarray, t: float, out: Path,
             pvd: str | None) -> Iterator[Written]:
    """The VTU series ``pvd`` (None: none) and the figures of a state in ``out``."""
    if pvd is not None:
        ClosureWriter(out / pvd, setup).write(t, u)
        yield Written(out / pvd)
    yield from (Written(path) for path in write_figures(setup, u, t, out, credit=column.credit))


def _measure_state(state: Path, out: Path | None) -> Iterator[Row | Stage | Written]:
    yield Stage(f"reading kept state {state} and building its input's closure model")
    inputs = present_inputs()
    key, kept, setup = state_input(Path(state), inputs)
    column = COLUMNS[key]
    residual = static_residual(setup, kept.u, kept.t)
    done = kept.phase == "done"
    text = (f"kept state {Path(state).name} of {key} ({kept.input}; {column.credit}): phase {kept.phase!r} at step "
            f"time {kept.t:.6g} after {kept.steps} path and {kept.held_steps} held steps, {kept.iterations} "
            f"iterations; static relative residual {residual:.3e} recomputed ({kept.relative_residual:.3e} recorded)")
    yield Stage(text)
    if out is not None:
        yield from _outputs(setup, column, kept.u, kept.t, Path(out), "mathur2022_kept_state.pvd")
    incomplete = "" if done else (f"INCOMPLETE: kept state {Path(state).name} in phase {kept.phase!r} at step time "
                                  f"{kept.t:.6g}, not the converged held load")
    yield from column_rows(column, closure_measures(setup, kept.u, kept.t), _open(setup),
                           kept.options.contact.dhat, incomplete)


def _close_one(key: str, path: Path, out: Path | None) -> Iterator[Row | Stage | Written]:
    """Close one input (resumed from its kept state when there is one) and yield its summary, outputs and rows."""
    column = COLUMNS[key]
    folder = None if out is None else Path(out) / key
    resume = folder is not None and (folder / STATE_FILE).is_file()
    kept = None
    if resume:
        try:
            kept = read_state(folder / STATE_FILE, input_name=path.name)
        except StateError as err:
            raise InputError(f"{err} (remove it to close {key} from the open valve, or choose another --out)") from err
    options = None if kept is None else kept.options
    try:
        setup = valve_setup(path, options)
    except UnsupportedInputError as err:
        yield Stage(f"{key} ({path.name}): the paper's {column.state} column is not computed: the valve model does "
                    f"not represent {len(err.features)} keyword(s) of the input; first: {err.features[0]}")
        return
    if kept is not None and kept.u.size != setup.problem.space.n_dofs:
        raise InputError(f"kept state {folder / STATE_FILE}: {kept.u.size} displacement values for the "
                         f"{setup.problem.space.n_dofs} dofs of {key} (remove it, or choose another --out)")
    yield Stage(f"{key}: {'resuming' if resume else 'closing'} {path.name} ({column.credit})"
                + ("" if folder is None else f" in {folder}"))
    last: dict[str, KeptState] = {}
    try:
        report = close_valve(path, options, out=folder, resume=resume, setup=setup,
                             callbacks=[lambda kept: last.update(state=kept)])
    except ClosureFailed as err:
        yield Stage(f"{key}: the closure stopped: {err}")
        if not last and folder is not None and (folder / STATE_FILE).is_file():
            last["state"] = read_state(folder / STATE_FILE)  # resumed, and no step accepted since
        if not last:
            return
        u, t, phase = last["state"].u, last["state"].t, last["state"].phase
        summary, done = f"measured at the last accepted state: phase {phase!r} at step time {t:.6g}", False
    else:
        u, t, done, summary = report.u, report.t, report.converged, report.summary()
        if folder is not None:
            yield Written(folder / "closure.pvd")
    yield Stage(f"{key}: {summary}")
    if folder is not None:
        yield from _outputs(setup, column, u, t, folder, None)
    incomplete = "" if done else f"INCOMPLETE: the closure of {key} did not converge (step time {t:.6g})"
    dhat = (options or CloseOptions()).contact.dhat
    yield from column_rows(column, closure_measures(setup, u, t), _open(setup), dhat, incomplete)


def reproduce(out: Path | None = None, full: bool = False,
              state: Path | None = None) -> Iterator[Row | Stage | Written]:
    """Yield the Table 2–3 rows (module docstring); exits with code 2 when the 1.0 diseased input is absent."""
    if state is not None:
        yield from _measure_state(Path(state), out)
        return
    if full:
        inputs = present_inputs()
        if not inputs:
            raise _no_input()
        for key, path in inputs.items():
            yield from _close_one(key, path, out)
        return
    path = trivalve_input()
    if path is None:
        raise _no_input()
    yield Stage(f"reading {path.name} and building the closure model with IPC contact ({CREDIT})")
    setup = valve_setup(path)
    yield Stage("Table 2 measures of the open (reference) configuration")
    reference = _open(setup)
    yield Row("Table 2 orifice area, diseased (mm²; annulus held)", TABLE2_AREAS["orifice"].diseased,
              reference.orifice[SURFACE], 0.03, relative=True,
              note="annulus loop of the mid surface projected on its best-fit plane, open configuration; the input "
                   "holds the ring 0.78 mm across the thickness from the annulus set, so it barely moves")
    yield Row("Table 2 leaflet area, diseased (mm²; open configuration)", TABLE2_AREAS["leaflet"].diseased,
              reference.leaflet_area[SURFACE], 0.05, relative=True, expected_difference=Reason.MODEL_DIFFERENCE,
              note="mid-surface area of the open, unloaded leaflets: the default run does not close the valve "
                   "(use --full, or --state with a kept state of skvalve valve close); the paper's value is at "
                   "end-systole")
