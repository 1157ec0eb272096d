r"""The load history of an Abaqus input over all its steps, as functions of the **total time**.

Step :math:`k` (time period :math:`T_k`) spans :math:`[t_k, t_k + T_k]`, :math:`t_k = \sum_{j<k} T_j`, and its step
time is :math:`\tau = t - t_k`. A definition of a boundary condition or a distributed load in step :math:`k`
(magnitude :math:`v`, amplitude :math:`A`) gives, following Abaqus ("Prescribed conditions", "Amplitude curves"),

.. math::

    f(t) = \begin{cases}
        v\,A(\tau) & \text{amplitude in step time (the default)},\\
        v\,A(t) & \text{amplitude with } \texttt{TIME=TOTAL TIME},\\
        f_{k-1} + (v - f_{k-1})\min(\tau/T_k, 1) & \text{no amplitude, static step (ramp; } f_{k-1}
            \text{ the value at the end of the previous step, or 0)},\\
        v & \text{no amplitude, dynamic step (applied at once)}.
    \end{cases}

A definition that a later step does not repeat is **carried** (``OP=MOD``, the default): it keeps its value at the end
of the step, :math:`f(t_k + T_k)`, or keeps following an amplitude in total time. ``OP=NEW`` on any ``*Boundary``
(``*Dsload``) of a step **releases** every boundary condition (distributed load) in effect that the step does not
define again: a released condition leaves its dof free (``None`` here), a released load goes to zero, ramped down over
a static step and at once in a dynamic one. Model-level ``*Boundary`` lines count as the first lines of the first
step (so ``OP=NEW`` there drops them). Within a step a later line on the same dof (the same surface and load type)
replaces an earlier one.

A single-step input gives :math:`t = \tau` and the same values as the one-step model always had.
:class:`NodalCondition` and :class:`PressureLoad` carry such a :class:`History` (their ``at(t)``), and
:func:`nodal_conditions` groups the mesh vertices of equal histories into conditions.
"""

from __future__ import annotations

from bisect import bisect_right
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from ..fem.amplitudes import Amplitude, SmoothStep, Tabular
from ..io.abaqus import AbaqusModel, BoundaryCondition, DistributedLoad, Location, Step

__all__ = ["StepWindow", "Segment", "History", "NodalCondition", "PressureLoad", "amplitude_table",
           "nodal_conditions", "step_windows", "selected_steps", "condition_histories", "load_histories"]


@dataclass(frozen=True)
class StepWindow:
    """One step on the total-time axis: its name, start :math:`t_k`, period :math:`T_k` and kind."""

    name: str
    start: float
    period: float
    static: bool
    location: Location | None = field(default=None, compare=False)

    @property
    def end(self) -> float:
        return self.start + self.period


@dataclass(frozen=True)
class Segment:
    """The value within one step (module docstring): ``value`` x amplitude, a ramp from ``ramp_from``, or constant.

    ``location`` (the defining line) is for messages and takes no part in comparisons, so equal histories of
    different lines group together.
    """

    start: float
    period: float
    value: float
    amplitude: Amplitude | None = None
    total_time: bool = False
    ramp_from: float | None = None
    location: Location | None = field(default=None, compare=False)

    def at(self, t: float) -> float:
        """The value at total time ``t``."""
        if self.amplitude is not None:
            return self.value * float(self.amplitude(t if self.total_time else t - self.start))
        if self.ramp_from is not None:
            return self.ramp_from + (self.value - self.ramp_from) * min(max((t - self.start) / self.period, 0.0), 1.0)
        return self.value

    def end_value(self) -> float:
        """The value at the end of the step, :math:`f(t_k + T_k)` (step time exactly :math:`T_k`)."""
        if self.amplitude is not None:
            return self.value * float(self.amplitude(self.start + self.period if self.total_time else self.period))
        return self.value


@dataclass(frozen=True)
class History:
    """One segment per step (``None``: not prescribed in that step); ``starts`` the steps' start times;
    ``released_by`` the ``OP=NEW`` line of each step that released it (for messages; not compared)."""

    starts: tuple[float, ...]
    segments: tuple[Segment | None, ...]
    released_by: tuple[Location | None, ...] = field(default=(), compare=False)

    def segment(self, t: float) -> Segment | None:
        """The segment in effect at total time ``t`` (the first step's before 0, the last step's after the end)."""
        k = min(max(bisect_right(self.starts, t) - 1, 0), len(self.starts) - 1)
        return self.segments[k]

    def at(self, t: float) -> float:
        """The value at total time ``t``; raises ``ValueError`` where nothing is prescribed."""
        segment = self.segment(t)
        if segment is None:
            raise ValueError(f"nothing is prescribed at total time {t:g}")
        return segment.at(t)

    @property
    def always(self) -> bool:
        """Prescribed in every step."""
        return all(s is not None for s in self.segments)

    @property
    def never(self) -> bool:
        return all(s is None for s in self.segments)

    def changes_at(self) -> Location | None:
        """The line that first releases or first adds the prescription after the first step (None: it never
        changes between prescribed and free)."""
        for k in range(1, len(self.segments)):
            before, after = self.segments[k - 1], self.segments[k]
            if (before is None) != (after is None):
                released = self.released_by[k] if k < len(self.released_by) else None
                return after.location if after is not None else (released or before.location)
        return None


