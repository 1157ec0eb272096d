"""Keyword handlers for history and constraints: amplitudes, boundary conditions, loads, contact, MPCs,
rigid bodies, connectors, transforms and steps."""

from __future__ import annotations

import numpy as np

from .lexer import Card, data_values, parse_float, parse_int, split_fields
from .mesh_cards import resolve_elements, resolve_nodes
from .model import (
    MPC,
    TWO_NODE_MPC_TYPES,
    Amplitude,
    BoundaryCondition,
    ConcentratedLoad,
    ConnectorSection,
    ContactPair,
    DistributedLoad,
    GeneralContact,
    RigidBody,
    Step,
    SurfaceInteraction,
    Transform,
)
from .state import ParseState

__all__ = ["HISTORY_HANDLERS"]

#: Named boundary-condition types and the dofs they fix (Abaqus "Boundary conditions" section).
NAMED_BOUNDARY_TYPES = {"ENCASTRE": (1, 2, 3, 4, 5, 6), "PINNED": (1, 2, 3), "XSYMM": (1, 5, 6),
                        "YSYMM": (2, 4, 6), "ZSYMM": (3, 4, 5), "XASYMM": (2, 3, 4), "YASYMM": (1, 3, 5),
                        "ZASYMM": (1, 2, 6)}
MAX_DOF = 6


def _op(card: Card) -> str:
    op = card.parameters.get("op", "MOD").upper()
    if op not in ("MOD", "NEW"):
        raise card.error(f"OP={op}: expected MOD or NEW")
    return op


def _require_data(card: Card, op: str) -> None:
    """Boundary conditions and loads need data lines; only ``OP=NEW`` (remove the previous ones) comes without."""
    if not card.data and op != "NEW":
        raise card.error("no data lines (only OP=NEW may come without them): the block is empty or the file cut "
                         "short")


def _surface_name(token: str, state: ParseState, card: Card, location) -> str:
    if token.upper() not in state.assembly.surfaces:
        raise card.error(f"unknown surface {token!r}", location)
    return state.assembly.surfaces[token.upper()].name


def read_amplitude(card: Card, state: ParseState) -> None:
    name = card.require("name")
    definition = card.parameters.get("definition", "TABULAR").upper()
    if definition not in ("TABULAR", "SMOOTH STEP"):
        raise card.error(f"DEFINITION={definition} is not supported (TABULAR, SMOOTH STEP)")
    values = data_values(card, blank=None)
    if len(values) < 2 or len(values) % 2:
        raise card.error(f"expected (time, amplitude) pairs, found {len(values)} values")
    pairs = np.array(values).reshape(-1, 2)
    steps = np.diff(pairs[:, 0])
    if np.any(steps < 0) or (definition == "SMOOTH STEP" and np.any(steps <= 0)):
        raise card.error("amplitude times must increase")
    if name.upper() in state.amplitudes:
        raise card.error(f"amplitude {name!r} is defined twice")
    state.amplitudes[name.upper()] = Amplitude(name, definition, pairs[:, 0].copy(), pairs[:, 1].copy(),
                                               card.parameters.get("time", "STEP TIME").upper(), card.location)


def _dof(token: str, card: Card, location) -> int:
    dof = parse_int(token, card, location, "degree of freedom")
    if not 1 <= dof <= MAX_DOF:
        raise card.error(f"degree of freedom {dof} is not in 1..{MAX_DOF}", location)
    return dof


def read_boundary(card: Card, state: ParseState) -> None:
    scope = state.model_scope(card)
    op, amplitude = _op(card), card.parameters.get("amplitude")
    kind = card.parameters.get("type", "DISPLACEMENT").upper()
    target = state.step.boundary_conditions if state.step else state.boundary_conditions
    _require_data(card, op)
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) < 2 or len(fields) > 4 or not fields[0]:
            raise card.error("a boundary line is: node or set, first dof[, last dof[, value]]", line.location)
        nodes = resolve_nodes(fields[0], scope, card, line.location)
        if fields[1].upper() in NAMED_BOUNDARY_TYPES:
            if len(fields) > 2:
                raise card.error(f"{fields[1]} takes no further fields", line.location)
            for dof in NAMED_BOUNDARY_TYPES[fields[1].upper()]:
                target.append(BoundaryCondition(fields[0], nodes, dof, dof, 0.0, amplitude, op, line.location, kind))
            continue
        first = _dof(fields[1], card, line.location)
        last = _dof(fields[2], card, line.location) if len(fields) > 2 and fields[2] else first
        if last < first:
            raise card.error(f"last dof {last} < first dof {first}", line.location)
        value = parse_float(fields[3], card, line.location) if len(fields) > 3 and fields[3] else 0.0
        target.append(BoundaryCondition(fields[0], nodes, first, last, value, amplitude, op, line.location, kind))


