"""``read_model``: walk the cards of an Abaqus input, dispatch each keyword, assemble an :class:`AbaqusModel`.

Keywords the implicit skvalve model does not use are listed in ``model.ignored`` with a reason and
reported once per file through :mod:`logging`; any keyword the reader does not know is an error (it could
carry a load or a constraint that must not be lost silently).
"""

from __future__ import annotations

import logging
import os
from collections import Counter
from pathlib import Path

import numpy as np

from .errors import AbaqusParseError, Location
from .lexer import Card, data_values, read_cards
from .materials import MATERIAL_OPTIONS, AbaqusMaterial, read_material_option
from .mesh import MeshScope, instance_part
from .mesh_cards import read_elements, read_nodes, read_section, read_set, read_surface
from .model import AbaqusModel, IgnoredKeyword, Instance, ReadWarning
from .state import ParseState
from .step_cards import HISTORY_HANDLERS

__all__ = ["read_model", "read_materials", "IGNORED_KEYWORDS"]

logger = logging.getLogger(__name__)

_OUTPUT = "output request"
_EXPLICIT = "explicit dynamics only (mass scaling / bulk viscosity)"
_ORIENTATION = "local material directions are not read"
#: Keywords skipped (with their data) and why.
IGNORED_KEYWORDS = {
    "output": _OUTPUT, "element output": _OUTPUT, "node output": _OUTPUT, "contact output": _OUTPUT,
    "energy output": _OUTPUT, "restart": _OUTPUT, "monitor": _OUTPUT, "el print": _OUTPUT,
    "node print": _OUTPUT, "node file": _OUTPUT, "el file": _OUTPUT, "print": _OUTPUT,
    "bulk viscosity": _EXPLICIT, "variable mass scaling": _EXPLICIT, "fixed mass scaling": _EXPLICIT,
    "distribution": _ORIENTATION, "distribution table": _ORIENTATION, "orientation": _ORIENTATION,
    "heading": "title only", "preprint": "printout control",
}
#: Material options that are kept in the material but that the implicit model does not use.
IGNORED_MATERIAL_OPTIONS = {"density": "mass density (no inertia in the quasi-static implicit model)",
                            "transverse shear": "shell transverse-shear stiffness (shells are not used as shells)",
                            "damping": "material damping (no dynamics)"}


def _part(card: Card, state: ParseState) -> None:
    if state.in_part or state.in_assembly:
        raise card.error("*Part inside a *Part or *Assembly")
    name = card.require("name")
    if name.upper() in state.parts:
        raise card.error(f"part {name!r} is defined twice")
    state.scope = state.parts[name.upper()] = state.part_scopes[id(card)]
    state.part_names.append(name)
    state.in_part = True


def _end_part(card: Card, state: ParseState) -> None:
    if not state.in_part:
        raise card.error("*End Part without *Part")
    state.in_part, state.scope = False, state.assembly


def _assembly(card: Card, state: ParseState) -> None:
    if state.in_part or state.in_assembly or state.assembly_seen or state.steps or state.step:
        raise card.error("*Assembly must come once, after the parts and before the steps")
    state.in_assembly = state.assembly_seen = True


def _end_assembly(card: Card, state: ParseState) -> None:
    if not state.in_assembly or state.open_instance is not None:
        raise card.error("*End Assembly without *Assembly (or inside *Instance)")
    state.in_assembly = False


def _instance(card: Card, state: ParseState) -> None:
    if not state.in_assembly or state.open_instance is not None:
        raise card.error("*Instance belongs in the *Assembly (and instances do not nest)")
    state.open_instance = card


def _end_instance(card: Card, state: ParseState) -> None:
    opened = state.open_instance
    if opened is None:
        raise card.error("*End Instance without *Instance")
    state.open_instance = None
    name, part_name = opened.require("name"), opened.require("part")
    if part_name.upper() not in state.parts:
        raise opened.error(f"unknown part {part_name!r}")
    if name.upper() in state.assembly.instances:
        raise opened.error(f"instance {name!r} is defined twice")
    rows = [data_values(Card(opened.keyword, {}, [], line.location, [line.text], [line.location.line]), blank=None)
            for line in opened.data]
    if len(rows) > 2 or (rows and len(rows[0]) != 3) or (len(rows) == 2 and len(rows[1]) != 7):
        raise opened.error("instance data: a translation line (3 values) and a rotation line (a, b, angle: 7)")
    translation = np.array(rows[0]) if rows else np.zeros(3)
    rotation = None
    if len(rows) == 2:
        a, b = np.array(rows[1][:3]), np.array(rows[1][3:6])
        if np.linalg.norm(b - a) == 0:
            raise opened.error("rotation axis points a and b coincide")
        rotation = (a, b, rows[1][6])
    instance = Instance(name, part_name, 0, 0, translation, rotation, opened.location)
    instance_part(state.assembly, instance, state.parts[part_name.upper()])


