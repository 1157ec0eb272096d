r"""Implicit, quasi-static closure of a Texas TriValve model: open configuration to end-systole.

The shipped inputs close the valve with Abaqus/Explicit (mass scaling, bulk viscosity). Here the same
model (:func:`~skvalve.valve.model.valve_model`: F-bar leaflet hexes, collapsed chordae cables, amplitude
conditions, follower pressure) is solved by Newton's method in load factor = step time, staged as in the
input: papillary-muscle motion (``Amp-2``, smooth step over 0–0.5) then the transvalvular pressure
(``Amp-1``, smooth step over 0.5–1.5). Two terms are added:

* :class:`~skvalve.fem.contact.SurfaceContact`: frictionless penalty self-contact of the union of the
  input's contact surfaces (``LEAFLET_SURFACES_INNER`` and ``LEAFLET_RIM_TIP``; the input uses kinematic
  contact with friction 0.001, taken as frictionless);
* :class:`~skvalve.fem.damping.ViscousDamping`: pseudo-transient damping with a coefficient that vanishes at
  ``damping_off`` (before the end), so the final state is an equilibrium of the undamped problem; the
  undamped residual there is reported (:attr:`ClosureRun.undamped_residual`).

Every converged step goes to the callbacks (VTU series of :mod:`.outputs`); a failed step raises the
solver's error with step and load factor, carrying the converged steps (``error.last_converged``). The route the
valve runs take, relaxation without Newton's load steps, is :mod:`.relaxation`.
"""

from __future__ import annotations

import math
import resource
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fem.amplitudes import GeometricRamp, smooth_step_polynomial
from ..fem.contact import SurfaceContact
from ..fem.damping import ViscousDamping, lumped_volume, undamped_residual
from ..fem.newton import StepEvent, solve
from ..fem.problem import Problem
from ..fem.truss import Truss
from ..io.abaqus import AbaqusModel, read_model, trivalve_input
from ..io.files import replace_atomically
from .model import ValveModel, valve_model
from .surfaces import contact_surface, contact_surface_names, thinnest_stack

__all__ = ["ClosureOptions", "ClosureSetup", "ClosureRun", "StagedDamping", "closure_setup", "contact_surface",
           "damping_weights", "load_factors", "run_closure"]


