"""The dataclasses of a read Abaqus model (:class:`AbaqusModel` and its parts).

Numbering: every node and element of the assembled model has a 0-based *global index*. Nodes defined
outside parts (assembly reference points, or all nodes of an input without parts) come first, in file
order; then the nodes of each part instance in instance order, moved by the instance's translation and
rotation. Elements are numbered block by block in the same way. Sets, surfaces, sections, boundary
conditions and constraints hold global indices. Names are case-insensitive as in Abaqus; a set of part
``P`` instanced as ``I`` is reached as ``"I.setname"``, and node ``12`` of ``I`` as ``"I.12"``
(:meth:`AbaqusModel.node_indices`); ``node_scopes``/``node_labels`` give each global node's instance
(index into ``scopes``, ``""`` = assembly) and its label there.

Steps keep the history data as written: ``BoundaryCondition.op == "NEW"`` means that the conditions of
earlier steps are released at the start of this step (Abaqus applies ``OP=NEW`` to the whole step), the
step's own conditions all apply together; ``amplitude`` names an :class:`Amplitude` (None: the step's
default ramp); ``DistributedLoad`` type ``P`` is a follower pressure acting against the face normal.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import Location
from .materials import AbaqusMaterial

__all__ = [
    "ElementBlock", "NodeSet", "ElementSet", "SurfaceFaces", "Surface", "Section", "Instance", "Amplitude",
    "BoundaryCondition", "DistributedLoad", "ConcentratedLoad", "ContactPair", "GeneralContact",
    "SurfaceInteraction", "MPC", "RigidBody", "ConnectorSection", "Transform", "Step", "IgnoredKeyword", "ReadWarning",
    "AbaqusModel", "TWO_NODE_MPC_TYPES",
]

#: ``*MPC`` types that join a node ``p`` to a node ``a`` (Abaqus Analysis User's Guide, "General multi-point
#: constraints"); ``LINK`` keeps their distance constant (pinned rigid link).
TWO_NODE_MPC_TYPES = ("LINK", "PIN", "TIE", "BEAM")

@dataclass
class ElementBlock:
    """One ``*Element`` block (per instance): type, element labels and connectivity in global node indices."""

    element_type: str
    scope: str
    labels: np.ndarray
    connectivity: np.ndarray
    offset: int
    elset: str | None
    location: Location

    @property
    def indices(self) -> np.ndarray:
        """Global element indices of this block."""
        return np.arange(self.offset, self.offset + len(self.labels))


@dataclass
class NodeSet:
    """A node set: name as written (qualified ``Instance.name`` for part sets) and global node indices."""

    name: str
    indices: np.ndarray
    location: Location


@dataclass
class ElementSet:
    """An element set: name as written (qualified for part sets) and global element indices."""

    name: str
    indices: np.ndarray
    location: Location


@dataclass
class SurfaceFaces:
    """Faces of one surface data line: a face label (``S1``..``S6``, ``SPOS``, ``SNEG``) on elements."""

    face: str
    elements: np.ndarray


@dataclass
class Surface:
    """An element-based ``*Surface``: a list of (face label, elements) groups."""

    name: str
    faces: list[SurfaceFaces]
    location: Location
    surface_type: str = "ELEMENT"


@dataclass
class Section:
    """``*Solid Section`` / ``*Shell Section`` / ``*Membrane Section`` on an element set.

    ``area`` is the first data value of a solid section on truss elements (cross-sectional area);
    ``thickness`` that of a shell/membrane section (or of a solid section on plane elements);
    ``integration_points`` the shell's through-thickness Simpson points.
    """

    kind: str
    elset: str
    material: str
    elements: np.ndarray
    location: Location
    orientation: str | None = None
    area: float | None = None
    thickness: float | None = None
    integration_points: int | None = None


@dataclass
class Instance:
    """A part instance: translation (applied first) and rotation (axis through ``a``, ``b``, angle in degrees)."""

    name: str
    part: str
    node_offset: int
    element_offset: int
    translation: np.ndarray
    rotation: tuple[np.ndarray, np.ndarray, float] | None
    location: Location


@dataclass
class Amplitude:
    """``*Amplitude``: definition (``TABULAR`` or ``SMOOTH STEP``), and (time, amplitude) pairs."""

    name: str
    definition: str
    times: np.ndarray
    values: np.ndarray
    time: str
    location: Location


@dataclass
class BoundaryCondition:
    """One ``*Boundary`` data line: dofs ``first_dof..last_dof`` (1-based) of ``nodes`` prescribed to ``value``.

    ``op`` is ``"NEW"`` (conditions of earlier steps released) or ``"MOD"``; ``amplitude`` None means the
    step's default ramp. A named type (``ENCASTRE``, ``PINNED``, ...) is expanded into dofs with value 0.
    """

    target: str
    nodes: np.ndarray
    first_dof: int
    last_dof: int
    value: float
    amplitude: str | None
    op: str
    location: Location
    kind: str = "DISPLACEMENT"


@dataclass
class DistributedLoad:
    """One ``*Dsload`` data line: load type (``P`` = pressure, positive into the surface) on a surface."""

    surface: str
    load_type: str
    magnitude: float
    amplitude: str | None
    op: str
    location: Location
    follower: bool = True


@dataclass
class ConcentratedLoad:
    """One ``*Cload`` data line: force ``magnitude`` on dof ``dof`` of ``nodes``."""

    target: str
    nodes: np.ndarray
    dof: int
    magnitude: float
    amplitude: str | None
    op: str
    location: Location


@dataclass
class ContactPair:
    """``*Contact Pair``: surfaces (one name = self contact), interaction property and constraint method."""

    surfaces: tuple[str, ...]
    interaction: str
    mechanical_constraint: str | None
    cpset: str | None
    location: Location


@dataclass
class GeneralContact:
    """``*Contact`` (general contact) with its inclusions: ``(s1, s2)`` a pair, ``(s,)`` self contact of
    ``s``, ``()`` all exterior faces; property assignments as written (surface, surface, interaction)."""

    inclusions: list[tuple[str, ...]]
    property_assignments: list[tuple[str, str, str]]
    location: Location


@dataclass
class SurfaceInteraction:
    """``*Surface Interaction`` with its ``*Friction`` and ``*Surface Behavior`` options."""

    name: str
    location: Location
    data: list[float] = field(default_factory=list)
    friction: float | None = None
    rough: bool = False
    pressure_overclosure: str = "HARD"
    no_separation: bool = False
    behavior_data: list[float] = field(default_factory=list)


@dataclass
class MPC:
    """One ``*MPC`` data line: type (``LINK``, ``TIE``, ``BEAM``, ...) and the node groups it ties.

    For the two-node types (:data:`TWO_NODE_MPC_TYPES`: ``LINK``, ``PIN``, ``TIE``, ``BEAM``; Abaqus writes
    ``type, p, a``) the reader checks that there are two groups, of equal size or with a single node ``a``; node
    ``k`` of the first group is paired with node ``k`` of the second, or with ``a`` (:meth:`pairs`).
    """

    mpc_type: str
    targets: tuple[str, ...]
    nodes: list[np.ndarray]
    location: Location

    def pairs(self) -> np.ndarray:
        """(n, 2) global node indices ``(p, a)`` of a two-node MPC type."""
        if self.mpc_type not in TWO_NODE_MPC_TYPES:
            raise ValueError(f"{self.location}: MPC {self.mpc_type} does not join pairs of nodes")
        p, a = (np.asarray(group, dtype=np.int64) for group in self.nodes)
        return np.column_stack([p, np.broadcast_to(a, p.shape)])


@dataclass
class RigidBody:
    """``*Rigid Body``: reference node (global index) and the elements made rigid."""

    reference_node: int
    elset: str | None
    elements: np.ndarray
    location: Location
    parameters: dict[str, str] = field(default_factory=dict)


@dataclass
class ConnectorSection:
    """``*Connector Section``: connection types (e.g. ``Slot``) and orientation names, kept as data."""

    elset: str
    elements: np.ndarray
    connection_types: list[str]
    orientations: list[str]
    location: Location
    behavior: str | None = None


@dataclass
class Transform:
    """``*Transform``: local nodal directions for ``nodes`` (type R rectangular, C, S) and its data."""

    nset: str
    nodes: np.ndarray
    transform_type: str
    data: list[float]
    location: Location


@dataclass
class Step:
    """``*Step``: procedure (``"dynamic explicit"``, ``"static"``, ...) with its data and what it applies."""

    name: str
    location: Location
    nlgeom: bool = False
    procedure: str | None = None
    procedure_data: list[float | None] = field(default_factory=list)
    boundary_conditions: list[BoundaryCondition] = field(default_factory=list)
    distributed_loads: list[DistributedLoad] = field(default_factory=list)
    concentrated_loads: list[ConcentratedLoad] = field(default_factory=list)
    contact_pairs: list[ContactPair] = field(default_factory=list)
    general_contact: GeneralContact | None = None

    @property
    def time_period(self) -> float:
        """The step's time period: second field of the procedure data (default 1)."""
        if len(self.procedure_data) > 1 and self.procedure_data[1] is not None:
            return float(self.procedure_data[1])
        return 1.0


