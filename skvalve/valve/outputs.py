r"""Closure outputs: the mathur2022 Table 2–3 measures of a state and a ParaView series with contact pressure.

Measures of a state :math:`u` of a :class:`~skvalve.valve.setup.ValveSetup` (units of the input: mm, MPa):

* orifice and leaflet areas of :func:`skvalve.valve.geometry.valve_areas` (ventricular, mid and atrial
  surfaces), the leaflet centre regions chosen once on the reference configuration;
* shell inputs (Texas TriValve 1.1, extruded into stacks of ``layers`` hexes by :mod:`.extrude`): the leaflet
  surface is the shell midsurface, the input's own shell faces, and an input shell node sits at the mean of
  the two model vertices of its through-thickness fibre at layers :math:`\lfloor n/2 \rfloor` and
  :math:`\lceil n/2 \rceil`, i.e. on the middle node layer of the stack for an even :math:`n` (the default
  :math:`n = 4`: the layer that carries the midsurface and the chordae attachments, at exactly the input
  node in the reference configuration) and halfway between the two middle layers for an odd :math:`n`. The
  ventricular/atrial surfaces of a shell input are the current midsurface offset by the reference
  :math:`\pm h/2` (:class:`~skvalve.valve.geometry.LeafletSurfaces`), not the stack's skins;
* coaptation area: the current area of the contact surface's faces with positive contact pressure
  (:meth:`~skvalve.fem.contact.SurfaceContact.contact_area`): both touching sides count, as Abaqus's CAREA of
  a self-contact surface does;
* centre stress: the maximum principal Cauchy stress at the centres of the hexes that share a centre-region
  face of the mid surface, averaged over them (the paper averages over the leaflet centres, Fig. 4d/e); for
  shells, all hexes of the stacks extruded from the centre region's shell elements.

:class:`ClosureWriter` is a solver callback writing one VTU per converged step (hexes in VTK order and the
chordae as lines) with displacement, leaflet id, nodal contact pressure and maximum principal Cauchy stress,
plus the ``.pvd`` collection, every file written under a temporary name and renamed.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np
import scipy.sparse as sp

from ..fem.contact import IPCContact
from ..fem.fields import element_centres
from ..fem.solvers.newton import StepEvent
from ..io.abaqus.elements import is_shell_like
from ..io.files import replace_atomically
from .geometry import annulus_nodes, leaflet_surfaces, valve_areas
from .model import ABAQUS_TO_SKFEM_HEX
from .setup import ValveSetup
from .surfaces import shell_stacks

__all__ = ["ClosureMeasures", "closure_measures", "ClosureWriter", "abaqus_positions", "ShellMidsurface",
           "shell_midsurface"]

LEAFLETS = ("anterior", "posterior", "septal")


@dataclass
class ClosureMeasures:
    """Table 2–3 quantities of one state (mm², MPa).

    ``orifice`` and ``leaflet_area`` (all leaflets) per surface; ``per_leaflet_area``: leaflet -> surface -> area.
    """

    orifice: dict[str, float]
    leaflet_area: dict[str, float]
    coaptation_area: float
    centre_stress: dict[str, float]
    per_leaflet_area: dict[str, dict[str, float]] = field(default_factory=dict)


@dataclass
class ShellMidsurface:
    """Input shell nodes and the two model vertices (layers floor(n/2), ceil(n/2) of their fibre) they average."""

    nodes: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


def shell_midsurface(setup: ValveSetup) -> ShellMidsurface:
    """The :class:`ShellMidsurface` of a setup's extruded shells (empty for bricks; module docstring).

    Raises ``ValueError`` if the vertices found do not average to the input's shell nodes in the reference
    configuration (a model not built by :func:`~skvalve.valve.model.valve_model`'s extrusion).
    """
    abaqus, model = setup.abaqus, setup.model
    blocks = [b for b in abaqus.element_blocks if is_shell_like(b.element_type)]
    stacks = shell_stacks(model) if blocks else {}
    corners = model.mesh.t.T[:, np.argsort(ABAQUS_TO_SKFEM_HEX)]  # Abaqus C3D8 corner order
    nodes, lower, upper = [], [], []
    for block in blocks:
        n = block.connectivity.shape[1]
        for element, connectivity in zip(block.indices.tolist(), block.connectivity, strict=True):
            stack = stacks.get(element)
            if stack is None:
                continue
            # hex k of a stack spans node layers k (corners 1-4, in the shell's node order) and k + 1 (corners 5-8)
            middle = corners[stack[len(stack) // 2]]
            nodes.append(connectivity)
            lower.append(middle[:n])
            upper.append(middle[:n] if len(stack) % 2 == 0 else middle[4:4 + n])
    if not nodes:
        empty = np.zeros(0, dtype=np.int64)
        return ShellMidsurface(empty, empty, empty)
    found, first = np.unique(np.concatenate(nodes), return_index=True)
    result = ShellMidsurface(found, np.concatenate(lower)[first], np.concatenate(upper)[first])
    X = model.mesh.p.T
    gap = np.linalg.norm(0.5 * (X[result.lower] + X[result.upper]) - abaqus.nodes[found], axis=1)
    scale = max(float(np.ptp(abaqus.nodes[found], axis=0).max()), 1.0)
    if gap.max() > 1e-9 * scale:
        worst = int(np.argmax(gap))
        raise ValueError(f"{abaqus.path}: shell node label {abaqus.node_labels[found[worst]]} is {gap[worst]:.3g} "
                         "away from the middle of its extruded fibre (not an extrusion of the model builder)")
    return result


def abaqus_positions(setup: ValveSetup, u: np.ndarray) -> np.ndarray:
    """Current coordinates of all the input's nodes (nodes outside the model stay where they are).

    Shell nodes follow the middle of their extruded fibre (:func:`shell_midsurface`).
    """
    x = setup.abaqus.nodes.copy()
    source = setup.model.vertex_source
    has = source >= 0
    current = setup.model.mesh.p.T + u[: setup.problem.space.n_u].reshape(-1, 3)
    x[source[has]] = current[has]
    mid = _reference(setup).midsurface
    x[mid.nodes] = 0.5 * (current[mid.lower] + current[mid.upper])
    return x


def _vertex_of(setup: ValveSetup) -> np.ndarray:
    vertex_of = np.full(setup.abaqus.nodes.shape[0], -1, dtype=np.int64)
    source = setup.model.vertex_source
    vertex_of[source[source >= 0]] = np.flatnonzero(source >= 0)
    return vertex_of


def _elements_with_faces(setup: ValveSetup, faces: np.ndarray) -> np.ndarray:
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
    """Shell midsurface map, surfaces, annulus and centre regions of the reference configuration, once per setup."""

    def __init__(self, setup: ValveSetup) -> None:
        self.midsurface = shell_midsurface(setup)
        self._measured = False

    def measure(self, setup: ValveSetup) -> _Reference:
        """Surfaces, annulus and centre regions (on first use: :func:`abaqus_positions` needs only the map)."""
        if self._measured:
            return self
        self.surfaces = leaflet_surfaces(setup.abaqus)
        self.annulus = annulus_nodes(setup.abaqus)
        areas = valve_areas(self.surfaces, setup.abaqus.nodes, self.annulus)
        self.centre_faces = areas.centre_faces
        self.centre_elements = {}
        stacks = None
        for name, leaflet in self.surfaces.items():
            if leaflet.thickness is not None:  # shells: every hex of the centre elements' stacks
                stacks = shell_stacks(setup.model) if stacks is None else stacks
                owners = leaflet.elements[areas.centre_faces[name]].tolist()
                self.centre_elements[name] = np.unique(np.concatenate([stacks[e] for e in owners]))
            else:
                faces = leaflet.mid_lower[areas.centre_faces[name]]
                self.centre_elements[name] = _elements_with_faces(setup, faces)
        self._measured = True
        return self


_REFERENCES: dict[int, tuple[weakref.ref, _Reference]] = {}


def _reference(setup: ValveSetup) -> _Reference:
    """The cached :class:`_Reference` of ``setup`` (keyed by identity, dropped when the setup is collected)."""
    key = id(setup)
    cached = _REFERENCES.get(key)
    if cached is None or cached[0]() is not setup:
        cached = (weakref.ref(setup, lambda _, key=key: _REFERENCES.pop(key, None)), _Reference(setup))
        _REFERENCES[key] = cached
    return cached[1]


def closure_measures(setup: ValveSetup, u: np.ndarray, t: float = 1.5) -> ClosureMeasures:
    """Orifice, leaflet and coaptation areas and leaflet-centre stresses at state ``u`` (module docstring)."""
    reference = _reference(setup).measure(setup)
    x = abaqus_positions(setup, u)
    areas = valve_areas(reference.surfaces, x, reference.annulus, centre_faces=reference.centre_faces)
    leaflet_area = {which: areas.total(which) for which in areas.orifice}
    coaptation = setup.contact.contact_area(u, t=t)
    principal = max_principal_cauchy(setup, u)
    centre = {name: float(principal[elements].mean()) for name, elements in reference.centre_elements.items()}
    return ClosureMeasures(areas.orifice, leaflet_area, coaptation, centre, areas.leaflet)


def max_principal_cauchy(setup: ValveSetup, u: np.ndarray) -> np.ndarray:
    """Maximum principal Cauchy stress at each hex centre (n_elements,)."""
    sigma = element_centres(setup.problem).cauchy(u)
    return np.linalg.eigvalsh(sigma.transpose(2, 0, 1))[:, -1]


def _nodal_contact_pressure(contact, u: np.ndarray, t: float) -> np.ndarray:
    """Nodal contact pressure of the IPC barrier at (u, t), or of the penalty contact after its assembly."""
    return contact.nodal_pressure(u, t) if isinstance(contact, IPCContact) else contact.nodal_pressure(u)


class ClosureWriter:
    """Solver callback: ``<stem>_<k>.vtu`` per converged step and ``<stem>.pvd`` (module docstring)."""

    def __init__(self, path, setup: ValveSetup) -> None:
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
                      "contact_pressure": _nodal_contact_pressure(setup.contact, u, t)}
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