@dataclass
class ClosureOptions:
    """Controls of the closure (units of the input: mm, MPa, s).

    penalty : contact penalty (MPa/mm): overlap ~ pressure / (2 penalty) (two-pass).
    damping : :math:`c_0` of the damping schedule (N·s/mm⁴: force per lumped volume and pseudo-velocity) and
    ``damping_off``, the step time from which it is zero. Keep :math:`c_0 V v` far below what the leaflets carry:
    the papillary tips move 14 mm in 0.5 (peak pseudo-velocity ~50 mm per unit step time) and drag ~10³ mm³ of
    leaflet, while a 1 kPa leaflet 0.78 mm thick carries ~10⁻² N across 30 mm; :math:`c_0 = 10^{-3}` gave
    damping forces of tens of newtons that the chords had to overcome (their exponential law then blew up),
    :math:`10^{-6}` gives ~0.05 N at the peak and still supports otherwise free nodes.
    papillary_steps, pressure_steps : nominal load steps over 0–``pressure_start`` and ``pressure_start``–``end``.
    pressure_start : step time at which the pressure amplitude starts (0.5 in the 1.0 inputs: papillary motion
    first; 0 where everything ramps together, as in the 1.1 healthy input).
    end : last step time (1.5 = end-systole; less for a partial closure).
    max_increment : optional cap (mm) on any node's displacement change per Newton iteration
    (:func:`~skvalve.fem.newton.solve`); off by default: on the 1.0 valve it slowed the papillary stage (each
    tip step needs the leaflet edges to follow by millimetres) more than it saved in cut-backs.
    regularization : initial Levenberg–Marquardt shift of the tangent in each step (:func:`~skvalve.fem.newton.solve`).
    pressure_damping : :math:`c_0` from ``pressure_start`` on, decaying to zero at ``damping_off``
    (:class:`StagedDamping`): the leaflets under the first, tiny pressures are nearly free, and nothing prescribed
    drags them there, so they take far more damping than the papillary stage does.
    cable_slack_fraction : the cables' stiffness below their slack length, relative to their small-strain modulus
    (:meth:`~skvalve.valve.model.ValveModel.problem`; Abaqus's T3D2 chordae resist compression with their full law).
    cable_compression : the cables that are one input truss carry their law in compression as well, as the input's
    trusses do (``ValveModel.problem(compression=True)``); collapsed chains stay tension-only.
    contact_exclude_within : node-face pairs whose reference distance is below this never contact
    (:class:`~skvalve.fem.contact.SurfaceContact` ``exclude_within``; on the 1.0 valve the only pairs of the papillary
    stage were rim nodes against the inner face of their own leaflet 0.5 mm away, across the 0.78 mm thick corner).
    contact_blend : 0 for closest-triangle contact; a band beta > 0 for blended contact, whose energy is continuous
    across triangle edges and has no search memory (:class:`~skvalve.fem.contact.SurfaceContact` ``blend``).
    contact_barrier : ``None`` for the penalty alone; else the overlap (a fraction of the search depth) from which a log
    barrier adds pressure that grows without bound towards the clearance limit's floor
    (:class:`~skvalve.fem.contact.SurfaceContact` ``barrier``, :mod:`~skvalve.fem.contact.laws`).
    contact_depth : the contact's search depth g_max (mm; ``SurfaceContact`` ``max_penetration``): deeper
    passes are ignored and the clearance limit keeps steps to three quarters of it. ``None``: a quarter of the
    thinnest stack on extruded shells (their two skins a thickness apart must not pair), the mean face edge on bricks.
    contact_loaded_faces : also put the faces the input loads with pressure (the leaflets' ventricular skins on the
    1.0 bricks, ``Leaflet_Surfaces_Outer``) in contact. The 1.0 inputs name only the inner (atrial) skins and the rim,
    so a node that meets another leaflet from its ventricular side enters its solid unopposed and is seen only once
    it is within the search depth of the inner skin, already in the fade-out; extruded shells are double-sided
    anyway (:mod:`.surfaces`).
    contact_smoothing : the overlap (mm) over which the contact pressure is rounded as a pair switches on
    (:class:`~skvalve.fem.contact.SurfaceContact` ``smoothing``; ``None``: 1 % of the surface's mean face edge).
    contact_ramp : the penalty rises from zero at ``contact_from`` to ``penalty`` over this step-time interval (a smooth
    step): folds that overlap when it switches on are pushed apart gradually (switched on at once, three overlapping
    pairs at the free edge of the 1.0 valve threw their nodes by millimetres and stalled the pseudo-time steps at
    ~1e-6).
    contact_from : step time from which the contact penalty acts (the pressure's start by :meth:`for_model`): in the
    papillary stage the chords pull the leaflets apart, and the few pairs that folds of one leaflet make there
    (1–7 on the 1.0 valve) switched on and off between iterates and stalled Newton.
    insertion : ``"patch"`` spreads each chord's pull over the cells around its insertion (a modelling
    change from the input's point attachment, see :func:`~skvalve.valve.chordae.insertion_patches`), ``"node"``
    keeps the point attachment.
    :meth:`for_model` derives ``end``, ``pressure_start``, ``damping_off`` and ``cable_stiffening`` from an input.
    rtol, atol : Newton tolerances: relative to reactions/loads, and an absolute floor (N) for the papillary
    stage, whose loads and reactions are nearly zero (pressure load at the end: about 8 N).
    cable_softening, cable_stiffening : the chordae (and any other bars: annuloplasty links) start with their law
    scaled by ``cable_softening`` and stiffen geometrically to it over the step-time interval ``cable_stiffening``
    (:class:`~skvalve.fem.amplitudes.GeometricRamp`); 1 switches the continuation off.
    path_rtol, path_atol : looser tolerances for the steps while the damping acts (a pseudo-transient path,
    not equilibria of the problem); the steps from ``damping_off`` on are solved to ``rtol, atol``.
    """

    penalty: float = 1.0
    damping: float = 1e-6
    damping_off: float = 1.25
    papillary_steps: int = 40
    pressure_steps: int = 20
    end: float = 1.5
    max_cutbacks: int = 8
    max_iter: int = 30
    rtol: float = 1e-6
    atol: float = 1e-6
    solver: str | None = None
    cable_softening: float = 1e-3
    path_rtol: float = 1e-4
    path_atol: float = 1e-5
    cable_stiffening: tuple[float, float] = (0.4, 0.6)
    pressure_start: float = 0.5
    insertion: str = "patch"
    max_increment: float | None = None
    regularization: float = 0.0
    contact_from: float = 0.5
    contact_ramp: float = 0.0
    contact_exclude_within: float = 0.0
    contact_blend: float = 0.0
    contact_barrier: float | None = None
    contact_depth: float | None = None
    contact_loaded_faces: bool = False
    contact_smoothing: float | None = None
    cable_slack_fraction: float = 1e-6
    cable_compression: bool = False
    pressure_damping: float = 1e-4

    def __post_init__(self) -> None:
        _check_length("contact_depth", self.contact_depth, "a positive length (mm)", zero=False)
        _check_length("contact_smoothing", self.contact_smoothing, "a length >= 0 (mm)", zero=True)
        if not isinstance(self.contact_loaded_faces, (bool, np.bool_)):
            raise ValueError("ClosureOptions.contact_loaded_faces must be True or False; "
                             f"got {self.contact_loaded_faces!r}")

    @classmethod
    def for_relaxation(cls, model: ValveModel, **overrides) -> ClosureOptions:
        """:meth:`for_model` set up for :func:`.relaxation.relax_closure`: no damping term (the solver damps), the
        chordae at their full law from the start (no soft start: the pseudo-transient steps follow the tips without it),
        the contact penalty switched on by a smooth step over 0.1 of step time from the pressure's start (from the start
        instead, one rim node of the 1.0 diseased valve, paired with its own leaflet 3.3 mm away, throttled the
        papillary stage to pseudo-steps of 1e-5 by its edges' stretch limit), no contact between skins that are less
        than 1 mm apart in the reference (more than the 0.78 mm leaflet thickness), the single input trusses carrying
        their law in compression as the input's do (``cable_compression``: the fans of single trusses at the chordae
        branch points are then struts, not mechanisms held by slack springs), and blended contact (``contact_blend``
        0.1: on the 1.0 diseased valve the closest-triangle rule left 64 % of the held residual's square on one crease
        of the septal leaflet, 50 % of it on two nodes; blended from the pressure's start, 0.4 % on contact nodes, half
        of it spread over 2873 nodes)."""
        fitted = {"damping": 0.0, "cable_softening": 1.0, "contact_ramp": 0.1, "contact_exclude_within": 1.0,
                  "cable_compression": True, "contact_blend": 0.1}
        fitted.update(overrides)
        return cls.for_model(model, **fitted)

    @classmethod
    def for_model(cls, model: ValveModel, **overrides) -> ClosureOptions:
        """Options fitted to a model's step: ``end`` its step time, ``pressure_start`` the start of its pressure
        amplitude, damping off at three quarters of the pressure stage, cables stiffening over
        0.8–1.2 x ``pressure_start`` (no soft start when pressure and papillary motion ramp together)."""
        starts = [float(p.amplitude.times[0]) for p in model.pressures if p.amplitude is not None]
        pressure_start = min(starts) if starts else 0.0
        end = float(model.end_time)
        fitted = {"end": end, "pressure_start": pressure_start, "contact_from": pressure_start,
                  "damping_off": pressure_start + 0.75 * (end - pressure_start)}
        if pressure_start > 0.0:
            fitted["cable_stiffening"] = (0.8 * pressure_start, min(1.2 * pressure_start, end))
        else:
            fitted["cable_softening"] = 1.0
        fitted.update(overrides)
        return cls(**fitted)


