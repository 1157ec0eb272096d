r"""The closure by relaxation (the default route of the Texas TriValve runs): pseudo-transient continuation up to the
held load, then an energy trust region there, in stages (:func:`relax_closure`), with the controls found on the
1.0 diseased valve (:func:`relaxation_options`, :func:`held_options`, :func:`held_stages`). The model, its contact and
the load-stepped Newton route are in :mod:`.closure`.
"""

from __future__ import annotations

import math
import resource
import time
from collections.abc import Sequence
from dataclasses import replace
from functools import partial

import numpy as np

from ..fem.block_relaxation import BlockRelaxation
from ..fem.contact.clearance import clearance_fraction
from ..fem.damping import undamped_residual
from ..fem.errors import ConvergenceError
from ..fem.ptc import PseudoTransientOptions, pseudo_transient
from ..fem.truss import Truss
from ..fem.trust_region import TrustRegionOptions, trust_region
from .closure import ClosureRun, ClosureSetup, damping_weights
from .model import ValveModel

__all__ = ["EveryLoadFactor", "HELD_PROJECTED_STEPS", "HELD_STALL_FRACTION", "held_options", "held_stages",
           "hub_relaxation", "relax_closure", "relaxation_options", "watched_edges"]


def relaxation_options(pressure_start: float = 0.5, **overrides) -> list[tuple[float, PseudoTransientOptions]]:
    """Pseudo-transient stages for the Texas TriValve closure (units mm, MPa, step time), found on the 1.0 diseased
    valve, as ``(until, options)`` for :func:`relax_closure`. Both: damping 1e-5 per lumped volume, load steps of at
    most 0.005 (the tips move up to 0.25 mm per step), 0.5 mm trust region on any node, and Δτ grown only to fill 0.8
    of the trust regions from the last step's use (``fill``: on the 1.0 diseased valve the papillary stage took 690
    attempts, 87 rejected, against 809 and 213 without, 55 against 61 min, and arrived at the held load within a median
    0.0017 mm and the same residual, 2.83e-3).

    * up to ``pressure_start`` (the papillary tips move): a trust region of 0.05 on any edge's or cable's tensile
      stretch per step, nothing else (larger regions let the hexes next to the insertions reach states that lose
      stability through the thickness; stiffness-proportional or local damping hold the stiff chords back against
      the moving tips, whose forces then grow to newtons);
    * after (the pressure): a trust region of 0.2, a stiffness-proportional damping of 1e-3 while the pressure rises
      (1e-4 let the stage crawl at steps of ~4e-4: the overshoots are where the exponential laws are stiff) and none
      once it is held (kept, it holds the leaflets' soft modes back: from a 1.0 diseased end state at relative
      residual 3.07e-3, 34 held steps with it left 3.07e-3, 7 without reached 1.3e-3 and 125 a best of 8.7e-4), local
      damping (x10) of the nodes that break a trust region, and ``overrides`` (e.g. ``rtol``, ``atol`` of the end
      state).

    The first stage ends on a loose relative residual (1e-3): its end state only starts the second.
    """
    common = {"damping": 1e-5, "max_load_step": 0.005, "first_step": 5e-4, "max_increment": 0.5, "fill": 0.8}
    stages = []
    if pressure_start > 0.0:
        stages.append((pressure_start, PseudoTransientOptions(**common, max_strain_increment=0.05, rtol=1e-3)))
    fitted = {**common, "max_strain_increment": 0.2, "stiffness_damping": 1e-3, "held_stiffness_damping": 0.0,
              "local_damping": 10.0}
    fitted.update(overrides)
    stages.append((math.inf, PseudoTransientOptions(**fitted)))
    return stages


class EveryLoadFactor:
    """A callback passed on only when the load factor enters a new multiple of ``spacing`` (pseudo-transient runs take
    hundreds of steps; a VTU series wants tens)."""

    def __init__(self, callback, spacing: float = 0.05) -> None:
        if not spacing > 0.0:
            raise ValueError(f"spacing must be positive; got {spacing!r}")
        self.callback, self.spacing, self.last = callback, float(spacing), None

    def __call__(self, event) -> None:
        bucket = int(np.floor(event.load_factor / self.spacing + 1e-9))
        if self.last is None or bucket > self.last:
            self.last = bucket
            self.callback(event)


