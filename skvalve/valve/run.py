r"""One call closes a Texas TriValve input: open valve to the converged end-systolic state, no hand repairs.

``skvalve valve close FILE`` runs :func:`close_valve`. The model is :func:`~skvalve.valve.model.valve_model` (F-bar
leaflet hexes, chordae cables, the input's annulus and papillary conditions and follower pressure, all with their
amplitudes in load factor = step time) plus :class:`~skvalve.fem.contact.IPCContact` on the leaflets' whole hex
boundary, on from the start: its barrier grows without bound as any gap closes, and every trial step is cut to 0.9 of
the collision-free share (continuous collision detection), so no iterate passes through a leaflet and no state needs
repair afterwards.

Path (:class:`~skvalve.valve.options.StepOptions`): incremental-potential steps
(:func:`~skvalve.fem.incremental.minimise_step`) with a viscous pseudo-mass :math:`cV_i/\Delta t`, whose length
grows after easy steps and halves after failed ones. Held load (:class:`~skvalve.valve.options.HoldOptions`): the
same steps at the end time with the pseudo-step doubling after each converged one (the pseudo-mass fading), each
converged to a tenth of the static residual it starts from (or, out of iterations, kept when it lowered the static
residual), and the static problem once the static residual is small, solved to ``rtol`` (1e-6) of the undamped
problem. The line search's merit is the incremental potential plus the follower pressure's work
along the ray, by the trapezoidal rule (the pressure on the leaflets' open surface has no potential).

Output in ``out``: ``state.npz`` after every accepted step (atomic, :mod:`skvalve.valve.state`; ``resume=True``
continues from it and repeats the uninterrupted run), ``closure.log`` (one line per step), and at the end
``closure.pvd`` with its VTU file. Ctrl-C leaves the last kept state and raises :class:`KeyboardInterrupt`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np
from tqdm.auto import tqdm

from ..fem import linsolve
from ..fem.errors import NonPositiveJacobianError, SingularSystemError, SolverError
from ..fem.incremental import IncrementalOptions, StepFailed, minimise_step
from ..io.abaqus import AbaqusModel
from ..io.files import replace_atomically
from .options import CloseOptions
from .outputs import ClosureWriter
from .setup import ValveSetup, smallest_corner_jacobian, valve_setup
from .state import KeptState, read_state, write_state

__all__ = ["ClosureFailed", "CloseReport", "StepRecord", "close_valve", "relative_residual"]

logger = logging.getLogger("skvalve.valve")

STATE_FILE = "state.npz"
LOG_FILE = "closure.log"


class ClosureFailed(SolverError):
    """The closure could not go on: the step, its step time and why (the kept state is the last accepted one)."""


@dataclass
class StepRecord:
    """One accepted step: phase, step time, step length, iterations, static relative residual, contact pairs."""

    phase: str
    t: float
    increment: float
    iterations: int
    relative_residual: float
    contact_pairs: int
    seconds: float
    converged: bool = True  # False: a held step kept for its progress after it ran out of iterations

    def line(self) -> str:
        return (f"{self.phase} t={self.t:.6g} dt={self.increment:.3g} iterations={self.iterations} "
                f"relative_residual={self.relative_residual:.3e} contact_pairs={self.contact_pairs} "
                f"seconds={self.seconds:.2f}{'' if self.converged else ' unconverged'}")


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
    """A step's end: state, static residual (all dofs), iteration history, whether it met its tolerance."""

    u: np.ndarray
    residual: np.ndarray
    history: list[dict]
    converged: bool


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
        # the static relative residual at which the static problem last failed: it is tried again only once the held
        # steps have lowered the residual tenfold (from an unchanged state it would fail the same way)
        self.static_failed_at = float("inf")

    # ------------------------------------------------------------ kept state
    def resume(self, kept: KeptState) -> None:
        self.problem.restore(kept.terms)
        self.state = kept
        if self.out is not None and (self.out / LOG_FILE).is_file():
            self.lines = (self.out / LOG_FILE).read_text().splitlines()

    def keep(self, record: StepRecord) -> None:
        self.records.append(record)
        self.state.terms = self.problem.state()
        self.lines.append(record.line())
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
                                             s.steps + s.held_steps + 1, opts, self.solver)
        return u, residual, history

    def attempt(self, t_new: float, inertia_scale: float, rtol: float, max_iter: int,
                progress_only: bool = False) -> _Outcome | None:
        """:meth:`step`, or ``None`` after rewinding the terms when it fails. ``progress_only``: a step that ran out
        of iterations is still kept (unconverged) when its last iterate's static residual is below the kept
        state's (a held step only has to make progress towards the static equilibrium)."""
        try:
            return _Outcome(*self.step(t_new, inertia_scale, rtol, max_iter), True)
        except (StepFailed, NonPositiveJacobianError, SingularSystemError, np.linalg.LinAlgError) as err:
            last = getattr(err, "last", None) if progress_only else None
            if last is not None and relative_residual(self.setup, last[1]) < self.state.relative_residual:
                u, _, history = last
                residual, _ = self.problem.assemble(u, t_new, tangent=False)  # the terms' last state is u's
                logger.info("held step to t=%.6g kept unconverged after %d iterations: %s", t_new, len(history), err)
                return _Outcome(u, residual, history, False)
            self.problem.rewind()
            self.failed += 1
            logger.info("step to t=%.6g failed: %s", t_new, err)
            self.last_error = err
            return None

    def accept(self, u: np.ndarray, t: float, residual: np.ndarray, history: list) -> float:
        """Commit an accepted step and return its static relative residual."""
        problem = self.problem
        problem.commit()
        problem.check_state(u, t)
        relative = relative_residual(self.setup, residual)
        s = self.state
        s.u, s.t, s.relative_residual = u, float(t), relative
        s.iterations += len(history)
        return relative

    def idle(self, rtol: float) -> bool:
        """True when the kept state already meets a damped step's convergence test at ``rtol`` (:meth:`step`), so
        that a damped held step would accept it without an iteration."""
        residual, _ = self.problem.assemble(self.state.u, self.end, tangent=False)
        return relative_residual(self.setup, residual) <= rtol

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
            u, residual, history, _ = outcome
            step_length = t_new - s.t
            relative = self.accept(u, t_new, residual, history)
            s.steps += 1
            grow = len(history) <= opts.easy_iterations
            base = dt if cut else step_length  # a step cut short by a break leaves the planned length as it was
            s.increment = min(opts.largest, base * opts.growth) if grow else base
            if t_new >= self.end:
                s.phase, s.increment = "hold", step_length
            pairs = self.setup.contact.active_pairs(u, t_new)
            self.keep(StepRecord("path", t_new, step_length, len(history), relative, pairs,
                                 time.perf_counter() - clock))
            bar.update(step_length)
            bar.set_postfix(it=len(history), res=f"{relative:.1e}", pairs=pairs, dt=f"{step_length:.2g}")

    def hold(self, bar) -> None:
        opts, steps, s = self.options.hold, self.options.steps, self.state
        if opts.max_steps == 0:  # the path only (e.g. a run that stops part-way along the load path)
            return
        if not any(float(np.max(np.abs(load.at(self.end)))) > 0.0 for load in self.setup.model.pressures):
            # before the pressure: leaflets hanging from chordae and annulus have no unique static state to hold
            logger.warning("%s: no pressure at step time %.6g: the path only, no held load", s.input, self.end)
            return
        while s.phase == "hold":
            if s.held_steps >= opts.max_steps:
                raise ClosureFailed(f"{s.input}: held load not converged in {opts.max_steps} steps (relative "
                                    f"residual {s.relative_residual:.3e}; the kept state is the last one)")
            clock = time.perf_counter()
            # a damped held step converges to a tenth of the static residual it starts from (a forcing term: at the
            # path's looser tolerance a state the path left at, say, 0.9 of it would be accepted as it is, and the
            # held steps would not move), not looser than the path's tolerance (on the 1.0 diseased valve's held
            # load, at a static residual of 0.2, held steps converged to a tenth of it let the static residual rise,
            # 0.2067 -> 0.2086 -> 0.2119, where steps converged to 1e-3 lowered it at every step), and not below the
            # hold's aim
            forcing = (min(steps.rtol, max(opts.rtol, 0.1 * s.relative_residual))
                       if np.isfinite(s.relative_residual) else steps.rtol)
            # the static problem once the static residual is small, or where a damped held step would find nothing to
            # do at its tolerance (a held load with hardly any reaction: the relative residual stays large however
            # long the pseudo-step grows)
            idle = self.idle(forcing)
            small = np.isfinite(s.relative_residual) and s.relative_residual <= opts.static_below
            static = idle or (small and s.relative_residual <= 0.1 * self.static_failed_at)
            outcome = self.attempt(self.end, 0.0, opts.rtol, steps.max_iter) if static else None
            if outcome is None:
                if static:
                    self.static_failed_at = s.relative_residual
                if idle:
                    raise ClosureFailed(f"{s.input}: the static problem at step time {self.end:.6g} failed "
                                        f"({self.last_error}) and a damped held step has nothing left to do at its "
                                        "tolerance (the kept state is the last one)")
                outcome = self.attempt(self.end, steps.damping / s.increment, forcing, steps.max_iter,
                                       progress_only=True)
                if outcome is None:
                    s.increment *= 0.5
                    if s.increment < steps.smallest:
                        raise ClosureFailed(f"{s.input}: held step {s.held_steps + 1} failed at every pseudo-step "
                                            f"down to {steps.smallest:g}: {self.last_error}")
                    continue
                pseudo = s.increment
                if outcome.converged:  # each converged held step lets the pseudo-mass fade (HoldOptions.growth)
                    s.increment *= opts.growth
            else:
                pseudo = float("inf")
            u, residual, history, converged = outcome
            relative = self.accept(u, self.end, residual, history)
            s.held_steps += 1
            if relative <= opts.rtol:
                s.phase = "done"
            pairs = self.setup.contact.active_pairs(u, self.end)
            self.keep(StepRecord("hold", self.end, pseudo, len(history), relative, pairs,
                                 time.perf_counter() - clock, converged))
            bar.set_postfix(held=s.held_steps, it=len(history), res=f"{relative:.1e}", pairs=pairs)


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
        kept = read_state(out / STATE_FILE, input_name=Path(str(getattr(source, "path", source))).name)
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
