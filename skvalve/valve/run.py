r"""One call closes a Texas TriValve input: open valve to the converged end-systolic state, no hand repairs.

``skvalve valve close FILE`` runs :func:`close_valve`. The model is :func:`~skvalve.valve.model.valve_model` (F-bar
leaflet hexes, chordae cables, the input's annulus and papillary conditions and follower pressure, all with their
amplitudes in load factor = step time) plus :class:`~skvalve.fem.contact.IPCContact` on the leaflets' whole hex
boundary, on from the start: its barrier grows without bound as any gap closes, and every trial step is cut to 0.9 of
the collision-free share (continuous collision detection), so no iterate passes through a leaflet and no state needs
repair afterwards.

Path (:class:`~skvalve.valve.options.StepOptions`): incremental-potential steps
(:func:`~skvalve.fem.solvers.incremental.minimise_step`) with a viscous pseudo-mass :math:`cV_i/\Delta t`, whose length
grows after easy steps and halves after failed ones. The line search's merit is the incremental potential plus the
follower pressure's work along the ray, by the trapezoidal rule (the pressure on the leaflets' open surface has no
potential). The chordae branch points are swept to their own balance (with the step's pseudo-mass) on the first
iterate and after every accepted iteration (:func:`hub_relaxation`): when the papillary tips move, the cables' pull on
them is most of the residual. Held load (:class:`~skvalve.valve.options.HoldOptions`): energy trust-region stages
(:func:`energy_stages`: *descend* on the element-projected tangent, *settle* on the symmetric one; steps of at most a
millimetre, accepted by the energy they release) while the coaptation forms, then, below ``proximal_below`` or when
their energy drop stalls, the path's own steps with the load held: each a proximal step
:math:`\min_u \Pi(u) + \tfrac{c}{2h}\sum_i V_i|u_i - u_i^k|^2` whose pseudo-step :math:`h` starts at the path's last
step length and grows ``growth``-fold after every easy step (halved after a failed one), until the static residual is
below ``rtol`` (1e-6) of the end load's nodal forces. Each step is solved to a tenth of the static residual it starts
from; a step whose iterations run out is taken inexactly, at its last iterate, when that lowers the static residual
(the pseudo-step then stays as it was), as inexact proximal point methods allow. The follower pressure on an open
surface has no potential, so energy steps can circle its equilibrium; a proximal step's fixed points are exactly the
static equilibria, its pseudo-mass keeps each step's problem well posed while :math:`h` is short, and as :math:`h`
grows the steps become Newton's.

Output in ``out``: ``state.npz`` after every accepted step (atomic, :mod:`skvalve.valve.state`; ``resume=True``
continues from it and repeats the uninterrupted run), ``closure.log`` (one line per step), and at the end
``closure.pvd`` with its VTU file. Ctrl-C leaves the last kept state and raises :class:`KeyboardInterrupt`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
from tqdm.auto import tqdm

from ..fem.contact import IPCContact
from ..fem.elements.fbar import FBarTerm
from ..fem.elements.truss import Truss
from ..fem.errors import ConvergenceError, NonPositiveJacobianError, SingularSystemError, SolverError, StateRefused
from ..fem.solvers import linsolve
from ..fem.solvers.block_relaxation import BlockRelaxation
from ..fem.solvers.extension import MotionExtension
from ..fem.solvers.incremental import IncrementalOptions, StepFailed, minimise_step
from ..fem.solvers.ptc import switched_evolution_factor
from ..fem.solvers.trust_region import TrustRegionOptions, TrustRegionStep, trust_region
from ..io.abaqus import AbaqusModel
from ..io.files import replace_atomically
from .links import LINK_TERM
from .options import CloseOptions, HoldOptions
from .outputs import ClosureWriter
from .setup import ValveSetup, smallest_corner_jacobian, valve_setup
from .state import KeptState, read_state, write_state

__all__ = ["ClosureFailed", "CloseReport", "StepRecord", "close_valve", "energy_stages", "hub_relaxation",
           "relative_residual"]

logger = logging.getLogger("skvalve.valve")

STATE_FILE = "state.npz"
LOG_FILE = "closure.log"


class ClosureFailed(SolverError):
    """The closure could not go on: the step, its step time and why (the kept state is the last accepted one)."""


@dataclass
class StepRecord:
    """One accepted step: phase (``path``, or the held load's ``descend``, ``settle`` and ``proximal`` stages), step
    time, step length (path), trust radius (descend, settle) or pseudo-step (proximal), iterations (descend, settle: the
    trust region's tries, rejected ones included), static relative residual, contact pairs, seconds, the largest
    nodal motion (mm), and whether the step was solved to its tolerance (``exact``; False for a proximal step taken at
    its last iterate)."""

    phase: str
    t: float
    increment: float
    iterations: int
    relative_residual: float
    contact_pairs: int
    seconds: float
    moved: float = float("nan")
    exact: bool = True

    def line(self) -> str:
        size = {"path": "dt", "proximal": "h"}.get(self.phase, "radius")
        phase = self.phase if self.exact else f"{self.phase} (inexact)"
        return (f"{phase} t={self.t:.6g} {size}={self.increment:.3g} iterations={self.iterations} "
                f"relative_residual={self.relative_residual:.3e} contact_pairs={self.contact_pairs} "
                f"max_du={self.moved:.3g} seconds={self.seconds:.2f}")


@dataclass
class CloseReport:
    """What a closure did: steps, iterations, final residual, contact, the checks, wall time and its split."""

    input_name: str
    converged: bool
    t: float
    u: np.ndarray
    steps: int
    held_steps: int
    iterations: int
    relative_residual: float
    intersects: bool
    smallest_jacobian: float
    contact_pairs: int
    contact_area: float
    seconds: float
    records: list[StepRecord] = field(default_factory=list)
    failed_steps: int = 0

    def summary(self) -> str:
        return (f"{self.input_name}: {'converged' if self.converged else 'NOT converged'} at step time {self.t:.6g}; "
                f"{self.steps} path steps, {self.held_steps} held steps, {self.iterations} iterations, "
                f"{self.failed_steps} cut-backs; relative residual {self.relative_residual:.3e}; intersection "
                f"{'YES' if self.intersects else 'none'}; smallest corner Jacobian {self.smallest_jacobian:.3g}; "
                f"{self.contact_pairs} contact pairs, contact area {self.contact_area:.1f} mm^2; "
                f"{self.seconds:.1f} s")


def relative_residual(setup: ValveSetup, residual: np.ndarray) -> float:
    """The static relative residual: the free components' norm over the end load's nodal pressure forces
    (:func:`~skvalve.valve.setup.end_load_norm`), as the closure reports and converges it."""
    return float(np.linalg.norm(residual[setup.problem.pattern.free]) / setup.load_norm)


class _Outcome(NamedTuple):
    """A step's end: state, static residual (all dofs), iteration history; ``exact`` False for the last iterate of a
    step whose iterations ran out (:meth:`_Run.inexact`)."""

    u: np.ndarray
    residual: np.ndarray
    history: list[dict]
    exact: bool = True


class _Run:
    """The closure's loop: controller state, kept state, log and progress (one instance per call)."""

    def __init__(self, setup: ValveSetup, options: CloseOptions, out: Path | None, progress: bool,
                 callbacks: Sequence[Callable[[KeptState], None]]) -> None:
        self.setup, self.options, self.out, self.callbacks = setup, options, out, list(callbacks)
        self.problem = setup.problem
        self.end = float(options.end if options.end is not None else setup.model.end_time)
        # the input's step boundaries: path steps land on them (amplitudes and obstacle contact change there)
        self.breaks = sorted(w.start for w in getattr(setup.model, "steps", ()) if 0.0 < w.start < self.end)
        n = self.problem.space.n_dofs
        self.state = KeptState(0.0, np.zeros(n), setup.input_name, options, "path", options.steps.first)
        self.records: list[StepRecord] = []
        self.failed = 0
        self.progress = progress
        self.solver = linsolve.solver_name(options.solver)
        self.lines: list[str] = []
        # the path's sweep over the chordae branch points: to a tenth of what a path step may leave unbalanced
        self.path_hubs = hub_relaxation(setup, tol=0.1 * options.steps.rtol * setup.load_norm)
        self.carry = motion_extension(setup, self.solver)

    # ------------------------------------------------------------ kept state
    def resume(self, kept: KeptState) -> None:
        self.problem.restore(kept.terms)
        self.state = kept
        if self.out is not None and (self.out / LOG_FILE).is_file():
            self.lines = (self.out / LOG_FILE).read_text().splitlines()

    def keep(self, record: StepRecord | None) -> None:
        """Write the kept state (with the terms' committed state) and the log, after ``record`` (None: no new step)."""
        if record is not None:
            self.records.append(record)
            self.lines.append(record.line())
        self.state.terms = self.problem.state()
        if self.out is not None:
            write_state(self.out / STATE_FILE, self.state)
            text = "\n".join(self.lines) + "\n"
            replace_atomically(self.out / LOG_FILE, lambda temporary: temporary.write_text(text))
        for callback in self.callbacks:
            callback(self.state)

    # ------------------------------------------------------------ one step
    def step(self, t_new: float, inertia_scale: float, rtol: float, max_iter: int):
        """A minimisation from the kept state to ``t_new`` with the pseudo-mass ``inertia_scale`` x volumes."""
        s = self.state
        # converged relative to the end load's nodal forces (end_load_norm), as the static residual is reported
        opts = IncrementalOptions(rtol=rtol, reference=self.setup.load_norm, max_iter=max_iter,
                                  solver=self.options.solver)
        inertia = inertia_scale * self.setup.volumes
        u, residual, history = minimise_step(self.problem, s.u, s.t, t_new, s.u, inertia,
                                             s.steps + s.held_steps + 1, opts, self.solver, relax=self.path_hubs,
                                             carry=self.carry)
        return u, residual, history

    def attempt(self, t_new: float, inertia_scale: float, rtol: float, max_iter: int,
                inexact_below: float | None = None) -> _Outcome | None:
        """:meth:`step`, or ``None`` after rewinding the terms when it fails. A converged step whose state a term
        refuses (:class:`~skvalve.fem.errors.StateRefused`: an intersection among collision primitives that the
        barrier excludes) fails too, so the step is cut back instead of ending the run.

        ``inexact_below``: a step whose iterations ran out is still taken at its last iterate when the terms accept
        that state and its static relative residual is below this (an inexact proximal step)."""
        try:
            try:
                outcome = _Outcome(*self.step(t_new, inertia_scale, rtol, max_iter))
            except StepFailed as err:
                outcome = self.inexact(err, t_new, inexact_below)
                if outcome is None:
                    raise
            self.problem.check_state(outcome.u, t_new)
            return outcome
        except (StepFailed, NonPositiveJacobianError, SingularSystemError, StateRefused, np.linalg.LinAlgError) as err:
            self.problem.rewind()
            self.failed += 1
            logger.info("step to t=%.6g failed: %s", t_new, err)
            self.last_error = err
            return None

    def inexact(self, err: StepFailed, t_new: float, below: float | None) -> _Outcome | None:
        """The last iterate of a step that ran out of iterations (:attr:`StepFailed.last`) where it lowers the static
        relative residual below ``below`` (the caller still lets the terms vet it); else ``None``."""
        if below is None or err.last is None:
            return None
        outcome = _Outcome(*err.last, exact=False)
        relative = relative_residual(self.setup, outcome.residual)
        if not relative < below:
            logger.info("step to t=%.6g: its last iterate (relative residual %.3e) is not below %.3e", t_new,
                        relative, below)
            return None
        logger.info("step to t=%.6g: %s; its last iterate taken (relative residual %.3e < %.3e)", t_new, err,
                    relative, below)
        return outcome

    def accept(self, u: np.ndarray, t: float, residual: np.ndarray, history: list) -> tuple[float, float]:
        """Commit an accepted step; return its static relative residual and its largest nodal motion."""
        problem = self.problem
        problem.commit()  # its state was vetted in attempt()
        relative = relative_residual(self.setup, residual)
        s = self.state
        moved = float(np.max(np.abs(u - s.u), initial=0.0))
        s.u, s.t, s.relative_residual = u, float(t), relative
        s.iterations += len(history)
        return relative, moved

    # ------------------------------------------------------------ phases
    def path(self, bar) -> None:
        opts, s = self.options.steps, self.state
        while s.phase == "path":
            clock = time.perf_counter()
            dt = min(s.increment, self.end - s.t)
            t_new = self.end if self.end - (s.t + dt) < 1e-9 * self.end else s.t + dt
            t_new = min([t_new] + [b for b in self.breaks if s.t + 1e-9 * self.end < b < t_new])
            cut = t_new < s.t + dt  # landed on a break short of the planned length
            outcome = self.attempt(t_new, opts.damping / (t_new - s.t), opts.rtol, opts.max_iter)
            if outcome is None:
                s.increment = 0.5 * (t_new - s.t)
                if s.increment < opts.smallest:
                    raise ClosureFailed(f"{s.input}: load step {s.steps + 1} from step time {s.t:.6g} failed at "
                                        f"every length down to {opts.smallest:g}: {self.last_error}")
                continue
            u, residual, history, _ = outcome  # no inexact path steps
            step_length = t_new - s.t
            relative, moved = self.accept(u, t_new, residual, history)
            s.steps += 1
            grow = len(history) <= opts.easy_iterations
            base = dt if cut else step_length  # a step cut short by a break leaves the planned length as it was
            s.increment = min(opts.largest, base * opts.growth) if grow else base
            if t_new >= self.end:
                s.phase, s.increment = "hold", step_length
            pairs = self.setup.contact.active_pairs(u, t_new)
            self.keep(StepRecord("path", t_new, step_length, len(history), relative, pairs,
                                 time.perf_counter() - clock, moved))
            bar.update(step_length)
            bar.set_postfix(it=len(history), res=f"{relative:.1e}", pairs=pairs, dt=f"{step_length:.2g}")

    def hold(self, bar) -> None:
        """The held load (module docstring): the descend and settle stages, then proximal steps to ``hold.rtol``."""
        hold, s = self.options.hold, self.state
        if hold.max_steps == 0:  # the path only (e.g. a run that stops part-way along the load path)
            return
        if not any(float(np.max(np.abs(load.at(self.end)))) > 0.0 for load in self.setup.model.pressures):
            # before the pressure: leaflets hanging from chordae and annulus have no unique static state to hold
            logger.warning("%s: no pressure at step time %.6g: the path only, no held load", s.input, self.end)
            return
        stages = energy_stages(hold, self.setup.load_norm, self.options.solver)
        hubs = hub_relaxation(self.setup)
        while s.phase == "hold" and s.held_stage < len(stages):
            self.energy_stage(bar, stages[s.held_stage], hubs)
        while s.phase == "hold":
            self.proximal_step(bar)

    def energy_stage(self, bar, options: TrustRegionOptions, hubs: BlockRelaxation | None) -> None:
        """One of the energy trust-region stages, to its hand-on (``proximal_below``, a stall or its share of the
        held steps); the next stage goes on from its last state."""
        hold, s = self.options.hold, self.state
        clock = [time.perf_counter()]
        stage = s.held_stage
        name = ENERGY_STAGES[stage]

        def keep_step(event: TrustRegionStep) -> None:
            attempts = event.control.attempts - (s.control.attempts if s.control is not None else 0)
            s.u, s.relative_residual, s.control = event.u, float(event.relative_residual), event.control
            s.held_steps += 1
            s.iterations += attempts
            pairs = self.setup.contact.active_pairs(event.u, self.end)
            self.keep(StepRecord(name, self.end, event.control.radius, attempts, s.relative_residual, pairs,
                                 time.perf_counter() - clock[0], event.largest))
            clock[0] = time.perf_counter()
            bar.set_postfix(stage=name, held=s.held_steps, res=f"{s.relative_residual:.1e}", pairs=pairs)

        # the held steps left to the run, counted from this stage's start (a resumed stage has taken control.steps)
        left = hold.max_steps - (s.held_steps - (s.control.steps if s.control is not None else 0))
        options = replace(options, max_steps=max(min(options.max_steps, left), 1))
        try:
            result = trust_region(self.problem, self.end, s.u, options,
                                  callbacks=[keep_step], progress=False, relax=hubs,
                                  control=s.control)
        except ConvergenceError as err:  # stalled or out of steps: the next stage goes on from the last step
            logger.info("%s: the %s stage stopped (%s)", s.input, name, err)
            result = None
        if result is not None:
            s.u = result.u
        residual, _ = self.problem.assemble(s.u, self.end, tangent=False)
        s.relative_residual = relative_residual(self.setup, residual)
        s.held_stage, s.control = stage + 1, None
        if s.relative_residual <= hold.rtol:
            s.phase = "done"
        logger.info("%s: %s stage ends at relative residual %.3e", s.input, name, s.relative_residual)
        self.keep(None)

    def proximal_step(self, bar) -> None:
        """One held proximal step (its pseudo-step grown by :func:`proximal_growth`, halved after a failed one), or the
        end."""
        hold, opts, s = self.options.hold, self.options.steps, self.state
        if s.relative_residual <= hold.rtol:
            s.phase = "done"
            self.keep(None)
            return
        if s.held_steps >= hold.max_steps:
            raise ClosureFailed(f"{s.input}: held load not converged in {hold.max_steps} held steps (relative "
                                f"residual {s.relative_residual:.3e}; the kept state is the last accepted step)")
        clock = time.perf_counter()
        h, before = s.increment, s.relative_residual
        # the step's own tolerance: a tenth of the static residual it starts from, down to half the goal
        rtol = max(0.5 * hold.rtol, 0.1 * s.relative_residual)
        outcome = self.attempt(self.end, opts.damping / h, rtol, opts.max_iter, inexact_below=s.relative_residual)
        if outcome is None:
            s.increment = 0.5 * h
            if s.increment < opts.smallest:
                raise ClosureFailed(f"{s.input}: held step {s.held_steps + 1} failed at every pseudo-step down to "
                                    f"{opts.smallest:g}: {self.last_error}")
            return
        u, residual, history, exact = outcome
        relative, moved = self.accept(u, self.end, residual, history)
        s.held_steps += 1
        s.increment = h * proximal_growth(exact, len(history) <= opts.easy_iterations, before, relative, hold.growth)
        pairs = self.setup.contact.active_pairs(u, self.end)
        self.keep(StepRecord("proximal", self.end, h, len(history), relative, pairs, time.perf_counter() - clock,
                             moved, exact))
        bar.set_postfix(stage=2, held=s.held_steps, it=len(history), res=f"{relative:.1e}", pairs=pairs, h=f"{h:.2g}")


def proximal_growth(exact: bool, easy: bool, before: float, after: float, growth: float) -> float:
    """The held proximal pseudo-step's factor after an accepted step: ``growth`` after an easy exact step, else
    switched evolution relaxation's ratio of the static residuals ``before / after`` (between 1/2 and ``growth``;
    :func:`~skvalve.fem.solvers.ptc.switched_evolution_factor`) after an exact one, 1 after an inexact one.

    Why the residual ratio: on the 1.0 diseased valve's held load the pseudo-step stayed at 0.128 for six steps of
    16-40 iterations each (630 s) while the static residual fell 7.3e-3 -> 9.2e-4 by factors of 1.2-2.5 a step; once
    two steps were easy it grew threefold a step and five steps of 2-12 iterations closed it. The iteration count
    says how hard a step's own problem was, the residual ratio how far the damping still holds the state back."""
    if not exact:
        return 1.0
    return growth if easy else switched_evolution_factor(before, after, growth)


#: the held load's energy stages, in order (:func:`energy_stages`); the proximal steps follow them
ENERGY_STAGES = ("descend", "settle")


def energy_stages(options: HoldOptions, load_norm: float, solver: str | None = None) -> list[TrustRegionOptions]:
    """The held load's energy trust-region stages (:class:`~skvalve.valve.options.HoldOptions`), each ending below
    ``proximal_below`` or when its energy drop stalls: *descend* (the element-projected tangent under Marquardt's
    diagonal shift, steps scaled into the radius) and *settle* (the symmetric tangent, a uniform shift fitted to the
    radius, the IPC contact's stencils projected one by one); residuals relative to the end load's nodal forces."""
    common = {"radius": 0.25 * options.max_radius, "max_radius": options.max_radius, "rtol": options.proximal_below,
              "reference": load_norm, "max_steps": options.max_steps, "max_strain_increment": None,
              "stall_fraction": options.stall_fraction, "solver": solver}
    descend = TrustRegionOptions(project=True, **common)
    settle = TrustRegionOptions(project=False, fit_radius=3, shift_scaling="uniform", project_terms=(IPCContact.name,),
                                **common)
    return [descend, settle]


def hub_relaxation(setup: ValveSetup, tol: float = 1e-9) -> BlockRelaxation | None:
    """The chordae branch points (vertices of no leaflet cell, not prescribed) brought to equilibrium by the cables
    alone with the rest held (:mod:`skvalve.fem.solvers.block_relaxation`): a global step that sees a hub's slack side
    overshoots it, and unbalanced hubs would carry the residual (on the 1.0 diseased valve's held load, without it, 50
    hub nodes carried 96 % of the residual's square after 30 steps). None when the model has none."""
    problem = setup.problem
    in_cell = np.zeros(problem.space.n_u // problem.space.dim, dtype=bool)
    in_cell[np.unique(setup.model.mesh.t)] = True
    trusses = [term for term in problem.terms if isinstance(term, Truss)]
    hubs = np.flatnonzero(~in_cell)
    if hubs.size == 0 or not trusses:
        return None
    relax = BlockRelaxation(problem, problem.space.displacement_dofs(hubs).ravel(), trusses, tol=tol)
    return relax if relax.dofs.size else None


def motion_extension(setup: ValveSetup, solver: str | None = None) -> MotionExtension | None:
    """The prescribed annulus motion carried into the leaflets (:mod:`skvalve.fem.solvers.extension`) over the leaflet
    hexes and the LINK bars; not over the chordae, which a moving papillary tip does not drag (on the 1.0 annuloplasty
    valve's step to 0.081 the first residual was 1.4e7 load norms with the annulus moved alone, 4.2e3 carried over
    hexes and links, 1.3e5 over the chordae as well). None when the model has no solid term."""
    terms = [term for term in setup.problem.terms
             if isinstance(term, FBarTerm) or (isinstance(term, Truss) and term.name == LINK_TERM)]
    if not any(isinstance(term, FBarTerm) for term in terms):
        return None
    return MotionExtension(setup.problem, terms, solver)


def close_valve(source: str | Path | AbaqusModel, options: CloseOptions | None = None, out: str | Path | None = None,
                resume: bool = False, progress: bool = True, setup: ValveSetup | None = None,
                callbacks: Sequence[Callable[[KeptState], None]] = ()) -> CloseReport:
    """Close the valve of ``source`` (module docstring) and return the :class:`CloseReport`.

    ``out``: folder of the kept state, log and VTU output (None: nothing written, no resume). ``resume``: continue
    from ``out/state.npz`` (with the options it was computed with). ``setup``: a ready :func:`valve_setup`.
    Raises :class:`ClosureFailed` when a step fails at every length (the kept state is the last accepted one).
    """
    clock = time.perf_counter()
    out = None if out is None else Path(out)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    kept = None
    if resume:
        if out is None:
            raise ValueError("close_valve: resume needs an output folder (out)")
        name = setup.input_name if setup is not None else Path(str(getattr(source, "path", source))).name
        kept = read_state(out / STATE_FILE, input_name=name)
        options = kept.options
    options = options or CloseOptions()
    setup = setup or valve_setup(source, options)
    run = _Run(setup, options, out, progress, callbacks)
    if kept is not None:
        if kept.u.shape != (setup.problem.space.n_dofs,):
            raise ValueError(f"kept state {out / STATE_FILE}: {kept.u.size} values for {setup.problem.space.n_dofs} "
                             "dofs")
        run.resume(kept)
    else:
        setup.problem.assemble(run.state.u, 0.0, tangent=False, step=0)
        setup.problem.commit()
    with tqdm(total=run.end, initial=run.state.t, disable=not progress, desc=f"closing {setup.input_name}",
              unit="step time", bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} [{elapsed}<{remaining}{postfix}]") as bar:
        run.path(bar)
        run.hold(bar)
    s = run.state
    if out is not None:
        _write_final(setup, s.u, s.t, out / "closure.pvd")
    return CloseReport(s.input, s.phase == "done", s.t, s.u, s.steps, s.held_steps, s.iterations,
                       s.relative_residual, setup.contact.intersects(s.u, s.t), smallest_corner_jacobian(setup, s.u),
                       setup.contact.active_pairs(s.u, s.t), setup.contact.contact_area(s.u, s.t),
                       time.perf_counter() - clock, run.records, run.failed)


def _write_final(setup: ValveSetup, u: np.ndarray, t: float, path: Path) -> None:
    """The final state as a one-entry VTU/PVD series (:class:`~skvalve.valve.outputs.ClosureWriter`)."""
    ClosureWriter(path, setup).write(t, u)
