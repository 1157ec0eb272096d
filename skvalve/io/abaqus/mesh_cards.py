"""Keyword handlers for the mesh: ``*Node``, ``*Element``, ``*Nset``, ``*Elset``, ``*Surface`` and sections."""

from __future__ import annotations

import numpy as np

from .elements import FACE_LABELS, NODES_PER_ELEMENT, SHELL_FACE_LABELS, is_shell_like
from .errors import Location
from .lexer import _INT, MAX_INT, Card, fast_table, parse_float, parse_int, split_fields
from .mesh import MeshScope
from .model import ElementBlock, Section, Surface, SurfaceFaces

__all__ = ["read_nodes", "read_elements", "read_set", "read_surface", "read_section", "resolve_nodes",
           "resolve_elements"]

#: Largest set a ``generate`` line may produce (guards against a typo asking for billions of labels).
MAX_GENERATED = 10_000_000


def _instance_scope(scope: MeshScope, name: str, card: Card, location: Location):
    try:
        return scope.instances[name.upper()]
    except KeyError:
        raise card.error(f"unknown instance {name!r}", location) from None


def _resolve(token: str, scope: MeshScope, card: Card, location: Location, kind: str,
             instance: str | None = None) -> np.ndarray:
    """Scope indices of a node/element label or set name; ``Inst.label``/``Inst.set`` in the assembly."""
    nodes = kind == "node"
    offset = 0
    target = scope
    if instance is not None:
        inst, target = _instance_scope(scope, instance, card, location)
        offset = inst.node_offset if nodes else inst.element_offset
    elif "." in token and scope.instances:
        head, tail = token.split(".", 1)
        inst, target = _instance_scope(scope, head, card, location)
        offset = inst.node_offset if nodes else inst.element_offset
        token = tail
    if _INT.fullmatch(token):
        index = target.node_index if nodes else target.element_index
        return index.lookup(np.array([int(token)]), card, location, kind) + offset
    sets = target.node_sets if nodes else target.element_sets
    try:
        return sets[token.upper()].indices + offset
    except KeyError:
        raise card.error(f"unknown {kind} set {token!r}", location) from None


def resolve_nodes(token: str, scope: MeshScope, card: Card, location: Location, instance: str | None = None):
    """Scope node indices of a label, ``Inst.label``, set or ``Inst.set``."""
    return _resolve(token, scope, card, location, "node", instance)


def resolve_elements(token: str, scope: MeshScope, card: Card, location: Location, instance: str | None = None):
    """Scope element indices of a label, ``Inst.label``, set or ``Inst.set``."""
    return _resolve(token, scope, card, location, "element", instance)


def read_nodes(card: Card, scope: MeshScope) -> None:
    """``*Node``: label and up to three coordinates per line (missing coordinates are 0)."""
    if card.parameters.get("system", "R").upper() != "R":
        raise card.error("only rectangular nodal coordinates (SYSTEM=R) are supported")
    if not card.texts and "input" not in card.parameters:  # INPUT= is rejected with its own message
        raise card.error("no data lines (label, coordinates): the block is empty or the file cut short")
    table = fast_table(card, 4, integer=False)
    if table is not None and np.all(np.abs(table[:, 0]) <= MAX_INT) and \
            all(_INT.fullmatch(text.split(",", 1)[0].strip()) for text in card.texts):
        labels, xyz = table[:, 0].astype(np.int64), table[:, 1:]
    else:
        labels, xyz = _read_node_lines(card)
    if np.any(labels <= 0):
        row = int(np.flatnonzero(labels <= 0)[0])
        raise card.error(f"node label {int(labels[row])} is not positive", card.data[row].location)
    keep = scope.keep_last(labels, card, "node")
    indices = scope.add_nodes(labels[keep], xyz[keep], card)
    if "nset" in card.parameters:
        scope.add_to_node_set(card.require("nset"), indices, card.location)


def _read_node_lines(card: Card) -> tuple[np.ndarray, np.ndarray]:
    n = len(card.data)
    labels = np.empty(n, np.int64)
    xyz = np.zeros((n, 3))
    for row, line in enumerate(card.data):
        fields = split_fields(line.text)
        if len(fields) > 4:
            raise card.error(f"a node line has at most a label and 3 coordinates, found {len(fields)} fields",
                             line.location)
        labels[row] = parse_int(fields[0], card, line.location, "node label")
        for col, token in enumerate(fields[1:]):
            if token:
                xyz[row, col] = parse_float(token, card, line.location, "coordinate")
    return labels, xyz