def _check_length(name: str, value, what: str, zero: bool) -> None:
    """Refuse a ClosureOptions length that is not None, a finite number, and positive (or >= 0 with ``zero``)."""
    if value is None:
        return
    if not (isinstance(value, (int, float)) and math.isfinite(value) and (value >= 0.0 if zero else value > 0.0)):
        raise ValueError(f"ClosureOptions.{name} must be {what} or None; got {value!r}")


@dataclass
class ClosureSetup:
    """The model, its problem and the added contact and damping terms."""

    abaqus: AbaqusModel
    model: ValveModel
    problem: Problem
    contact: SurfaceContact
    damping: ViscousDamping | None
    leaflet_of_vertex: np.ndarray


@dataclass
class ClosureRun:
    """What a closure run did: steps, iterations, contact pairs, times, and the undamped residual at the end."""

    load_factors: list[float] = field(default_factory=list)
    iterations: list[int] = field(default_factory=list)
    contact_pairs: list[int] = field(default_factory=list)
    seconds: float = 0.0
    peak_memory_mb: float = 0.0
    undamped_residual: tuple[float, float] | None = None
    u: np.ndarray | None = None
    error: str | None = None
    timings: dict[str, float] = field(default_factory=dict)
    #: negative eigenvalues of the symmetric tangent at the converged held state (trust region with PARDISO)
    negative_eigenvalues: int | None = None
    #: accepted steps of each held stage (:func:`.relaxation.relax_closure` with a sequence of trust-region options)
    stage_steps: list[int] = field(default_factory=list)