def _material(card: Card, state: ParseState) -> None:
    name = card.require("name")
    if card.data:
        raise card.error("*Material takes no data lines", card.data[0].location)
    for key, other in state.materials.items():
        if key.upper() == name.upper():
            raise card.error(f"material {name!r} is already defined at line {other.line} as {key!r} "
                             "(Abaqus names are case-insensitive)")
    state.material = state.materials[name] = AbaqusMaterial(name, card.location.line)


def _material_option(card: Card, state: ParseState) -> None:
    assert state.material is not None
    state.material.options.append(read_material_option(card))
    if card.keyword in IGNORED_MATERIAL_OPTIONS:
        state.ignored.append(IgnoredKeyword(card.title, card.location, IGNORED_MATERIAL_OPTIONS[card.keyword]))


def _mesh(handler):
    """A mesh keyword's handler, run where mesh data may appear (nodes and elements: only checked here)."""
    def run(card: Card, state: ParseState) -> None:
        if state.open_instance is not None:
            raise card.error("definitions inside *Instance are not supported")
        if state.step is not None:
            raise card.error("mesh definitions are not allowed inside a *Step")
        if not (state.in_assembly or state.in_part or not state.assembly_seen):
            raise card.error("mesh definitions after *End Assembly")
        if handler is not None:
            handler(card, state.scope)
    return run


def _read_nodes_and_elements(cards: list[Card], state: ParseState) -> None:
    """First pass: all ``*Node`` and ``*Element`` blocks, so that sets may name elements defined later
    (Abaqus allows it; the 1.0 clipping input does). Parts get their scope here."""
    scope = state.assembly
    for card in cards:
        if card.keyword == "part":
            scope = state.part_scopes[id(card)] = MeshScope(card.require("name"))
        elif card.keyword == "end part":
            scope = state.assembly
        elif card.keyword == "node":
            read_nodes(card, scope)
        elif card.keyword == "element":
            read_elements(card, scope)


_HANDLERS = {
    "part": _part, "end part": _end_part, "assembly": _assembly, "end assembly": _end_assembly,
    "instance": _instance, "end instance": _end_instance, "material": _material,
    "node": _mesh(None), "element": _mesh(None), "nset": _mesh(read_set), "elset": _mesh(read_set),
    "surface": _mesh(read_surface), "solid section": _mesh(read_section), "shell section": _mesh(read_section),
    "membrane section": _mesh(read_section), **HISTORY_HANDLERS,
}


def _dispatch(card: Card, state: ParseState) -> None:
    if state.open_instance is not None and card.keyword != "end instance":
        raise card.error("only *End Instance may follow *Instance")
    if state.material is not None and card.keyword in MATERIAL_OPTIONS:
        _material_option(card, state)
        return
    state.material = None
    if card.keyword in MATERIAL_OPTIONS:
        raise card.error("material option outside a *Material")
    if card.keyword not in ("friction", "surface behavior"):
        state.interaction = None
    if "input" in card.parameters:
        raise card.error("data read from another file (INPUT=) is only supported through *Include")
    if card.keyword in IGNORED_KEYWORDS:
        state.ignored.append(IgnoredKeyword(card.title, card.location, IGNORED_KEYWORDS[card.keyword]))
        return
    handler = _HANDLERS.get(card.keyword)
    if handler is None:
        raise card.error("keyword not supported by the skvalve Abaqus reader")
    if card.keyword in ("end part", "end assembly", "end instance", "end step", "assembly") and card.data:
        raise card.error("takes no data lines", card.data[0].location)
    handler(card, state)


def _check_references(state: ParseState) -> None:
    """Amplitudes, materials and interactions named anywhere must exist."""
    users = [*state.boundary_conditions]
    for step in state.steps:
        users += [*step.boundary_conditions, *step.distributed_loads, *step.concentrated_loads]
    for item in users:
        if item.amplitude is not None and item.amplitude.upper() not in state.amplitudes:
            raise AbaqusParseError(f"unknown amplitude {item.amplitude!r}", item.location)
    names = {m.upper() for m in state.materials}
    for section in state.assembly.sections + [s for p in state.parts.values() for s in p.sections]:
        if section.material.upper() not in names:
            raise AbaqusParseError(f"section on {section.elset!r} uses unknown material {section.material!r}",
                                   section.location)
    pairs = state.contact_pairs + [p for step in state.steps for p in step.contact_pairs]
    for pair in pairs:
        if pair.interaction.upper() not in state.interactions:
            raise AbaqusParseError(f"unknown surface interaction {pair.interaction!r}", pair.location)


