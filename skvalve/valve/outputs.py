r"""Closure outputs: the mathur2022 Table 2–3 measures of a state and a ParaView series with contact pressure.

Measures of a state :math:`u` of a :class:`~skvalve.valve.closure.ClosureSetup` (units of the input: mm, MPa):

* orifice and leaflet areas of :func:`skvalve.valve.geometry.valve_areas` (ventricular, mid and atrial
  surfaces), the leaflet centre regions chosen once on the reference configuration;
* coaptation area: the current area of the contact surface's faces with positive contact pressure
  (:meth:`~skvalve.fem.contact.SurfaceContact.contact_area`): both touching sides count, as Abaqus's CAREA of
  a self-contact surface does;
* centre stress: the maximum principal Cauchy stress at the centres of the hexes that share a centre-region
  face of the mid surface, averaged over them (the paper averages over the leaflet centres, Fig. 4d/e).

:class:`ClosureWriter` is a solver callback writing one VTU per converged step (hexes in VTK order and the
chordae as lines) with displacement, leaflet id, nodal contact pressure and maximum principal Cauchy stress,
plus the ``.pvd`` collection, every file written under a temporary name and renamed.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import meshio
import numpy as np
import scipy.sparse as sp

from ..fem.fields import element_centres
from ..fem.newton import StepEvent
from ..io.files import replace_atomically
from .closure import ClosureSetup
from .geometry import annulus_nodes, leaflet_surfaces, valve_areas
from .model import ABAQUS_TO_SKFEM_HEX

__all__ = ["ClosureMeasures", "closure_measures", "ClosureWriter", "abaqus_positions"]

LEAFLETS = ("anterior", "posterior", "septal")


@dataclass
class ClosureMeasures:
    """Table 2–3 quantities of one state (mm², MPa)."""

    orifice: dict[str, float]
    leaflet_area: dict[str, float]
    coaptation_area: float
    centre_stress: dict[str, float]


def abaqus_positions(setup: ClosureSetup, u: np.ndarray) -> np.ndarray:
    """Current coordinates of all the input's nodes (nodes outside the model stay where they are)."""
    x = setup.abaqus.nodes.copy()
    source = setup.model.vertex_source
    has = source >= 0
    x[source[has]] = setup.model.mesh.p.T[has] + u[: setup.problem.space.n_u].reshape(-1, 3)[has]
    return x


def _vertex_of(setup: ClosureSetup) -> np.ndarray:
    vertex_of = np.full(setup.abaqus.nodes.shape[0], -1, dtype=np.int64)
    source = setup.model.vertex_source
    vertex_of[source[source >= 0]] = np.flatnonzero(source >= 0)
    return vertex_of


def _elements_with_faces(setup: ClosureSetup, faces: np.ndarray) -> np.ndarray:
    """Mesh elements having all four vertices of one of ``faces`` (input node indices)."""
    mesh = setup.model.mesh
    vertices = _vertex_of(setup)[faces]
    incidence = sp.csr_matrix((np.ones(mesh.t.size), (np.repeat(np.arange(mesh.nelements), 8), mesh.t.T.ravel())),
                              shape=(mesh.nelements, mesh.p.shape[1]))
    face_incidence = sp.csr_matrix((np.ones(vertices.size), (np.repeat(np.arange(len(faces)), 4), vertices.ravel())),
                                   shape=(len(faces), mesh.p.shape[1]))
    shared = (incidence @ face_incidence.T).tocoo()
    return np.unique(shared.row[shared.data >= 4])


class _Reference:
    """Surfaces, annulus and centre regions of the reference configuration, computed once per setup."""

    def __init__(self, setup: ClosureSetup) -> None:
        self.surfaces = leaflet_surfaces(setup.abaqus)
        self.annulus = annulus_nodes(setup.abaqus)
        areas = valve_areas(self.surfaces, setup.abaqus.nodes, self.annulus)
        self.centre_faces = areas.centre_faces
        self.centre_elements = {}
        for name, leaflet in self.surfaces.items():
            faces = leaflet.mid_lower[areas.centre_faces[name]]
            self.centre_elements[name] = _elements_with_faces(setup, faces)


_REFERENCES: dict[int, _Reference] = {}


def closure_measures(setup: ClosureSetup, u: np.ndarray, t: float = 1.5) -> ClosureMeasures:
    """Orifice, leaflet and coaptation areas and leaflet-centre stresses at state ``u`` (module docstring)."""
    reference = _REFERENCES.setdefault(id(setup), _Reference(setup))
    x = abaqus_positions(setup, u)
    areas = valve_areas(reference.surfaces, x, reference.annulus, centre_faces=reference.centre_faces)
    leaflet_area = {which: areas.total(which) for which in areas.orifice}
    coaptation = setup.contact.contact_area(u, t=t)
    principal = max_principal_cauchy(setup, u)
    centre = {name: float(principal[elements].mean()) for name, elements in reference.centre_elements.items()}
    return ClosureMeasures(areas.orifice, leaflet_area, coaptation, centre)


def max_principal_cauchy(setup: ClosureSetup, u: np.ndarray) -> np.ndarray:
    """Maximum principal Cauchy stress at each hex centre (n_elements,)."""
    sigma = element_centres(setup.problem).cauchy(u)
    return np.linalg.eigvalsh(sigma.transpose(2, 0, 1))[:, -1]


class ClosureWriter:
    """Solver callback: ``<stem>_<k>.vtu`` per converged step and ``<stem>.pvd`` (module docstring)."""

    def __init__(self, path, setup: ClosureSetup) -> None:
        self.path = Path(path).with_suffix(".pvd")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.setup = setup
        mesh = setup.model.mesh
        to_vtk = np.argsort(ABAQUS_TO_SKFEM_HEX)
        self.cells = [("hexahedron", mesh.t.T[:, to_vtk]), ("line", setup.model.chordae.ends)]
        self.points = mesh.p.T
        self.entries: list[tuple[float, str]] = []

    def __call__(self, event: StepEvent) -> None:
        self.write(event.load_factor, event.u)

    def write(self, t: float, u: np.ndarray) -> Path:
        setup = self.setup
        n_lines = setup.model.chordae.ends.shape[0]
        setup.contact.assemble(u, t, False, None)
        point_data = {"displacement": u[: setup.problem.space.n_u].reshape(-1, 3),
                      "leaflet_id": setup.leaflet_of_vertex.astype(float),
                      "contact_pressure": setup.contact.nodal_pressure(u)}
        cell_data = {"max_principal_cauchy": [max_principal_cauchy(setup, u), np.zeros(n_lines)],
                     "leaflet_id": [setup.model.regions.astype(float), np.full(n_lines, -1.0)]}
        name = f"{self.path.stem}_{len(self.entries):04d}.vtu"
        target = self.path.parent / name
        mesh = meshio.Mesh(self.points, self.cells, point_data, cell_data)
        replace_atomically(target, lambda p: meshio.write(p, mesh, file_format="vtu"))
        self.entries.append((float(t), name))
        lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
        lines += [f'    <DataSet timestep="{t!r}" part="0" file="{n}"/>' for t, n in self.entries]
        lines += ["  </Collection>", "</VTKFile>", ""]
        replace_atomically(self.path, lambda p: p.write_text("\n".join(lines)))
        return target

    def close(self) -> None:
        """Nothing is held open."""