def load_factors(options: ClosureOptions) -> np.ndarray:
    """Nominal step times: ``papillary_steps`` over (0, ``pressure_start``], ``pressure_steps`` over
    (``pressure_start``, ``end``] (all ``pressure_steps`` when the pressure starts at 0)."""
    split = options.pressure_start
    first = np.linspace(0.0, min(split, options.end), options.papillary_steps + 1)[1:] if split > 0 else np.empty(0)
    if options.end <= split:
        return first
    return np.concatenate([first, np.linspace(split, options.end, options.pressure_steps + 1)[1:]])


def closure_setup(path=None, options: ClosureOptions | None = None, abaqus: AbaqusModel | None = None,
                  model: ValveModel | None = None) -> ClosureSetup:
    """Read the input (``path``; default the shipped diseased 1.0 valve) unless ``abaqus`` (and ``model``) are given,
    and build problem, contact, damping."""
    options = options or ClosureOptions()
    if abaqus is None:
        path = trivalve_input() if path is None else path
        if path is None:
            raise FileNotFoundError("Texas TriValve input not found: set $SKVALVE_TRIVALVE to the .inp file or its "
                                    "folder (model files of Mathur et al. 2022, CC BY-NC-SA 4.0)")
        abaqus = read_model(path)
    model = valve_model(abaqus) if model is None else model
    problem = model.problem(insertion=options.insertion, slack_fraction=options.cable_slack_fraction,
                            compression=options.cable_compression)
    if options.cable_softening != 1.0:
        ramp = GeometricRamp(options.cable_softening, *options.cable_stiffening)
        for term in problem.terms:
            if isinstance(term, Truss):
                term.stiffness_scale = ramp
    names = contact_surface_names(abaqus)
    if options.contact_loaded_faces:  # contact_surface keeps a face that two surfaces share once
        names += tuple(dict.fromkeys(load.surface for load in model.pressures))
    surface = contact_surface(abaqus, model, names)
    # extruded shells: the two skins of one stack face each other a thickness apart; a search depth of a
    # quarter of the thinnest stack keeps them from pairing (bricks: the contact term's default depth)
    thinnest = thinnest_stack(model, abaqus)
    depth = None if thinnest is None else 0.25 * thinnest
    if options.contact_depth is not None:
        depth = float(options.contact_depth)
    penalty = options.penalty if options.contact_from <= 0.0 and options.contact_ramp <= 0.0 else \
        _PenaltyFrom(options.penalty, options.contact_from, options.contact_ramp)
    contact = problem.add_term(SurfaceContact(problem.space, surface, penalty, max_penetration=depth,
                                              exclude_within=options.contact_exclude_within,
                                              blend=options.contact_blend, barrier=options.contact_barrier,
                                              smoothing=options.contact_smoothing))
    damping = None
    if options.damping > 0.0:
        schedule = StagedDamping(options.damping, options.pressure_damping, options.pressure_start,
                                 options.damping_off)
        damping = problem.add_term(ViscousDamping(problem.space, schedule, weighting=damping_weights(problem.space)))
    leaflet = np.full(model.mesh.p.shape[1], -1, dtype=np.int64)
    leaflet[model.mesh.t] = model.regions[None, :]
    return ClosureSetup(abaqus, model, problem, contact, damping, leaflet)


