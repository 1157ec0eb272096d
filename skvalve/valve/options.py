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
        the cables that are one input truss carry their law in compression too, as the input's T3D2 trusses
        (no ``*No Compression``) do. Off by default: a chord cannot push. On the 1.0 diseased valve's converged
        state with it on, 341 of 690 bars pushed, down to -2.61 N, where a 0.65 mm chord 10 mm long buckles near
        2e-3 N (Euler); those struts held the free edges apart (coaptation 120 mm² against the paper's 228 and 206
        with tension-only chordae) and made the annuloplasty valve's held problem strongly indefinite (its static
        residual with tension-only chordae: 63 load norms).
    corner_threshold
        the leaflet hexes resist a folding corner: :class:`~skvalve.fem.elements.corner_barrier.CornerBarrier` acts
        where a corner's Jacobian falls below this share of its reference value (0: off). A trilinear hex can fold
        at a corner while its Gauss points stay positive; on the 1.0 diseased valve's held load one free-edge hex did
        (corner ratio -0.007). 0.1: at the converged state of that valve (without the barrier) 6 of its 151 360
        corners lay below 0.1 and 84 below 0.3, so the barrier changes the solution only where a corner degenerates.
    """

    insertion: str = "patch"
    cable_compression: bool = False
    corner_threshold: float = 0.1

    def __post_init__(self) -> None:
        if self.insertion not in ("patch", "node"):
            raise ValueError(f"ModelOptions.insertion must be 'patch' or 'node'; got {self.insertion!r}")
        _positive("ModelOptions", "corner_threshold", self.corner_threshold, zero=True)
        if not self.corner_threshold < 1.0:
            raise ValueError(f"ModelOptions.corner_threshold must lie in [0, 1); got {self.corner_threshold!r}")


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
        body vertices closer than this (mm) in the reference never collide. 0 (every pair collides): an excluded pair
        is one the barrier and the collision-free step do not see, so the minimiser can drive it through itself. With
        1 mm (the default before this version): on the 1.0 diseased valve's held load two edges of one free-edge hex
        crossed (a folded corner); the 1.1 healthy input's path reached an intersecting state at step time 0.933,
        and from 0.919 every step was refused, down to 1.4e-6 of step time. Without exclusion, the posterior leaflet's
        papillary stage once jammed between a folding hex's own faces (relative residual 1e7, steps capped to 1e-3
        of their length); with the corner barrier (``ModelOptions.corner_threshold``) the same leaflet now closes
        without exclusion (27 + 67 steps, 526 iterations, 2.2e-11), and the whole 1.0 diseased valve's held load
        converged without it (6.2e-10). At rest the 1.1 healthy and diseased inputs then have 2 and 1 pairs within
        ``dhat`` (0.093 and 0.096 mm apart); the 1.0 inputs have none.
    friction
        ``None`` (frictionless; the 1.0 inputs' friction 0.001 is negligible) or a :class:`Friction`.
    tie_within
        the clip arms' rough, no-separation contact (the input's ``*Friction, rough`` with ``*Surface Behavior, no
        separation``): a leaflet vertex within this distance (mm) of an active arm at an accepted step is tied to its
        point on the arm from then on (:class:`~skvalve.fem.contact.tie.ObstacleTie`; stiffness
        :data:`~skvalve.valve.setup.TIE_FACTOR` times the peak pressure over ``dhat``). 0.1 mm: within the barrier's
        range, i.e. touching. 0: frictionless arms.
    check_intersections
        assert after every accepted step that the collision mesh does not intersect
        (``has_intersections``, ~0.03 s on the 1.0 valve): a guard, since the collision-free line search makes it
        impossible by construction.
    """

    dhat: float = 0.1
    pressure_factor: float = 2.0
    exclude_within: float = 0.0
    friction: Friction | None = None
    tie_within: float = 0.1
    check_intersections: bool = True

    def __post_init__(self) -> None:
        _positive("ContactOptions", "dhat", self.dhat)
        _positive("ContactOptions", "pressure_factor", self.pressure_factor)
        _positive("ContactOptions", "exclude_within", self.exclude_within, zero=True)
        _positive("ContactOptions", "tie_within", self.tie_within, zero=True)


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
        iterations per step before it is cut back; a step whose iterations still each halve the residual goes on,
        up to twice as many (:data:`~skvalve.fem.solvers.incremental.CONTRACTING`).
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
    r"""The held load at the end time (:func:`skvalve.valve.run.close_valve`), in three stages, every accepted step a
    kept state:

    1. *descend*: energy trust-region steps (:func:`~skvalve.fem.solvers.trust_region.trust_region`) on the
       element-projected tangent under Marquardt's diagonal shift, up to ``max_radius`` on any node, the chordae branch
       points relaxed after each; one factorisation a step carries the leaflets the millimetres the path's damping
       left;
    2. *settle*: the same on the symmetric tangent with a uniform (Levenberg) shift fitted to the radius and the
       contact's stencils projected one by one (the sliding directions of a contact patch stay soft), while the
       coaptation forms;
    3. *proximal*: the path's steps with the load held, each a proximal step with the pseudo-mass :math:`c/h`
       (``StepOptions.damping`` over a pseudo-step :math:`h`) starting at the path's last step length and growing
       ``growth``-fold after each step of at most ``StepOptions.easy_iterations`` iterations, else by the ratio of
       the static residuals before and after the step (switched evolution relaxation, at most ``growth``;
       :func:`~skvalve.valve.run.proximal_growth`) and halved after a failed step, each solved to a tenth of the
       static residual it starts from, to ``rtol`` of the undamped problem. A step whose iterations run out is taken
       at its last iterate when that lowers the static residual (an inexact proximal step; the pseudo-step stays as
       it was).

    An energy stage hands on below ``proximal_below`` or when its energy drop stalls (the last 20 steps' average
    below ``stall_fraction`` of the stage's). Why proximal steps at the end: a follower pressure on the leaflets'
    open surface has no potential, and energy steps circle its equilibrium (the 1.0 annuloplasty valve's held load:
    400 settle steps between relative residuals 7e-4 and 1.8e-2, 5136 s, not converged, with Newton's tries that
    backtrack). A proximal step's fixed points are exactly the static equilibria, its pseudo-mass keeps each step's
    problem well posed while :math:`h` is short, and as :math:`h` grows the steps become Newton's: from the last of
    those 400 states four proximal steps converged it (61 s: 1.1e-3, 8.5e-5, 6.0e-6, 1.1e-6, 7.9e-8). Why not
    proximal steps sooner: from the descend stage's end (coaptation still forming, relative residual 0.85 and 9.9)
    they took 18-32 Newton iterations each on the 1.0 diseased valve (0.85 -> 0.037 in 4 steps, 1144 s) and failed
    twice in 40 on the annuloplasty valve, where settle steps cost one factorisation each.

    rtol
        the undamped, static residual asked for (relative to the end load's nodal pressure forces).
    max_steps
        accepted held steps in all before the run stops with its last state; 0: no held phase (the path only).
    max_radius
        the most any node moves in one energy step (mm; the first radius is a quarter of it).
    stall_fraction
        when an energy stage stalls (above).
    proximal_below
        the relative residual below which the energy stages hand on to the proximal steps. 1e-2: where the settle stage
        began to circle on the 1.0 valves.
    growth
        the proximal pseudo-step's factor after an easy step. 3: the damping falls a decade in about two steps, so a
        state near the equilibrium is reached by Newton's steps within a few, while a failed step costs one halving.
    """

    rtol: float = 1e-6
    max_steps: int = 600
    max_radius: float = 1.0
    stall_fraction: float = 0.2
    proximal_below: float = 1e-2
    growth: float = 3.0

    def __post_init__(self) -> None:
        for name in ("rtol", "max_radius", "proximal_below"):
            _positive("HoldOptions", name, getattr(self, name))
        if not 0.0 <= self.stall_fraction < 1.0:
            raise ValueError(f"HoldOptions.stall_fraction must lie in [0, 1); got {self.stall_fraction!r}")
        if not isinstance(self.growth, int | float) or not math.isfinite(self.growth) or not self.growth >= 1.0:
            raise ValueError(f"HoldOptions.growth must be a finite number >= 1; got {self.growth!r}")
        if not isinstance(self.max_steps, int) or isinstance(self.max_steps, bool) or self.max_steps < 0:
            raise ValueError(f"HoldOptions.max_steps must be an integer >= 0; got {self.max_steps!r}")


#: fields of :class:`HoldOptions` in kept states of earlier versions (Newton's tries in the settle stage), dropped on
#: reading
RETIRED_HOLD_FIELDS = ("newton_below",)


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
                   HoldOptions(**{key: value for key, value in data["hold"].items()
                                  if key not in RETIRED_HOLD_FIELDS}), data.get("end"), data.get("solver"))