def _require_step(card: Card, state: ParseState) -> Step:
    if state.step is None:
        raise card.error("only allowed inside a *Step")
    return state.step


def read_dsload(card: Card, state: ParseState) -> None:
    step = _require_step(card, state)
    op, amplitude = _op(card), card.parameters.get("amplitude")
    follower = card.parameters.get("follower", "YES").upper() != "NO"
    _require_data(card, op)
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) != 3 or not fields[0]:
            raise card.error("a *Dsload line is: surface, P, magnitude", line.location)
        load_type = fields[1].upper()
        if load_type != "P":
            raise card.error(f"load type {fields[1]!r} is not supported (P)", line.location)
        surface = _surface_name(fields[0], state, card, line.location)
        magnitude = parse_float(fields[2], card, line.location, "magnitude")
        step.distributed_loads.append(
            DistributedLoad(surface, load_type, magnitude, amplitude, op, line.location, follower))


def read_cload(card: Card, state: ParseState) -> None:
    step = _require_step(card, state)
    op, amplitude = _op(card), card.parameters.get("amplitude")
    _require_data(card, op)
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) != 3 or not fields[0]:
            raise card.error("a *Cload line is: node or set, dof, magnitude", line.location)
        nodes = resolve_nodes(fields[0], state.assembly, card, line.location)
        dof = _dof(fields[1], card, line.location)
        magnitude = parse_float(fields[2], card, line.location, "magnitude")
        step.concentrated_loads.append(ConcentratedLoad(fields[0], nodes, dof, magnitude, amplitude, op, line.location))


def read_contact_pair(card: Card, state: ParseState) -> None:
    state.model_scope(card)
    interaction = card.require("interaction")
    target = state.step.contact_pairs if state.step else state.contact_pairs
    for line in card.data:
        fields = split_fields(line.text)
        if not 1 <= len(fields) <= 2 or not all(fields):
            raise card.error("a contact pair line is: surface[, surface]", line.location)
        surfaces = tuple(_surface_name(f, state, card, line.location) for f in fields)
        target.append(ContactPair(surfaces, interaction, card.parameters.get("mechanical constraint"),
                                  card.parameters.get("cpset"), line.location))
    if not card.data:
        raise card.error("contact pair without surfaces")


def read_contact(card: Card, state: ParseState) -> None:
    step = _require_step(card, state)
    if card.data:
        raise card.error("*Contact takes no data lines", card.data[0].location)
    state.contact = step.general_contact = GeneralContact([], [], card.location)


def _open_contact(card: Card, state: ParseState) -> GeneralContact:
    if state.contact is None:
        raise card.error("must follow *Contact")
    return state.contact


def read_contact_inclusions(card: Card, state: ParseState) -> None:
    contact = _open_contact(card, state)
    if "all exterior" in card.flags:
        contact.inclusions.append(())
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) > 2:
            raise card.error("an inclusion line is: surface[, surface]", line.location)
        names = tuple(_surface_name(f, state, card, line.location) if f else None for f in fields)
        contact.inclusions.append(names if any(names) else ())


def read_contact_property_assignment(card: Card, state: ParseState) -> None:
    contact = _open_contact(card, state)
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) != 3 or not fields[2]:
            raise card.error("a property assignment line is: surface, surface, interaction", line.location)
        contact.property_assignments.append((fields[0], fields[1], fields[2]))


def read_surface_interaction(card: Card, state: ParseState) -> None:
    name = card.require("name")
    if name.upper() in state.interactions:
        raise card.error(f"surface interaction {name!r} is defined twice")
    state.interaction = SurfaceInteraction(name, card.location, data_values(card))
    state.interactions[name.upper()] = state.interaction


def _open_interaction(card: Card, state: ParseState) -> SurfaceInteraction:
    if state.interaction is None:
        raise card.error("must follow *Surface Interaction")
    return state.interaction


def read_friction(card: Card, state: ParseState) -> None:
    interaction = _open_interaction(card, state)
    values = data_values(card)
    interaction.rough = "rough" in card.flags
    if not interaction.rough:
        if len(values) != 1 or values[0] < 0:
            raise card.error("expected one non-negative friction coefficient")
        interaction.friction = values[0]


def read_surface_behavior(card: Card, state: ParseState) -> None:
    interaction = _open_interaction(card, state)
    interaction.pressure_overclosure = card.parameters.get("pressure-overclosure", "HARD").upper()
    interaction.no_separation = "no separation" in card.flags
    interaction.behavior_data = data_values(card)