@dataclass
class NodalCondition:
    """Component ``component`` (0..2) of ``vertices`` prescribed to ``value`` x amplitude(t); with a ``history``
    (:mod:`.history`) the value follows it over all steps (``value``, ``amplitude`` are then the first step's)."""

    vertices: np.ndarray
    component: int
    value: float
    amplitude: Amplitude | None
    ramp_time: float | None = None
    history: History | None = None

    def at(self, t: float) -> float:
        """The prescribed value at total time ``t`` (the step time of a one-step model)."""
        if self.history is not None:
            return self.history.at(t)
        if self.amplitude is not None:
            return self.value * float(self.amplitude(t))
        if self.ramp_time is not None:
            return self.value * min(max(t / self.ramp_time, 0.0), 1.0)
        return self.value


@dataclass
class PressureLoad:
    """Follower pressure ``magnitude`` x amplitude(t) on mesh ``facets`` (positive pushes into the surface)."""

    surface: str
    facets: np.ndarray
    magnitude: float
    amplitude: Amplitude | None
    ramp_time: float | None = None
    history: History | None = None

    def at(self, t: float) -> float:
        """The pressure at total time ``t`` (``history``, or ``magnitude`` x amplitude)."""
        return NodalCondition(np.empty(0, int), 0, self.magnitude, self.amplitude, self.ramp_time, self.history).at(t)



def amplitude_table(abaqus: AbaqusModel) -> tuple[dict[str, Amplitude], dict[str, bool]]:
    """The input's amplitudes by upper-case name, and whether each is in total time (``TIME=TOTAL TIME``)."""
    out: dict[str, Amplitude] = {}
    for key, amp in abaqus.amplitudes.items():
        kind = amp.definition.upper()
        if kind == "SMOOTH STEP":
            out[key.upper()] = SmoothStep(tuple(amp.times), tuple(amp.values), name=amp.name)
        elif kind == "TABULAR":
            out[key.upper()] = Tabular(tuple(amp.times), tuple(amp.values), name=amp.name)
        else:
            raise ValueError(f"{amp.location}: amplitude {amp.name!r} has unsupported definition {amp.definition!r}")
    total = {key.upper(): (amp.time or "").upper().replace("_", " ") == "TOTAL TIME"
             for key, amp in abaqus.amplitudes.items()}
    return out, total


def selected_steps(abaqus: AbaqusModel, step: int | None = None) -> list[Step]:
    """All steps (``step`` None) or step ``step`` alone."""
    if step is None:
        return list(abaqus.steps)
    if not 0 <= step < max(len(abaqus.steps), 1):
        raise ValueError(f"{abaqus.path}: step {step} does not exist (the input has {len(abaqus.steps)} step(s))")
    return [abaqus.steps[step]] if abaqus.steps else []


def step_windows(steps: list[Step]) -> list[StepWindow]:
    """The steps laid end to end from total time 0 (no step: one dynamic window of period 1)."""
    if not steps:
        return [StepWindow("", 0.0, 1.0, False)]
    windows, start = [], 0.0
    for step in steps:
        static = (step.procedure or "").lower().startswith("static")
        windows.append(StepWindow(step.name, start, step.time_period, static, step.location))
        start += step.time_period
    return windows


def _segment(window: StepWindow, value: float, amplitude: str | None, amplitudes: dict[str, Amplitude],
             total_time: dict[str, bool], previous: float | None, location: Location) -> Segment:
    """The segment of a definition in a step (module docstring)."""
    if amplitude is not None:
        key = amplitude.upper()
        if key not in amplitudes:
            raise ValueError(f"{location}: unknown amplitude {amplitude!r}")
        return Segment(window.start, window.period, value, amplitudes[key], total_time.get(key, False), None, location)
    ramp = (previous or 0.0) if window.static else None
    return Segment(window.start, window.period, value, None, False, ramp, location)


def _carried(window: StepWindow, before: Segment) -> Segment:
    """A definition carried into a step that does not repeat it: its end value, or its total-time amplitude."""
    if before.amplitude is not None and before.total_time:
        return Segment(window.start, window.period, before.value, before.amplitude, True, None, before.location)
    return Segment(window.start, window.period, before.end_value(), None, False, None, before.location)