def read_elements(card: Card, scope: MeshScope) -> None:
    """``*Element``: label and nodes per element; a line ending in a comma continues on the next."""
    element_type = card.require("type").upper()
    if element_type not in NODES_PER_ELEMENT:
        raise card.error(f"unsupported element type {element_type}")
    per_element = NODES_PER_ELEMENT[element_type]
    if not card.texts and "input" not in card.parameters:
        raise card.error("no data lines (label, nodes): the block is empty or the file cut short")
    table = fast_table(card, per_element + 1, integer=True)
    if table is None:
        table = _read_element_lines(card, element_type, per_element)
    if np.any(table[:, 0] <= 0):
        raise card.error(f"element label {int(table[table[:, 0] <= 0, 0][0])} is not positive")
    table = table[scope.keep_last(table[:, 0], card, "element")]
    where = card.data[0].location if card.data else card.location
    connectivity = _node_columns(table[:, 1:], scope, card, where)
    elset = card.parameters.get("elset") or None
    block = ElementBlock(element_type, scope.name, table[:, 0], connectivity, scope.n_elements, elset, card.location)
    scope.add_block(block, card)
    if elset:
        scope.add_to_element_set(elset, block.indices, card.location)


def _read_element_lines(card: Card, element_type: str, per_element: int) -> np.ndarray:
    rows: list[list[int]] = []
    pending: list[int] = []
    for line in card.data:
        raw = [f.strip() for f in line.text.split(",")]
        continues = raw[-1] == ""
        tokens = raw[:-1] if continues else raw
        for token in tokens:
            pending.append(parse_int(token, card, line.location, "element label or node"))
        if len(pending) > per_element + 1:
            raise card.error(f"element {pending[0]}: {len(pending) - 1} nodes, {element_type} has {per_element}",
                             line.location)
        if len(pending) == per_element + 1:
            rows.append(pending)
            pending = []
        elif not continues:
            raise card.error(f"element {pending[0]}: {len(pending) - 1} nodes, {element_type} has {per_element}",
                             line.location)
    if pending:
        raise card.error(f"element {pending[0]} is cut short", card.data[-1].location)
    return np.array(rows, np.int64).reshape(-1, per_element + 1)


def _node_columns(labels: np.ndarray, scope: MeshScope, card: Card, where: Location) -> np.ndarray:
    found = scope.node_index.find(labels)
    if np.any(found < 0):
        row, column = (int(i[0]) for i in np.nonzero(found < 0))
        raise card.error(f"element {row + 1} of the block refers to undefined node {int(labels[row, column])}",
                         where)
    return found


def _generate(fields: list[str], card: Card, location: Location) -> np.ndarray:
    if len(fields) not in (2, 3) or any(not f for f in fields):
        raise card.error("a GENERATE line is: first, last[, increment]", location)
    first, last = (parse_int(f, card, location) for f in fields[:2])
    step = parse_int(fields[2], card, location) if len(fields) == 3 else 1
    if step <= 0 or last < first:
        raise card.error(f"GENERATE {first}, {last}, {step}: need first <= last and increment > 0", location)
    if (last - first) // step + 1 > MAX_GENERATED:
        raise card.error(f"GENERATE {first}, {last}, {step} asks for more than {MAX_GENERATED} labels", location)
    return np.arange(first, last + 1, step, dtype=np.int64)


def read_set(card: Card, scope: MeshScope) -> None:
    """``*Nset`` / ``*Elset``: labels, set names or ``generate`` ranges (optionally of an ``instance=``)."""
    nodes = card.keyword == "nset"
    name = card.require("nset" if nodes else "elset")
    instance = card.parameters.get("instance")
    if instance is not None and not scope.instances:
        raise card.error("INSTANCE= is only allowed in the assembly")
    chunks: list[np.ndarray] = [np.empty(0, np.int64)]
    if nodes and card.parameters.get("elset"):
        if card.data or instance is not None:
            raise card.error("*Nset with ELSET= takes no data lines and no INSTANCE=")
        chunks.append(_element_nodes(resolve_elements(card.parameters["elset"], scope, card, card.location), scope))
    labels: list[int] = []
    label_lines: list[Location] = []
    for line in card.data:
        fields = split_fields(line.text)
        if "generate" in card.flags:
            generated = _generate(fields, card, line.location)
            chunks.append(_labels_to_indices(generated, [line.location] * len(generated), scope, card, nodes,
                                             instance))
            continue
        for token in fields:
            if not token:
                raise card.error("blank field in a set definition", line.location)
            if _INT.fullmatch(token):
                labels.append(parse_int(token, card, line.location, "label"))
                label_lines.append(line.location)
            else:
                resolve = resolve_nodes if nodes else resolve_elements
                chunks.append(resolve(token, scope, card, line.location, instance))
    if labels:
        chunks.append(_labels_to_indices(np.array(labels, np.int64), label_lines, scope, card, nodes, instance))
    indices = np.concatenate(chunks)
    if nodes:
        scope.add_to_node_set(name, indices, card.location)
    else:
        scope.add_to_element_set(name, indices, card.location)