def relax_closure(setup: ClosureSetup, end: float,
                  options: PseudoTransientOptions | list[tuple[float, PseudoTransientOptions]] | None = None,
                  callbacks=(), progress: bool = True, verbose: bool = False, u0: np.ndarray | None = None,
                  t0: float = 0.0, held: TrustRegionOptions | Sequence[TrustRegionOptions] | None = None
                  ) -> ClosureRun:
    """The closure by pseudo-transient continuation (:func:`~skvalve.fem.ptc.pseudo_transient`): one damped,
    linearised step per pseudo-time step, no equilibrium asked for on the way, relaxed at ``end`` to the undamped
    equilibrium. ``setup`` must have no damping term (``ClosureOptions(damping=0)``): the damping is the
    solver's, with :func:`damping_weights`. ``options``: one set, or stages ``(until, options)`` run one after the
    other (:func:`relaxation_options`). ``held``: relax at the held load with the energy trust region
    (:func:`~skvalve.fem.trust_region.trust_region`, with the chordae branch points relaxed after each step:
    :func:`hub_relaxation`) instead, from the first state Ψtc reaches there (its last stage then stops as soon as the
    load is held, once its relative residual is below 1); a sequence of options relaxes in stages, each from where
    the one before ended (:func:`held_stages`: an earlier stage hands on when it stalls,
    :attr:`~skvalve.fem.trust_region.TrustRegionOptions.stall_fraction`, or passes its ``max_steps``; a converged
    stage ends the run). Ψtc's and the trust region's steps are both limited by the
    contact clearance (:func:`~skvalve.fem.contact.clearance.clearance_fraction`). Never raises for a failed run:
    the error and the kept state are recorded (the last accepted one; after Ψtc gave up at the held load, the held
    state with the smallest residual).
    """
    if setup.damping is not None:
        raise ValueError("relax_closure damps through the solver: build the setup with ClosureOptions(damping=0)")
    options = options or PseudoTransientOptions()
    stages = [(math.inf, options)] if isinstance(options, PseudoTransientOptions) else list(options)
    run = ClosureRun()

    def record(event) -> None:
        run.load_factors.append(float(event.load_factor))
        run.iterations.append(1)
        run.contact_pairs.append(setup.contact.last_pairs.touching if setup.contact.last_pairs is not None else 0)
        run.u = event.u

    edges, rest_lengths = watched_edges(setup.model) if setup.model is not None else (None, None)
    weights = damping_weights(setup.problem.space)
    clearance = partial(clearance_fraction, setup.contact)
    start = time.perf_counter()
    result, first_load = None, float(t0)

    def add_effort(stage_result) -> None:
        counts = [("rejected_steps", stage_result.rejected)]
        if hasattr(stage_result, "newton_tries"):
            counts += [("newton_tries", stage_result.newton_tries), ("newton_steps", stage_result.newton_steps)]
        for key, value in (*stage_result.timings.items(), *((name, float(count)) for name, count in counts)):
            run.timings[key] = run.timings.get(key, 0.0) + value

    try:
        for until, stage in stages:
            stop = min(until, end)
            if stop <= t0 and until < end:
                continue
            if held is not None and stop >= end:  # Ψtc only brings the load to its end
                stage = replace(stage, rtol=1.0)
            result = pseudo_transient(setup.problem, weights, stop, stage, u0=u0, t0=t0, edges=edges,
                                      rest_lengths=rest_lengths, callbacks=[record, *callbacks], progress=progress,
                                      verbose=verbose, limit=clearance)
            add_effort(result)
            u0, t0 = result.u, result.load_factor
            if stop >= end:
                break
        if held is not None:
            hubs = hub_relaxation(setup) if setup.model is not None else None
            staged = [held] if isinstance(held, TrustRegionOptions) else list(held)
            for number, held_stage in enumerate(staged, start=1):
                try:
                    result = trust_region(setup.problem, end, u0, held_stage, edges=edges, rest_lengths=rest_lengths,
                                          callbacks=[record, *callbacks], progress=progress, verbose=verbose,
                                          relax=hubs, limit=clearance)
                except ConvergenceError as err:  # an earlier stage that used its steps hands on its last state
                    if number == len(staged) or getattr(err, "last_state", None) is None:
                        raise
                    result = err.last_state
                add_effort(result)
                run.stage_steps.append(len(result.residuals))
                u0 = result.u
                if verbose and number < len(staged):
                    print(f"held stage {number} ended after {len(result.residuals)} steps "
                          f"({'stalled' if result.stalled else 'converged' if result.converged else 'max steps'})",
                          flush=True)
                if result.converged:
                    break
            run.negative_eigenvalues = result.negative_eigenvalues
    except Exception as err:  # noqa: BLE001 - a failed closure is a result to report, with its last state
        run.error = f"{type(err).__name__}: {err}"
        result = getattr(err, "last_state", None)
        if result is not None:  # the failed stage's effort, and its kept state (the best one at the held load)
            add_effort(result)
            run.u = result.u
    finally:
        run.peak_memory_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB
        run.seconds = time.perf_counter() - start
    if result is not None and run.error is None and not result.converged:
        run.error = "did not converge"
    if run.u is None and run.error is None and result is not None:  # converged at its start: no step recorded it
        run.u = result.u
    if not run.load_factors:  # failed before its first step: the load factor of the kept (or starting) state
        run.load_factors.append(float(getattr(result, "load_factor", first_load)))
        run.iterations.append(0)
        run.contact_pairs.append(0)
    if run.u is not None:
        run.undamped_residual = undamped_residual(setup.problem, run.u, run.load_factors[-1])
    return run