def run_closure(setup: ClosureSetup, options: ClosureOptions | None = None, callbacks=(), progress: bool = True,
                verbose: bool = False, u0: np.ndarray | None = None, t0: float = 0.0) -> ClosureRun:
    """Solve the staged closure; never raises for a failed step: the run records the error and the last state.

    The returned :class:`ClosureRun` has the converged step times, Newton iterations and active contact pairs
    per step, wall time, peak resident memory of the process, and the undamped residual at the last converged state.
    ``u0, t0``: resume from a converged state (e.g. the last one a run kept on disk); earlier step times are skipped.
    """
    options = options or ClosureOptions()
    run = ClosureRun()
    if u0 is not None and setup.damping is not None:
        setup.damping.committed_u, setup.damping.committed_t = np.array(u0, dtype=float), float(t0)

    stage_timings: dict[int, dict] = {}

    def record(event: StepEvent) -> None:
        stage_timings[id(event.result)] = event.result.timings  # cumulative per solve: setup, assembly, solve
        run.load_factors.append(float(event.load_factor))
        run.iterations.append(len(event.result.histories[-1]))
        run.contact_pairs.append(setup.contact.last_pairs.touching if setup.contact.last_pairs is not None else 0)
        run.u = event.u

    start = time.perf_counter()
    factors = load_factors(options)
    factors = factors[factors > t0 * (1 + 1e-12)]
    damped_until = options.damping_off if setup.damping is not None else 0.0
    stages = [(factors[factors < damped_until], options.path_rtol, options.path_atol),
              (factors[factors >= damped_until], options.rtol, options.atol)]
    stage_callbacks = [record, *callbacks]
    try:
        for steps, rtol, atol in stages:
            if steps.size == 0:
                continue
            solve(setup.problem, steps, rtol=rtol, atol=atol, max_iter=options.max_iter,
                  max_cutbacks=options.max_cutbacks, solver=options.solver, progress=progress, verbose=verbose,
                  u0=u0, t0=t0, callbacks=stage_callbacks, max_increment=options.max_increment,
                  regularization=options.regularization)
            u0, t0 = run.u, run.load_factors[-1]
            stage_callbacks = [_AfterStart(callback) for callback in (record, *callbacks)]
    except Exception as err:  # noqa: BLE001 - a failed closure is a result to report, with its last state
        run.error = f"{type(err).__name__}: {err}"
    finally:
        run.peak_memory_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB
        for timings in stage_timings.values():
            for key, value in timings.items():
                run.timings[key] = run.timings.get(key, 0.0) + value
        run.seconds = time.perf_counter() - start
    if run.u is not None:
        run.undamped_residual = undamped_residual(setup.problem, run.u, run.load_factors[-1])
    return run


def damping_weights(space) -> np.ndarray:
    """Lumped nodal volumes, with the nodes of no leaflet cell (chordae branch points) given the median nodal
    volume: a branch point whose cables are all slack has only their slack springs, and without damping Newton
    threw such points by tens of millimetres per iteration."""
    weights = lumped_volume(space)
    displacement = weights[: space.n_u]
    bare = displacement == 0.0
    if np.any(bare) and np.any(~bare):
        displacement[bare] = np.median(displacement[~bare])
    return weights


@dataclass(frozen=True)
class StagedDamping:
    r"""Damping coefficient of the two stages: ``papillary`` before ``pressure_start``, then
    :math:`c_p\,(1 - \tau)^2` with :math:`\tau = (t - t_p)/(t_\text{off} - t_p)`, zero from ``t_off`` on."""

    papillary: float
    pressure: float
    pressure_start: float
    t_off: float

    def __call__(self, t: float) -> float:
        if t < self.pressure_start:
            return self.papillary
        if t >= self.t_off:
            return 0.0
        return self.pressure * (1.0 - (t - self.pressure_start) / (self.t_off - self.pressure_start)) ** 2


@dataclass(frozen=True)
class _PenaltyFrom:
    """Contact penalty: zero before ``start``, ``value`` from ``start + ramp`` on, a smooth step in between."""

    value: float
    start: float
    ramp: float = 0.0

    def __call__(self, t: float) -> float:
        if t < self.start:
            return 0.0
        if self.ramp <= 0.0 or t >= self.start + self.ramp:
            return self.value
        return self.value * float(smooth_step_polynomial((t - self.start) / self.ramp))


class _AfterStart:
    """A callback that skips the start state of a solve (the last state of the previous stage, already seen)."""

    def __init__(self, callback) -> None:
        self.callback = callback

    def __call__(self, event: StepEvent) -> None:
        if event.step > 0:
            self.callback(event)


def write_log(run: ClosureRun, path: Path) -> None:
    """A plain-text summary of the run (atomic write)."""
    lines = [f"seconds {run.seconds:.1f}", f"peak_memory_mb {run.peak_memory_mb:.0f}",
             "timings " + " ".join(f"{key}={value:.1f}" for key, value in run.timings.items()),
             f"steps {len(run.load_factors) - 1}", f"newton_iterations {sum(run.iterations)}",
             f"last_load_factor {run.load_factors[-1] if run.load_factors else float('nan'):.6g}",
             f"undamped_residual {run.undamped_residual}", f"negative_eigenvalues {run.negative_eigenvalues}",
             f"error {run.error}"]
    lines += [f"step {k} t={t:.5g} iterations={i} contact_pairs={c}"
              for k, (t, i, c) in enumerate(zip(run.load_factors, run.iterations, run.contact_pairs, strict=True))]
    replace_atomically(path, lambda temporary: temporary.write_text("\n".join(lines) + "\n"))