def read_mpc(card: Card, state: ParseState) -> None:
    scope = state.model_scope(card)
    if not card.data:
        raise card.error("no data lines (type, node or set, node or set): the block is empty or the file cut short")
    for line in card.data:
        fields = split_fields(line.text)
        if len(fields) < 3 or not all(fields):
            raise card.error("an MPC line is: type, node or set, node or set[, ...]", line.location)
        nodes = [resolve_nodes(f, scope, card, line.location) for f in fields[1:]]
        kind = fields[0].upper()
        if kind in TWO_NODE_MPC_TYPES:
            if len(nodes) != 2 or len(nodes[1]) not in (1, len(nodes[0])):
                raise card.error(f"MPC {kind} joins node p to node a (node sets: of equal size, or a single node a); "
                                 f"got {' and '.join(str(len(n)) for n in nodes)} node(s) in {', '.join(fields[1:])}",
                                 line.location)
            same = np.flatnonzero(np.asarray(nodes[0]) == np.asarray(nodes[1]))  # broadcasts a single a
            if same.size:
                raise card.error(f"MPC {kind} joins a node to itself ({fields[1]} and {fields[2]}, pair "
                                 f"{int(same[0])})", line.location)
        state.mpcs.append(MPC(kind, tuple(fields[1:]), nodes, line.location))


def read_rigid_body(card: Card, state: ParseState) -> None:
    scope = state.model_scope(card)
    reference = resolve_nodes(card.require("ref node"), scope, card, card.location)
    if len(reference) != 1:
        raise card.error(f"REF NODE must be one node, found {len(reference)}")
    elset = card.parameters.get("elset")
    elements = resolve_elements(elset, scope, card, card.location) if elset else np.empty(0, np.int64)
    state.rigid_bodies.append(RigidBody(int(reference[0]), elset, elements, card.location, dict(card.parameters)))


def read_connector_section(card: Card, state: ParseState) -> None:
    scope = state.model_scope(card)
    elset = card.require("elset")
    elements = resolve_elements(elset, scope, card, card.location)
    lines = [[f.strip('"') for f in split_fields(line.text) if f] for line in card.data]
    if not lines or not lines[0]:
        raise card.error("expected the connection type(s) on the first data line")
    state.connector_sections.append(ConnectorSection(
        elset, elements, lines[0], lines[1] if len(lines) > 1 else [], card.location, card.parameters.get("behavior")))


def read_transform(card: Card, state: ParseState) -> None:
    scope = state.model_scope(card)
    nset = card.require("nset")
    nodes = resolve_nodes(nset, scope, card, card.location)
    values = data_values(card, blank=None)
    if len(values) != 6:
        raise card.error(f"expected 6 values (points a and b), found {len(values)}")
    state.transforms.append(Transform(nset, nodes, card.parameters.get("type", "R").upper(), values, card.location))


def read_step(card: Card, state: ParseState) -> None:
    state.model_scope(card)
    if state.step is not None:
        raise card.error(f"step {state.step.name!r} (line {state.step.location.line}) has no *End Step")
    nlgeom = card.parameters.get("nlgeom", "NO").upper() == "YES"
    state.step = Step(card.parameters.get("name", f"Step-{len(state.steps) + 1}"), card.location, nlgeom)
    state.contact = None


def read_end_step(card: Card, state: ParseState) -> None:
    step = _require_step(card, state)
    state.steps.append(step)
    state.step = None
    state.contact = None


def read_procedure(card: Card, state: ParseState) -> None:
    step = _require_step(card, state)
    if step.procedure is not None:
        raise card.error(f"step {step.name!r} already has the procedure *{step.procedure}")
    step.procedure = " ".join([card.keyword, *card.flags])
    step.procedure_data = [parse_float(f, card, line.location) if f else None
                           for line in card.data for f in split_fields(line.text)]


HISTORY_HANDLERS = {
    "amplitude": read_amplitude, "boundary": read_boundary, "dsload": read_dsload, "cload": read_cload,
    "contact pair": read_contact_pair, "contact": read_contact, "contact inclusions": read_contact_inclusions,
    "contact property assignment": read_contact_property_assignment,
    "surface interaction": read_surface_interaction, "friction": read_friction,
    "surface behavior": read_surface_behavior, "mpc": read_mpc, "rigid body": read_rigid_body,
    "connector section": read_connector_section, "transform": read_transform, "step": read_step,
    "end step": read_end_step, "static": read_procedure, "dynamic": read_procedure,
}