#: relative residual below which the held valve's steps first try full-tangent Newton (the follower pressure on
#: leaflets with free edges has a non-symmetric load stiffness, so the energy model is not exact near equilibrium)
HELD_NEWTON_BELOW = 1e-4


#: largest nodal motion (mm) of one held step; what keeps nodes from passing through a sheet is the clearance limit
HELD_MAX_RADIUS = 1.0

#: whether the held valve's last stage projects the element blocks onto positive semidefinite ones: not, since from the
#: same held 1.0 diseased state (relative residual 1.8e-3) the plain symmetric tangent with the inertia-corrected shift
#: reached 3.0e-4 in 152 steps, the projected one no lower than 7.6e-3 in 39; from the pressure stage's end (2.1e-3)
#: 1.7e-3 in 194 steps with 8 rejected, the projected one none below its first step in 196 (138 rejected in its run)
#: (projection drops the curvature that the valve's soft modes, 3e-5 N/mm, need: :mod:`skvalve.fem.soft_modes`)
HELD_PROJECT = False

#: refactorisations with a raised shift for a held step longer than the radius, and the shift's scaling: from the same
#: arrival state of the 1.0 diseased valve (relative residual 3.1e-3 at t = 1.5), the shift fitted to the radius
#: under a uniform scaling reached 8.9e-4 after 80 steps and 8.4e-4 after 169, the scaled steps under Marquardt's
#: diagonal shift 1.8e-3 after 83 (:attr:`~skvalve.fem.trust_region.TrustRegionOptions.fit_radius`, ``shift_scaling``);
#: neither closed the valve's centre from there (energy 8.4 and 2.5 N·mm down; projected runs: 29-35 N·mm, closed)
HELD_FIT_RADIUS = 3
HELD_SHIFT_SCALING = "uniform"

#: terms whose indefinite blocks the held valve's step matrix shifts locally
#: (:attr:`~skvalve.fem.trust_region.TrustRegionOptions.shift_terms`): at the 1.0 diseased valve's state after the
#: projected and the unprojected stage (relative residual 6.0e-4) the lowest eigenvalue of the symmetric tangent,
#: -0.175 N/mm, is one contact pair's, and it set a global shift that damps the soft modes a thousandfold; with the
#: contact shifted locally, 254 further steps from there went 2.97 N·mm down to a best of 1.25e-4, the coaptation area
#: from 172 to 261 mm² (the unprojected stage's own last 40 steps before that state: 0.12 N·mm, no lower residual)
HELD_SHIFT_TERMS = ("contact",)


