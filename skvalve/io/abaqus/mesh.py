"""Label look-up, the mesh of one scope (a part or the assembly) and the instancing of parts.

A :class:`MeshScope` collects nodes, element blocks, sets, surfaces and sections in its own 0-based
numbering. The assembly scope is the global model: instancing a part appends the part's nodes (moved by
the instance transform) and elements to it and registers the part's sets as ``"Instance.name"``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import AbaqusParseError, Location
from .lexer import Card
from .model import ElementBlock, ElementSet, Instance, NodeSet, ReadWarning, Section, Surface, SurfaceFaces

__all__ = ["LabelIndex", "MeshScope", "last_definitions", "instance_part", "rotation_matrix"]


class LabelIndex:
    """Map of integer labels (node or element numbers) to 0-based indices, with duplicate detection."""

    def __init__(self) -> None:
        self._labels: list[np.ndarray] = []
        self._indices: list[np.ndarray] = []
        self._sorted: tuple[np.ndarray, np.ndarray] | None = (np.empty(0, np.int64), np.empty(0, np.int64))

    def sorted(self) -> tuple[np.ndarray, np.ndarray]:
        """(sorted labels, their indices)."""
        if self._sorted is None:
            labels = np.concatenate(self._labels)
            indices = np.concatenate(self._indices)
            order = np.argsort(labels, kind="stable")
            self._sorted = labels[order], indices[order]
        return self._sorted

    def add(self, labels: np.ndarray, indices: np.ndarray, card: Card, what: str) -> None:
        """Register ``labels`` (unique, see :func:`last_definitions`); a label defined before is an error."""
        found = self.find(labels)
        if np.any(found >= 0):
            raise card.error(f"{what} {int(labels[found >= 0][0])} is already defined")
        self._labels.append(np.asarray(labels, np.int64))
        self._indices.append(np.asarray(indices, np.int64))
        self._sorted = None

    def find(self, labels: np.ndarray) -> np.ndarray:
        """Indices of ``labels``, -1 where a label is unknown."""
        sorted_labels, indices = self.sorted()
        labels = np.asarray(labels, np.int64)
        if len(sorted_labels) == 0:
            return np.full(labels.shape, -1, np.int64)
        pos = np.minimum(np.searchsorted(sorted_labels, labels), len(sorted_labels) - 1)
        return np.where(sorted_labels[pos] == labels, indices[pos], -1)

    def lookup(self, labels: np.ndarray, card: Card, location: Location, what: str) -> np.ndarray:
        """Indices of ``labels``; an unknown label is an error naming it."""
        found = self.find(labels)
        if np.any(found < 0):
            raise card.error(f"unknown {what} {int(np.asarray(labels)[found < 0].flat[0])}", location)
        return found


def last_definitions(labels: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """Rows to keep when a block defines a label twice (Abaqus uses the last definition), and the dropped rows."""
    order = np.arange(len(labels))
    last = {}
    for row, label in zip(order.tolist(), labels.tolist(), strict=True):
        last[label] = row
    keep = np.array(sorted(last.values()), dtype=np.int64)
    dropped = sorted(set(order.tolist()) - set(keep.tolist()))
    return keep, dropped


@dataclass
class MeshScope:
    """Nodes, elements, sets, surfaces and sections of a part or of the assembly (keys upper case)."""

    name: str
    coordinates: list[np.ndarray] = field(default_factory=list)
    n_nodes: int = 0
    node_index: LabelIndex = field(default_factory=LabelIndex)
    blocks: list[ElementBlock] = field(default_factory=list)
    n_elements: int = 0
    element_index: LabelIndex = field(default_factory=LabelIndex)
    node_sets: dict[str, NodeSet] = field(default_factory=dict)
    element_sets: dict[str, ElementSet] = field(default_factory=dict)
    surfaces: dict[str, Surface] = field(default_factory=dict)
    sections: list[Section] = field(default_factory=list)
    #: instance name (upper) -> (instance, part scope); only the assembly scope has instances
    instances: dict[str, tuple[Instance, MeshScope]] = field(default_factory=dict)
    warnings: list[ReadWarning] = field(default_factory=list)

    def keep_last(self, labels: np.ndarray, card: Card, what: str) -> np.ndarray:
        """Rows of a block to keep: a label defined twice in the block keeps its last definition (as Abaqus)."""
        keep, dropped = last_definitions(labels)
        for row in dropped:
            location = card.data[row].location if len(card.data) == len(labels) else card.location
            self.warnings.append(ReadWarning(
                f"{what} {int(labels[row])} is defined again later in the block; the last definition is used",
                location))
        return keep

    def add_nodes(self, labels: np.ndarray, xyz: np.ndarray, card: Card) -> np.ndarray:
        """Append a block of nodes (labels unique within the block); their scope indices."""
        indices = np.arange(self.n_nodes, self.n_nodes + len(labels))
        self.node_index.add(labels, indices, card, "node")
        self.coordinates.append(xyz)
        self.n_nodes += len(labels)
        return indices

    def add_block(self, block: ElementBlock, card: Card) -> None:
        self.element_index.add(block.labels, block.indices, card, "element")
        self.blocks.append(block)
        self.n_elements += len(block.labels)

    def add_to_node_set(self, name: str, indices: np.ndarray, location: Location) -> None:
        key = name.upper()
        if key in self.node_sets:
            old = self.node_sets[key]
            old.indices = np.unique(np.concatenate([old.indices, indices]))
        else:
            self.node_sets[key] = NodeSet(name, np.unique(indices), location)

    def add_to_element_set(self, name: str, indices: np.ndarray, location: Location) -> None:
        key = name.upper()
        if key in self.element_sets:
            old = self.element_sets[key]
            old.indices = np.unique(np.concatenate([old.indices, indices]))
        else:
            self.element_sets[key] = ElementSet(name, np.unique(indices), location)

    def all_coordinates(self) -> np.ndarray:
        return np.concatenate(self.coordinates) if self.coordinates else np.empty((0, 3))

    def element_types(self, elements: np.ndarray) -> list[str]:
        """Element types present among ``elements`` (scope indices)."""
        types = []
        for block in self.blocks:
            hit = (elements >= block.offset) & (elements < block.offset + len(block.labels))
            if np.any(hit) and block.element_type not in types:
                types.append(block.element_type)
        return types


def rotation_matrix(a: np.ndarray, b: np.ndarray, angle_degrees: float) -> np.ndarray:
    """Rotation by ``angle_degrees`` about the unit axis from ``a`` to ``b`` (Rodrigues' formula)."""
    axis = b - a
    axis = axis / np.linalg.norm(axis)
    theta = np.radians(angle_degrees)
    cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(theta) * cross + (1 - np.cos(theta)) * (cross @ cross)


def instance_part(assembly: MeshScope, instance: Instance, part: MeshScope) -> None:
    """Append the nodes, elements, sets, surfaces and sections of ``part`` to the assembly as ``instance``."""
    with np.errstate(over="ignore", invalid="ignore"):
        xyz = part.all_coordinates() + instance.translation
        if instance.rotation is not None:
            a, b, angle = instance.rotation
            xyz = (xyz - a) @ rotation_matrix(a, b, angle).T + a
    if not np.all(np.isfinite(xyz)):
        raise AbaqusParseError(f"instance {instance.name!r}: coordinates overflow after its transform",
                               instance.location, "Instance")
    node_offset, element_offset = assembly.n_nodes, assembly.n_elements
    instance.node_offset, instance.element_offset = node_offset, element_offset
    assembly.coordinates.append(xyz)
    assembly.n_nodes += part.n_nodes
    for block in part.blocks:
        assembly.blocks.append(ElementBlock(
            block.element_type, instance.name, block.labels, block.connectivity + node_offset,
            block.offset + element_offset, f"{instance.name}.{block.elset}" if block.elset else None, block.location))
    assembly.n_elements += part.n_elements
    prefix = f"{instance.name}."
    for key, nset in part.node_sets.items():
        assembly.node_sets[prefix.upper() + key] = NodeSet(
            prefix + nset.name, nset.indices + node_offset, nset.location)
    for key, elset in part.element_sets.items():
        assembly.element_sets[prefix.upper() + key] = ElementSet(
            prefix + elset.name, elset.indices + element_offset, elset.location)
    for key, surface in part.surfaces.items():
        faces = [SurfaceFaces(f.face, f.elements + element_offset) for f in surface.faces]
        assembly.surfaces[prefix.upper() + key] = Surface(prefix + surface.name, faces, surface.location,
                                                          surface.surface_type)
    for section in part.sections:
        assembly.sections.append(Section(
            section.kind, prefix + section.elset, section.material, section.elements + element_offset,
            section.location, section.orientation, section.area, section.thickness, section.integration_points))
    assembly.instances[instance.name.upper()] = (instance, part)
