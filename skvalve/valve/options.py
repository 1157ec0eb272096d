"""Options of the valve closure (:func:`skvalve.valve.run.close_valve`), one dataclass per concern.

Units are the input's: mm, MPa (N/mm²), N, step time. The defaults close every Texas TriValve input; each field says
what it controls and why its default is what it is.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

from ..fem.contact.ipc import Friction

__all__ = ["CloseOptions", "ContactOptions", "HoldOptions", "ModelOptions", "StepOptions"]


def _positive(owner: str, name: str, value, zero: bool = False) -> None:
    """Refuse a field that is not a finite number > 0 (>= 0 with ``zero``), naming it."""
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or not (value >= 0.0 if zero else value > 0.0):
        raise ValueError(f"{owner}.{name} must be a finite number {'>= 0' if zero else '> 0'}; got {value!r}")


@dataclass(frozen=True)
class ModelOptions:
    """How the input becomes the implicit model (:meth:`~skvalve.valve.model.ValveModel.problem`).

    insertion
        ``"patch"`` spreads each chord's pull over the cells around its insertion (a point attachment on a hex
        skin pulls one node through the leaflet), ``"node"`` keeps the input's point attachment.
    cable_compression
        the cables that are one input truss carry their law in compression too, as the input's truss
        elements do (a chordae branch point is then held by struts, not by slack springs).
    """

    insertion: str = "patch"
    cable_compression: bool = True

    def __post_init__(self) -> None:
        if self.insertion not in ("patch", "node"):
            raise ValueError(f"ModelOptions.insertion must be 'patch' or 'node'; got {self.insertion!r}")


@dataclass(frozen=True)
class ContactOptions:
    """The IPC barrier on the leaflets' whole hex boundary (:class:`~skvalve.fem.contact.IPCContact`).

    dhat
        the barrier's range (mm). Below every gap that must stay open at rest: 0.1 mm pairs no primitive of the
        1.0 diseased valve at rest (0.5 mm pairs 76 266: its 0.39 mm leaflets' two skins).
    pressure_factor
        the stiffness κ carries this many times the input's largest pressure at half of ``dhat``
        (:func:`~skvalve.fem.contact.ipc.stiffness_for_pressure`): coapting leaflets then meet about ``dhat``/2 apart.
    exclude_within
        body vertices closer than this (mm) in the reference never collide (the skins across a free edge
        and the commissures, where the leaflets share nodes).
    friction
        ``None`` (frictionless; the 1.0 inputs' friction 0.001 is negligible) or a :class:`Friction`.
    check_intersections
        assert after every accepted step that the collision mesh does not intersect
        (``has_intersections``, ~0.03 s on the 1.0 valve): a guard, since the collision-free line search makes it
        impossible by construction.
    """

    dhat: float = 0.1
    pressure_factor: float = 2.0
    exclude_within: float = 1.0
    friction: Friction | None = None
    check_intersections: bool = True

    def __post_init__(self) -> None:
        _positive("ContactOptions", "dhat", self.dhat)
        _positive("ContactOptions", "pressure_factor", self.pressure_factor)
        _positive("ContactOptions", "exclude_within", self.exclude_within, zero=True)


@dataclass(frozen=True)
class StepOptions:
    r"""The load path in step time: incremental-potential steps with a viscous pseudo-mass and an adaptive length.

    Each step :math:`t \to t + \Delta t` minimises :math:`\Pi(u, t+\Delta t) + \tfrac{c}{2\Delta t}
    \sum_i V_i |u_i - u_i^n|^2` (lumped nodal volumes :math:`V_i`): the proximal (pseudo-transient) term holds nodes
    that nothing else holds yet (free edges before they meet, slack chordae branch points), and it is dropped at the
    held load.

    damping
        :math:`c` (N·s/mm⁴ per unit step time). 1e-3: on the 1.0 diseased valve's early pressure stage (from
        step time 0.535, same machine and load) the steps with 1e-4 wandered (Marquardt shifts of 0.01-1 times the
        diagonal, the residual rising 40-fold within a step) and were cut back to 0.001-0.003 of step time: 3 steps in
        9 minutes; with 1e-3, 7 steps to 0.640 with no cut-back, the step growing to 0.033. The viscous force it
        leaves on the path (a few % of the pressure's nodal forces while the leaflets move) is removed by the held
        steps.
    first, largest, smallest
        the first, largest and smallest step (step time); a failed step is halved, and the run
        stops with the step and step time when it falls below ``smallest``.
    growth, easy_iterations
        a step that converged in at most ``easy_iterations`` iterations lets the next grow by
        ``growth``. On the 1.0 posterior leaflet's papillary stage a step took 10-25 iterations whatever its
        length (0.003-0.02 of step time: a chordae branch point between stiff struts sets the count, not the load
        increment), so a smaller bound kept the steps at their smallest.
    rtol
        each path step's tolerance, relative to the end load's nodal pressure forces
        (:func:`~skvalve.valve.setup.end_load_norm`, as every relative residual of the closure): a step leaves at
        most this share of the pressure unbalanced; the held load is then solved to ``HoldOptions.rtol``.
    max_iter
        iterations per step before it is cut back.
    """

    damping: float = 1e-3
    first: float = 0.01
    largest: float = 0.1
    smallest: float = 1e-6
    growth: float = 1.5
    easy_iterations: int = 20
    rtol: float = 1e-3
    max_iter: int = 40

    def __post_init__(self) -> None:
        for name in ("damping", "first", "largest", "smallest", "rtol"):
            _positive("StepOptions", name, getattr(self, name))
        if not self.smallest <= self.first <= self.largest:
            raise ValueError(f"StepOptions: need smallest <= first <= largest; got {self.smallest}, {self.first}, "
                             f"{self.largest}")
        if not self.growth >= 1.0:
            raise ValueError(f"StepOptions.growth must be >= 1; got {self.growth!r}")
        for name in ("easy_iterations", "max_iter"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise ValueError(f"StepOptions.{name} must be a positive integer; got {value!r}")


@dataclass(frozen=True)
class HoldOptions:
    """The held load at the end: pseudo-steps whose pseudo-mass fades (the step doubles), each converged to a tenth
    of the static residual it starts from (not below ``rtol``), then the static problem. A held step that runs out of
    iterations (``StepOptions.max_iter``) is kept, marked unconverged, when its last iterate lowered the static
    residual: the held phase only has to make progress towards the equilibrium, and on the 1.0 diseased valve a
    discarded step threw away 40 iterations (2-4 minutes) that had moved the leaflets towards it.

    rtol
        the undamped, static residual asked for (relative to the end load's nodal pressure forces).
    static_below
        once a held step leaves a static residual below this, the static problem is tried directly.
    max_steps
        held steps before the run stops with its best state; 0: no held phase (the path only).
    growth
        the held pseudo-step's growth after each converged held step (the pseudo-mass falls by it); a step kept
        unconverged keeps its pseudo-step, a failed one halves it. On the 1.0 diseased valve the held steps took
        20-40 iterations at every pseudo-step, so growing only after easy steps (as the path does) kept the
        pseudo-mass at its path value: the static residual fell 1-2 % per held step.
    """

    rtol: float = 1e-6
    static_below: float = 1e-3
    max_steps: int = 200
    growth: float = 2.0

    def __post_init__(self) -> None:
        _positive("HoldOptions", "rtol", self.rtol)
        _positive("HoldOptions", "static_below", self.static_below)
        if not self.growth > 1.0:
            raise ValueError(f"HoldOptions.growth must be > 1; got {self.growth!r}")
        if not isinstance(self.max_steps, int) or isinstance(self.max_steps, bool) or self.max_steps < 0:
            raise ValueError(f"HoldOptions.max_steps must be an integer >= 0; got {self.max_steps!r}")


@dataclass(frozen=True)
class CloseOptions:
    """Everything :func:`~skvalve.valve.run.close_valve` needs; ``end`` None: the input's step time."""

    model: ModelOptions = field(default_factory=ModelOptions)
    contact: ContactOptions = field(default_factory=ContactOptions)
    steps: StepOptions = field(default_factory=StepOptions)
    hold: HoldOptions = field(default_factory=HoldOptions)
    end: float | None = None
    solver: str | None = None

    def __post_init__(self) -> None:
        if self.end is not None:
            _positive("CloseOptions", "end", self.end)

    def as_dict(self) -> dict:
        """Plain data (JSON-ready) for the kept state."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> CloseOptions:
        """Inverse of :meth:`as_dict`."""
        contact = dict(data["contact"])
        if contact.get("friction") is not None:
            contact["friction"] = Friction(**contact["friction"])
        return cls(ModelOptions(**data["model"]), ContactOptions(**contact), StepOptions(**data["steps"]),
                   HoldOptions(**data["hold"]), data.get("end"), data.get("solver"))