def held_options(setup: ClosureSetup, **overrides) -> TrustRegionOptions:
    """Trust-region controls for the held load of a valve closure: first radius a quarter of the contact search depth,
    steps of at most ``HELD_MAX_RADIUS`` (or the depth, if larger) on any node, the step matrix projected or not as
    ``HELD_PROJECT`` says, a step longer than the radius shortened by a uniform shift fitted to it (``HELD_FIT_RADIUS``,
    ``HELD_SHIFT_SCALING``), the contact's indefinite blocks shifted locally (``HELD_SHIFT_TERMS``), and ``overrides``
    (e.g. ``rtol``, ``atol``). :func:`relax_closure` also limits each step by the contact clearance
    (:func:`~skvalve.fem.contact.clearance.clearance_fraction`): a penalty energy ignores a node past the search depth,
    so a step that moved a node further than that relative to a nearby sheet could carry it through unseen."""
    depth = setup.contact.max_penetration
    return TrustRegionOptions(**{"radius": 0.25 * depth, "max_radius": max(depth, HELD_MAX_RADIUS),
                                 "newton_below": HELD_NEWTON_BELOW, "project": HELD_PROJECT,
                                 "fit_radius": HELD_FIT_RADIUS, "shift_scaling": HELD_SHIFT_SCALING,
                                 "shift_terms": HELD_SHIFT_TERMS, **overrides})


#: the held valve's first stage: steps on the projected step matrix under Marquardt's diagonal shift, scaled into the
#: radius, until the energy drop of the last 20 steps averages below ``HELD_STALL_FRACTION`` of the stage's (at most
#: ``HELD_PROJECTED_STEPS``). From the arrival state of the 1.0 diseased valve (relative residual 3.1e-3) such steps
#: went 31.0 N·mm down in 103 steps and closed the valve's centre, the unprojected ones of :func:`held_options` 8.4
#: N·mm in 267 and left it open (both at relative residuals below 1e-3: the residual does not tell); after the
#: projected stage, the unprojected one lowered the relative residual from 2.1e-2 to 6.0e-4 in 167 steps. On that run
#: the 20-step average fell from 0.70 N·mm per step (step 30) to 0.055 (step 103), 0.18 of the stage's average.
HELD_STALL_FRACTION = 0.2
HELD_PROJECTED_STEPS = 200


def held_stages(setup: ClosureSetup, projected_steps: int = HELD_PROJECTED_STEPS,
                **overrides) -> list[TrustRegionOptions]:
    """The held load's stages for :func:`relax_closure`: projected steps (``HELD_STALL_FRACTION``,
    ``projected_steps``; 0: no such stage) that carry the valve down its energy to a closed state, then
    :func:`held_options` (``overrides`` for both, e.g. ``rtol``; the keys of the stage's own controls only for the
    last)."""
    last = held_options(setup, **overrides)
    if projected_steps <= 0:
        return [last]
    tolerances = {key: value for key, value in overrides.items() if key in ("rtol", "atol", "solver")}
    first = held_options(setup, project=True, fit_radius=0, shift_scaling="diagonal", shift_terms=(),
                         max_steps=projected_steps, stall_fraction=HELD_STALL_FRACTION, **tolerances)
    return [first, last]


def hub_relaxation(setup: ClosureSetup) -> BlockRelaxation | None:
    """The chordae branch points (vertices of no leaflet cell, not prescribed) brought to equilibrium with the rest
    held, by the cables alone (:mod:`skvalve.fem.block_relaxation`); None when the model has none."""
    mesh = setup.model.mesh
    in_cell = np.zeros(mesh.p.shape[1], dtype=bool)
    in_cell[np.unique(mesh.t)] = True
    hubs = np.flatnonzero(~in_cell)
    trusses = [term for term in setup.problem.terms if isinstance(term, Truss)]
    if hubs.size == 0 or not trusses:
        return None
    relax = BlockRelaxation(setup.problem, setup.problem.space.displacement_dofs(hubs).ravel(), trusses)
    return relax if relax.dofs.size else None


def watched_edges(model: ValveModel) -> tuple[np.ndarray, np.ndarray]:
    """Node pairs whose tensile stretch the pseudo-transient trust region limits, and the lengths from which they
    carry tension: every pair of a hex's vertices (edges and diagonals, whatever the vertex order; their reference
    lengths) and the cables (their rest lengths)."""
    hexes = model.mesh.t.T
    pairs = [(a, b) for a in range(hexes.shape[1]) for b in range(a + 1, hexes.shape[1])]
    in_hexes = np.concatenate([hexes[:, [a, b]] for a, b in pairs])
    X = model.mesh.p.T
    lengths = np.linalg.norm(X[in_hexes[:, 1]] - X[in_hexes[:, 0]], axis=1)
    return (np.concatenate([in_hexes, model.chordae.ends]),
            np.concatenate([lengths, np.asarray(model.chordae.rest_length, dtype=float)]))
