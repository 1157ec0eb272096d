"""The kept state of a valve closure: what a run writes after every step and resumes from.

One ``.npz`` file (written atomically, :func:`~skvalve.io.files.replace_atomically`) with the step time, the
displacement, the step controller (next step length, step count, held steps, the held stage and its trust region's
:class:`~skvalve.fem.solvers.trust_region.TrustRegionControl`), the name of the input, the run's
:class:`~skvalve.valve.options.CloseOptions` as JSON, and every stateful term's committed state
(:meth:`~skvalve.fem.problem.Problem.state`: the IPC barrier's stiffness and friction lag). A run resumed from it
repeats the uninterrupted one (same steps, same iterates).
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fem.solvers.trust_region import TrustRegionControl
from ..io.files import replace_atomically
from .options import CloseOptions

__all__ = ["KeptState", "StateError", "read_state", "write_state"]

#: format version of the kept state; a file of another version is refused. 4: term state keyed by the term's name
#: (:meth:`~skvalve.fem.problem.Problem.term_labels`); 3 (keyed by the term's position) is still read, and
#: :meth:`~skvalve.fem.problem.Problem.restore` gives its keys to the terms by position
FORMAT = 4
READS = (3, 4)
_TERM_PREFIX = "term:"
_CONTROL_SCALARS = ("radius", "shift", "fallback", "steps", "attempts", "retry_below", "retry_after")


class StateError(ValueError):
    """A kept state that cannot be read or does not belong to the run that reads it."""


@dataclass
class KeptState:
    """A closure state: step time ``t``, displacement ``u``, the controller, the input and the options.

    ``phase`` is ``"path"`` (loading), ``"hold"`` (held load) or ``"done"``; ``increment`` the next path step's length
    or proximal step's pseudo-step; ``held_stage`` the held load's stage (0 descend, 1 settle, 2 proximal) and
    ``control`` the energy stage's trust-region controller after its last step (None before a stage's first step and in
    the proximal stage); ``relative_residual`` the static residual at ``u``.
    """

    t: float
    u: np.ndarray
    input: str
    options: CloseOptions
    phase: str = "path"
    increment: float = 0.0
    steps: int = 0
    held_steps: int = 0
    iterations: int = 0
    relative_residual: float = float("nan")
    terms: dict[str, np.ndarray] = field(default_factory=dict)
    held_stage: int = 0
    control: TrustRegionControl | None = None

    def __post_init__(self) -> None:
        if self.phase not in ("path", "hold", "done"):
            raise StateError(f"kept state: phase must be 'path', 'hold' or 'done'; got {self.phase!r}")


def write_state(path: str | Path, state: KeptState) -> Path:
    """Write ``state`` to ``path`` atomically (a reader never sees a half-written file)."""
    arrays = {f"{_TERM_PREFIX}{key}": np.asarray(value) for key, value in state.terms.items()}
    scalars = {"format": FORMAT, "t": state.t, "phase": state.phase, "increment": state.increment,
               "steps": state.steps, "held_steps": state.held_steps, "iterations": state.iterations,
               "relative_residual": state.relative_residual, "input": state.input,
               "options": json.dumps(state.options.as_dict()), "held_stage": state.held_stage}
    if state.control is not None:
        c = state.control
        scalars["control"] = json.dumps({name: getattr(c, name) for name in _CONTROL_SCALARS})
        arrays["control_local"], arrays["control_energy_changes"] = c.local, np.asarray(c.energy_changes, dtype=float)
    return replace_atomically(Path(path), lambda temporary: np.savez(temporary, u=state.u, **scalars, **arrays))


def read_state(path: str | Path, input_name: str | None = None, n_dofs: int | None = None) -> KeptState:
    """Read a kept state; with ``input_name`` / ``n_dofs`` refuse one of another input or model size.

    Raises :class:`StateError` naming the file and what is wrong (missing, not a kept state, another version, another
    input, another size), never a bare ``KeyError``.
    """
    path = Path(path)
    if not path.is_file():
        raise StateError(f"kept state {path}: no such file")
    try:
        with np.load(path, allow_pickle=False) as data:
            content = {key: data[key] for key in data.files}
    except (OSError, ValueError, zipfile.BadZipFile) as err:
        raise StateError(f"kept state {path}: not a readable .npz file ({err})") from err
    missing = [key for key in ("format", "t", "u", "input", "options") if key not in content]
    if missing:
        raise StateError(f"kept state {path}: not a closure state of this version (missing {', '.join(missing)}; "
                         "states of benchmarks/trivalve_closure.py before skvalve.valve.run are not resumable)")
    if int(content["format"]) not in READS:
        raise StateError(f"kept state {path}: format {int(content['format'])}, this version reads "
                         f"{' and '.join(map(str, READS))}")
    name = str(content["input"])
    if input_name is not None and name != input_name:
        raise StateError(f"kept state {path}: computed from {name!r}, not from {input_name!r}")
    u = np.asarray(content["u"], dtype=float)
    if n_dofs is not None and u.shape != (n_dofs,):
        raise StateError(f"kept state {path}: {u.size} displacement values for a model of {n_dofs} dofs")
    try:
        options = CloseOptions.from_dict(json.loads(str(content["options"])))
    except (TypeError, KeyError, ValueError) as err:
        raise StateError(f"kept state {path}: its options do not read ({err})") from err
    terms = {key[len(_TERM_PREFIX):]: value for key, value in content.items() if key.startswith(_TERM_PREFIX)}
    control = None
    if "control" in content:
        try:
            scalars = json.loads(str(content["control"]))
            control = TrustRegionControl(local=np.asarray(content["control_local"], dtype=float),
                                         energy_changes=[float(x) for x in content["control_energy_changes"]],
                                         **{name: scalars[name] for name in _CONTROL_SCALARS})
        except (KeyError, TypeError, ValueError) as err:
            raise StateError(f"kept state {path}: its held-load controller does not read ({err})") from err
    return KeptState(float(content["t"]), u, name, options, str(content["phase"]), float(content["increment"]),
                     int(content["steps"]), int(content["held_steps"]), int(content["iterations"]),
                     float(content["relative_residual"]), terms, int(content.get("held_stage", 0)), control)
