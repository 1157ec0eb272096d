"""The valve closure's model: the input's implicit model plus IPC contact on the leaflets' hex boundary.

:func:`valve_setup` builds what :func:`skvalve.valve.run.close_valve` solves and what the outputs
(:mod:`.outputs`, the mathur2022 figures) measure: the :class:`~skvalve.valve.model.ValveModel`, its
:class:`~skvalve.fem.problem.Problem` with an :class:`~skvalve.fem.contact.IPCContact` term, each vertex's leaflet and
the lumped nodal volumes that weight the pseudo-mass.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fem.contact import IPCContact
from ..fem.contact.ipc import stiffness_for_pressure
from ..fem.damping import lumped_volume
from ..fem.problem import Problem
from ..io.abaqus import AbaqusModel, read_model
from .extrude import hex_corner_jacobians
from .model import ABAQUS_TO_SKFEM_HEX, ValveModel, valve_model
from .options import CloseOptions

__all__ = ["ValveSetup", "smallest_corner_jacobian", "valve_setup"]


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
    load_scale: float  # N: the largest pressure times the loaded area (reference), the end load's scale


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
                                          exclude_within=c.exclude_within, friction=c.friction,
                                          check_intersections=c.check_intersections))
    leaflet = np.full(model.mesh.p.shape[1], -1, dtype=np.int64)
    leaflet[model.mesh.t] = model.regions[None, :]
    volumes = lumped_volume(problem.space)
    bare = volumes[: problem.space.n_u] == 0.0  # chordae branch points: the median leaflet node's volume
    if np.any(bare) and np.any(~bare):
        volumes[: problem.space.n_u][bare] = np.median(volumes[: problem.space.n_u][~bare])
    loaded = sum(abs(load.magnitude) * _facet_area(model.mesh, load.facets) for load in model.pressures)
    return ValveSetup(abaqus, model, problem, contact, leaflet, volumes, Path(str(abaqus.path)).name, loaded)


def _facet_area(mesh, facets: np.ndarray) -> float:
    """Reference area of quadrilateral mesh facets (two triangles each)."""
    Q = mesh.p.T[mesh.facets[:, facets].T]
    return float(0.5 * np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]), axis=1).sum())


def smallest_corner_jacobian(setup: ValveSetup, u: np.ndarray) -> float:
    """The smallest det(dx/dxi) over every hex corner at ``u`` (<= 0: a folded corner)."""
    mesh = setup.model.mesh
    x = mesh.p.T + u[: setup.problem.space.n_u].reshape(-1, 3)
    return float(hex_corner_jacobians(x, mesh.t.T[:, np.argsort(ABAQUS_TO_SKFEM_HEX)]).min())