def _element_nodes(elements: np.ndarray, scope: MeshScope) -> np.ndarray:
    """Nodes (scope indices) of the given elements."""
    found = [block.connectivity[elements[(elements >= block.offset) & (elements < block.offset + len(block.labels))]
                                - block.offset].ravel() for block in scope.blocks]
    return np.unique(np.concatenate([np.empty(0, np.int64), *found]))


def _labels_to_indices(labels: np.ndarray, lines: list[Location], scope: MeshScope, card: Card, nodes: bool,
                       instance: str | None) -> np.ndarray:
    offset, target = 0, scope
    if instance is not None:
        inst, target = _instance_scope(scope, instance, card, lines[0])
        offset = inst.node_offset if nodes else inst.element_offset
    found = (target.node_index if nodes else target.element_index).find(labels)
    if np.any(found < 0):
        first = int(np.flatnonzero(found < 0)[0])
        raise card.error(f"unknown {'node' if nodes else 'element'} {int(labels[first])}", lines[first])
    return found + offset


def read_surface(card: Card, scope: MeshScope) -> None:
    """``*Surface, type=ELEMENT``: lines of ``element set or label, face label``."""
    surface_type = card.parameters.get("type", "ELEMENT").upper()
    if surface_type != "ELEMENT":
        raise card.error(f"only element-based surfaces are supported, not TYPE={surface_type}")
    name = card.require("name")
    faces: list[SurfaceFaces] = []
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) != 2 or not fields[0] or not fields[1]:
            raise card.error("a surface line is: element set or label, face label (S1..S6, SPOS, SNEG)",
                             line.location)
        elements = resolve_elements(fields[0], scope, card, line.location)
        face = fields[1].upper()
        for element_type in scope.element_types(elements):
            allowed = SHELL_FACE_LABELS if is_shell_like(element_type) else \
                FACE_LABELS.get(NODES_PER_ELEMENT[element_type], ())
            if face not in allowed:
                raise card.error(f"face {face} does not exist on {element_type} elements", line.location)
        faces.append(SurfaceFaces(face, elements))
    if not faces:
        raise card.error("surface without faces")
    if name.upper() in scope.surfaces:
        raise card.error(f"surface {name!r} is defined twice")
    scope.surfaces[name.upper()] = Surface(name, faces, card.location, surface_type)


def read_section(card: Card, scope: MeshScope) -> None:
    """``*Solid Section``, ``*Shell Section``, ``*Membrane Section`` on an element set."""
    kind = card.keyword.split()[0]
    elset = card.require("elset")
    material = card.require("material")
    elements = resolve_elements(elset, scope, card, card.location)
    if len(card.data) > 1:
        raise card.error("more than one data line is not supported for a section", card.data[1].location)
    fields = split_fields(card.data[0].text) if card.data else []
    location = card.data[0].location if card.data else card.location
    first = parse_float(fields[0], card, location, "section value") if fields and fields[0] else None
    section = Section(kind, elset, material, elements, card.location, card.parameters.get("orientation"))
    if kind == "solid":
        types = scope.element_types(elements)
        if first is not None and types and all(t.startswith("T") for t in types):
            section.area = first
        else:
            section.thickness = first
    else:
        if first is None or first <= 0:
            raise card.error(f"a {kind} section needs a positive thickness", location)
        section.thickness = first
        if kind == "shell" and len(fields) > 1 and fields[1]:
            section.integration_points = parse_int(fields[1], card, location, "integration points")
            if section.integration_points <= 0:
                raise card.error("the number of integration points must be positive", location)
    if section.area is not None and section.area <= 0:
        raise card.error(f"truss cross-section area {section.area} is not positive", location)
    scope.sections.append(section)