@dataclass(frozen=True)
class ReadWarning:
    """Something the reader accepted as Abaqus does but that deserves a look (e.g. a redefined element)."""

    message: str
    location: Location


@dataclass(frozen=True)
class IgnoredKeyword:
    """A keyword the implicit skvalve model does not use (mass scaling, output requests, ...)."""

    keyword: str
    location: Location
    reason: str


@dataclass
class AbaqusModel:
    """Everything read from an Abaqus input file, assembled (see the module docstring for numbering)."""

    path: Path
    nodes: np.ndarray
    node_scopes: np.ndarray
    node_labels: np.ndarray
    scopes: list[str]
    element_blocks: list[ElementBlock]
    node_sets: dict[str, NodeSet]
    element_sets: dict[str, ElementSet]
    surfaces: dict[str, Surface]
    sections: list[Section]
    materials: dict[str, AbaqusMaterial]
    instances: dict[str, Instance]
    amplitudes: dict[str, Amplitude]
    boundary_conditions: list[BoundaryCondition]
    contact_pairs: list[ContactPair]
    interactions: dict[str, SurfaceInteraction]
    mpcs: list[MPC]
    rigid_bodies: list[RigidBody]
    connector_sections: list[ConnectorSection]
    transforms: list[Transform]
    steps: list[Step]
    ignored: list[IgnoredKeyword]
    part_names: list[str]
    warnings: list[ReadWarning] = field(default_factory=list)
    _node_lookup: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict, repr=False)

    @property
    def n_elements(self) -> int:
        return sum(len(b.labels) for b in self.element_blocks)

    def blocks_of_type(self, element_type: str) -> list[ElementBlock]:
        """Element blocks of one type (``"C3D8R"``, ``"T3D2"``, ...)."""
        return [b for b in self.element_blocks if b.element_type == element_type.upper()]

    def elements_by_type(self) -> dict[str, int]:
        """Element count per element type."""
        counts: dict[str, int] = {}
        for block in self.element_blocks:
            counts[block.element_type] = counts.get(block.element_type, 0) + len(block.labels)
        return counts

    def node_set(self, name: str) -> NodeSet:
        """A node set by (qualified) name, case-insensitive."""
        return _lookup(self.node_sets, name, "node set")

    def element_set(self, name: str) -> ElementSet:
        """An element set by (qualified) name, case-insensitive."""
        return _lookup(self.element_sets, name, "element set")

    def surface(self, name: str) -> Surface:
        """A surface by (qualified) name, case-insensitive."""
        return _lookup(self.surfaces, name, "surface")

    def material(self, name: str) -> AbaqusMaterial:
        """A material by name, case-insensitive."""
        for key, material in self.materials.items():
            if key.upper() == name.upper():
                return material
        raise KeyError(f"{self.path}: no material {name!r}; have {sorted(self.materials)}")

    def amplitude(self, name: str) -> Amplitude:
        """An amplitude by name, case-insensitive."""
        return _lookup(self.amplitudes, name, "amplitude")

    def node_indices(self, reference: str | int, scope: str = "") -> np.ndarray:
        """Global indices of a node reference: ``"Inst.12"``, ``"Inst.set"``, an assembly set or label."""
        text = str(reference).strip()
        head, dot, tail = text.partition(".")
        if dot and tail.lstrip("-").isdigit() and head.upper() in self._node_lookup:
            return self._label_indices(head, np.array([int(tail)]))
        if text.lstrip("-").isdigit():
            return self._label_indices(scope, np.array([int(text)]))
        qualified = f"{scope}.{text}" if scope else text
        return self.node_set(qualified).indices

    def _label_indices(self, scope: str, labels: np.ndarray) -> np.ndarray:
        sorted_labels, order = self._node_lookup.get(scope.upper(), (np.empty(0, int), np.empty(0, int)))
        pos = np.searchsorted(sorted_labels, labels)
        pos = np.minimum(pos, max(len(sorted_labels) - 1, 0))
        if len(sorted_labels) == 0 or np.any(sorted_labels[pos] != labels):
            missing = labels[(len(sorted_labels) == 0) | (sorted_labels[pos] != labels)][:5]
            raise KeyError(f"{self.path}: no node {missing.tolist()} in scope {scope or '(assembly)'!r}")
        return order[pos]


def _lookup(table: dict, name: str, what: str):
    try:
        return table[name.strip().upper()]
    except KeyError:
        raise KeyError(f"no {what} {name!r}") from None
