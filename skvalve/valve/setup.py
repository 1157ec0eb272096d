"""The valve closure's model: the input's implicit model, IPC contact on the leaflets' hex boundary, a barrier against
folding hex corners (:class:`~skvalve.fem.elements.corner_barrier.CornerBarrier`) and, with clip arms, the tie that
keeps what they capture (:class:`~skvalve.fem.contact.tie.ObstacleTie`).

:func:`valve_setup` builds what :func:`skvalve.valve.run.close_valve` solves and what the outputs
(:mod:`.outputs`, the mathur2022 figures) measure: the :class:`~skvalve.valve.model.ValveModel`, its
:class:`~skvalve.fem.problem.Problem` with an :class:`~skvalve.fem.contact.IPCContact` term (with the model's clip arms
as moving obstacles, :mod:`.clip`), each vertex's leaflet and the lumped nodal volumes that weight the pseudo-mass.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fem.contact import IPCContact
from ..fem.contact.ipc import stiffness_for_pressure
from ..fem.contact.tie import ObstacleTie
from ..fem.elements.corner_barrier import CornerBarrier
from ..fem.loads import FollowerPressure
from ..fem.problem import Problem
from ..fem.solvers.damping import lumped_volume
from ..io.abaqus import AbaqusModel, read_model
from .extrude import hex_corner_jacobians
from .model import ABAQUS_TO_SKFEM_HEX, ValveModel, valve_model
from .options import CloseOptions

#: the clip arms' tie holds a captured vertex with k = TIE_FACTOR x (peak pressure) / dhat per unit area: under the
#: peak pressure over its own area a tied vertex sits dhat / 1000 (0.1 um) off its point on the arm
TIE_FACTOR = 1000.0

__all__ = ["TIE_FACTOR", "ValveSetup", "end_load_norm", "pressure_forces", "smallest_corner_jacobian", "valve_setup"]


@dataclass
class ValveSetup:
    """The model, its problem, the contact term and what the outputs need."""

    abaqus: AbaqusModel
    model: ValveModel
    problem: Problem
    contact: IPCContact
    leaflet_of_vertex: np.ndarray
    volumes: np.ndarray  # lumped nodal volumes per dof, the pseudo-mass's weights (StepOptions)
    input_name: str
    load_norm: float  # N: the norm of the end load's nodal pressure forces on the free dofs (end_load_norm)


def valve_setup(source: str | Path | AbaqusModel, options: CloseOptions | None = None,
                model: ValveModel | None = None) -> ValveSetup:
    """Read the input (a path or a read :class:`~skvalve.io.abaqus.AbaqusModel`; ``model`` a ready
    :class:`ValveModel` of it, e.g. a submodel) and build problem and contact."""
    options = options or CloseOptions()
    abaqus = read_model(source) if not isinstance(source, AbaqusModel) else source
    model = valve_model(abaqus) if model is None else model
    problem = model.problem(insertion=options.model.insertion, compression=options.model.cable_compression)
    peak = max((abs(load.magnitude) for load in model.pressures), default=0.0)
    if peak <= 0.0:
        raise ValueError(f"{abaqus.path}: no pressure load; the closure needs the transvalvular pressure")
    c = options.contact
    stiffness = stiffness_for_pressure(c.pressure_factor * peak, c.dhat, 0.5)
    contact = problem.add_term(IPCContact(problem.space, dhat=c.dhat, stiffness=stiffness,
                                          obstacles=model.obstacles, exclude_within=c.exclude_within,
                                          friction=c.friction, check_intersections=c.check_intersections))
    # terms added after the contact, so that the kept states of runs without them keep their terms' numbers
    if options.model.corner_threshold > 0.0:
        moduli = np.array([law.shear_modulus for law in model.laws])[model.regions]
        problem.add_term(CornerBarrier(problem.space, moduli, options.model.corner_threshold))
    if model.obstacles and c.tie_within > 0.0:
        # an arm grips from the step in which it starts to close (the leaflets may press on it before)
        grips = [arm.turns_from(model.steps) for arm in model.arms]
        problem.add_term(ObstacleTie(problem.space, contact.nodes, contact.area[contact.nodes], model.obstacles,
                                     capture=c.tie_within, stiffness=TIE_FACTOR * peak / c.dhat, capture_from=grips))
    leaflet = np.full(model.mesh.p.shape[1], -1, dtype=np.int64)
    leaflet[model.mesh.t] = model.regions[None, :]
    volumes = lumped_volume(problem.space)
    bare = volumes[: problem.space.n_u] == 0.0  # chordae branch points: the median leaflet node's volume
    if np.any(bare) and np.any(~bare):
        volumes[: problem.space.n_u][bare] = np.median(volumes[: problem.space.n_u][~bare])
    return ValveSetup(abaqus, model, problem, contact, leaflet, volumes, Path(str(abaqus.path)).name,
                      end_load_norm(problem, model.end_time))


def pressure_forces(problem: Problem, u: np.ndarray, t: float) -> np.ndarray:
    """The follower pressures' nodal forces (all dofs) at ``(u, t)``: the external load the leaflets carry."""
    force = np.zeros(problem.space.n_dofs)
    for term in problem.terms:
        if isinstance(term, FollowerPressure):
            force += term.assemble(u, t, tangent=False).external
    return force


def end_load_norm(problem: Problem, t_end: float) -> float:
    r"""The closure's force scale: :math:`\lVert f_p\rVert_2`, the follower pressures' nodal forces at step time
    ``t_end`` on the reference geometry, over the free dofs (N).

    The static residual is measured against it, in the same norm: the leaflets' equilibrium is the balance of this
    distributed load. Newton's usual scale, the reactions' norm, is set by a few annulus and papillary nodes (42 N on
    the 1.0 diseased valve against :math:`\lVert f_p\rVert_2` = 0.215 N), and a residual 1e-3 of it left 18 % of
    the pressure unbalanced: the load path arrived at the end load with the valve open in the middle.
    """
    force = pressure_forces(problem, np.zeros(problem.space.n_dofs), t_end)
    norm = float(np.linalg.norm(force[problem.pattern.free]))
    if not norm > 0.0:
        raise ValueError(f"no pressure load on the free dofs at step time {t_end:g}: the closure's force scale is the "
                         "end load's")
    return norm


def smallest_corner_jacobian(setup: ValveSetup, u: np.ndarray) -> float:
    """The smallest det(dx/dxi) over every hex corner at ``u`` (<= 0: a folded corner)."""
    mesh = setup.model.mesh
    x = mesh.p.T + u[: setup.problem.space.n_u].reshape(-1, 3)
    return float(hex_corner_jacobians(x, mesh.t.T[:, np.argsort(ABAQUS_TO_SKFEM_HEX)]).min())