def _histories(per_step: list[dict], released: list[Location | None], windows: list[StepWindow], amplitudes, total_time,
               loads: bool) -> dict:
    """Histories of keyed definitions: ``per_step[k][key] = (value, amplitude, location)`` the last line of step k."""
    keys = list(dict.fromkeys(key for defined in per_step for key in defined))
    starts = tuple(w.start for w in windows)
    out = {}
    for key in keys:
        segments: list[Segment | None] = []
        releases: list[Location | None] = []
        before: Segment | None = None
        for window, defined, new in zip(windows, per_step, released, strict=True):
            release = None
            if key in defined:
                value, amplitude, location = defined[key]
                previous = None if before is None else before.end_value()
                segment = _segment(window, value, amplitude, amplitudes, total_time, previous, location)
            elif before is None:
                segment = Segment(window.start, window.period, 0.0) if loads else None
            elif new is not None:
                ramp = before.end_value() if window.static else None
                segment = Segment(window.start, window.period, 0.0, None, False, ramp, new) if loads else None
                release = new
            else:
                segment = _carried(window, before)
            segments.append(segment)
            releases.append(release)
            before = segment
        out[key] = History(starts, tuple(segments), tuple(releases))
    return out


def condition_histories(abaqus: AbaqusModel, steps: list[Step], windows: list[StepWindow],
                        amplitudes: dict[str, Amplitude],
                        total_time: dict[str, bool]) -> dict[tuple[int, int], History]:
    """The history of every prescribed (global node, dof 1..6), in the order of first definition."""
    per_step, released = [], []
    for k, step in enumerate(steps or [None]):
        lines: list[BoundaryCondition] = list(step.boundary_conditions) if step is not None else []
        new = next((bc.location for bc in lines if bc.op == "NEW"), None)
        if k == 0 and new is None:
            lines = list(abaqus.boundary_conditions) + lines
        per_step.append(_last_definitions(lines))
        released.append(new if k > 0 else None)
    return _histories(per_step, released, windows, amplitudes, total_time, loads=False)


def _last_definitions(lines: Iterable[BoundaryCondition]) -> dict[tuple[int, int], tuple]:
    defined: dict[tuple[int, int], tuple] = {}
    for bc in lines:
        for dof in range(bc.first_dof, bc.last_dof + 1):
            for g in bc.nodes:
                defined[(int(g), dof)] = (float(bc.value), bc.amplitude, bc.location)
    return defined


def load_histories(steps: list[Step], windows: list[StepWindow], amplitudes: dict[str, Amplitude],
                   total_time: dict[str, bool]) -> list[tuple[DistributedLoad, History]]:
    """The history of each distributed load (surface and type), with its first line, in order of first definition."""
    per_step, released, first = [], [], {}
    for step in steps:
        defined = {}
        for load in step.distributed_loads:
            key = (load.surface.upper(), load.load_type.upper())
            first.setdefault(key, load)
            defined[key] = (float(load.magnitude), load.amplitude, load.location)
        per_step.append(defined)
        released.append(next((load.location for load in step.distributed_loads if load.op == "NEW"), None))
    histories = _histories(per_step, released, windows, amplitudes, total_time, loads=True)
    return [(first[key], history) for key, history in histories.items()]


def nodal_conditions(lines: list[BoundaryCondition], histories: dict[tuple[int, int], History],
                     fibres: dict[int, list[int]], references: set[int],
                     ramp: float | None) -> tuple[list[NodalCondition], set[int], int]:
    """The translation conditions of the mesh vertices: each (vertex, component) follows its node's history (the
    last definition in each step wins), vertices with equal histories grouped, in the order the lines give them.

    ``fibres``: global node -> its mesh vertices; ``references``: nodes modelled otherwise (clip arms), neither
    skipped nor counted. Returns the conditions, the skipped nodes outside the model, the skipped rotational dofs.
    """
    grouped: dict[tuple, list[tuple[int, int, int]]] = defaultdict(list)
    skipped_nodes, skipped_rotations = set(), 0
    for bc in lines:
        on_arms = set(np.asarray(bc.nodes).tolist()) <= references
        for dof in range(bc.first_dof, bc.last_dof + 1):
            if dof > 3:
                skipped_rotations += 0 if on_arms else 1
                continue
            for g in bc.nodes:
                if int(g) not in fibres:
                    if int(g) not in references:
                        skipped_nodes.add(int(g))
                    continue
                grouped[(dof - 1, float(bc.value), bc.amplitude)].extend((v, int(g), dof) for v in fibres[int(g)])
    owner: dict[tuple[int, int], History | None] = {}
    for key, items in grouped.items():
        for v, g, dof in items:
            history = histories.get((g, dof))
            owner[(v, key[0])] = None if history is None or history.never else history
    final: dict[tuple, list[int]] = defaultdict(list)
    for (v, component), history in owner.items():
        if history is not None:
            final[(component, history)].append(v)
    conditions = []
    for (component, history), v in final.items():
        if not history.always:
            raise ValueError(f"{history.changes_at()}: a dof prescribed in some steps only (refused by "
                             "skvalve.valve.support)")
        first = history.segments[0]
        conditions.append(NodalCondition(np.unique(np.asarray(v, dtype=np.int64)), component, first.value,
                                         first.amplitude, ramp, history))
    return conditions, skipped_nodes, skipped_rotations