def _check_end_of_file(cards: list[Card], state: ParseState) -> None:
    """What a file cut at a line leaves behind: nothing at all, a ``*Material`` without options, model data of
    parts and an assembly without any ``*Step``, a last keyword line without its newline.

    Errors where the input cannot be whole (nothing read, a last ``*Material`` with nothing after it), warnings
    (``state.warnings``) where Abaqus reads it as it is.
    """
    if not cards:
        raise AbaqusParseError("no keyword lines: an empty file, or not an Abaqus input", Location(state.path, 1))
    last = cards[-1]
    if state.assembly.n_nodes == 0 and not (state.parts or state.materials or state.steps):
        raise AbaqusParseError("the input defines no nodes, parts, materials or steps: an empty or cut file?",
                               last.location)
    for card, following in zip(cards, [*cards[1:], None], strict=True):
        if card.keyword != "material" or (following is not None and following.keyword in MATERIAL_OPTIONS):
            continue
        if following is None:
            raise card.error("the file ends after *Material: a material without options (the file cut short?)")
        state.warnings.append(ReadWarning(f"material {card.parameters.get('name')!r} has no material options",
                                          card.location))
    if (state.parts or state.assembly_seen) and not state.steps:
        state.warnings.append(ReadWarning("parts and an assembly but no *Step: the history data (steps, loads) "
                                          "are missing, or the file was cut short", last.location))
    if last.unterminated and not last.keyword.startswith("end "):
        state.warnings.append(ReadWarning(f"the file ends in this *{last.title} line without a final newline: "
                                          "cut short?", last.location))


def _assemble(state: ParseState) -> AbaqusModel:
    assembly = state.assembly
    scopes = [""] + [inst.name for inst, _ in assembly.instances.values()]
    scope_of = np.zeros(assembly.n_nodes, np.int64)
    labels = np.zeros(assembly.n_nodes, np.int64)
    lookup = {}
    sorted_labels, indices = assembly.node_index.sorted()
    labels[indices] = sorted_labels
    lookup[""] = (sorted_labels, indices)
    for number, (instance, part) in enumerate(assembly.instances.values(), start=1):
        part_labels, part_indices = part.node_index.sorted()
        global_indices = part_indices + instance.node_offset
        scope_of[global_indices] = number
        labels[global_indices] = part_labels
        lookup[instance.name.upper()] = (part_labels, global_indices)
    model = AbaqusModel(
        path=state.path, nodes=assembly.all_coordinates(), node_scopes=scope_of, node_labels=labels, scopes=scopes,
        element_blocks=assembly.blocks, node_sets=assembly.node_sets, element_sets=assembly.element_sets,
        surfaces=assembly.surfaces, sections=assembly.sections, materials=state.materials,
        instances={key: inst for key, (inst, _) in assembly.instances.items()}, amplitudes=state.amplitudes,
        boundary_conditions=state.boundary_conditions, contact_pairs=state.contact_pairs,
        interactions=state.interactions, mpcs=state.mpcs, rigid_bodies=state.rigid_bodies,
        connector_sections=state.connector_sections, transforms=state.transforms, steps=state.steps,
        ignored=state.ignored, part_names=state.part_names)
    model.warnings = [w for scope in (assembly, *state.parts.values()) for w in scope.warnings] + state.warnings
    model._node_lookup = lookup
    return model


def read_model(path: str | os.PathLike) -> AbaqusModel:
    """Read an Abaqus input file (``*Include`` expanded) into an assembled :class:`AbaqusModel`.

    Raises :class:`AbaqusParseError` (file, line, keyword) on malformed or unsupported input.
    """
    path = Path(path)
    state = ParseState(path)
    cards = read_cards(path)
    _read_nodes_and_elements(cards, state)
    for card in cards:
        _dispatch(card, state)
    last = cards[-1] if cards else None
    if state.in_part or state.in_assembly or state.open_instance is not None:
        raise AbaqusParseError("the file ends inside a *Part, *Assembly or *Instance", last.location if last else None)
    if state.step is not None:
        raise AbaqusParseError(f"step {state.step.name!r} has no *End Step", state.step.location)
    _check_end_of_file(cards, state)
    _check_references(state)
    model = _assemble(state)
    for warning in model.warnings:
        logger.warning("%s: %s", warning.location, warning.message)
    if model.ignored:
        counts = Counter(item.keyword for item in model.ignored)
        listing = ", ".join(f"*{name} x{count}" for name, count in sorted(counts.items()))
        logger.warning("%s: not used by the implicit model (see model.ignored): %s", path, listing)
    return model



def read_materials(path: str | os.PathLike) -> dict[str, AbaqusMaterial]:
    """All ``*Material`` blocks of an Abaqus input file, by name as written.

    Reads only the materials (with the same strict rules as :func:`read_model`: counts, numbers,
    duplicate names, ``*Include``), so a file whose other keywords the model reader rejects still works.
    """
    state = ParseState(Path(path))
    for card in read_cards(Path(path)):
        if card.keyword == "material":
            _material(card, state)
        elif state.material is not None and card.keyword in MATERIAL_OPTIONS:
            _material_option(card, state)
        elif card.keyword in MATERIAL_OPTIONS:
            raise card.error("material option outside a *Material")
        else:
            state.material = None
    return state.materials
