r"""What :func:`~skvalve.valve.model.valve_model` cannot model, found before it builds anything.

An input that uses parts the model cannot represent would otherwise be built as a *different* model (the missing
parts skipped), so :func:`check_supported` raises :class:`UnsupportedInputError` listing every such keyword with
its file line. ``partial=True`` builds one chosen step alone when that step itself uses none of them; model-level
parts it does not touch become notes. Parts modelled only approximately are accepted and described in the notes
:func:`check_supported` returns (they end up in ``ValveModel.notes``).

Modelled
--------
* **Several steps** (:mod:`.history`): one load path over the total time, amplitudes in step time, conditions and
  loads carried (``OP=MOD``) or released (``OP=NEW``); the steps' start times and names are on the model.
* **Rigid clip arms** (:mod:`.clip`): ``*Rigid Body`` of ``R3D4`` facets whose reference node is held in dofs 1-5
  at zero in every step and turned in dof 6 about the local 3-axis of its ``*Transform`` become kinematic
  obstacles of the IPC contact (no unknowns). The ``*Transform`` on such reference nodes and their rotation
  ``*Boundary`` lines are thereby modelled.
* **Inert connectors**: ``CONN3D2`` of translational types (``Slot``, ...) between nodes held in dofs 1-3 cannot act
  and are dropped.
* **Contact with the arms** (``*Contact Pair`` / ``*Contact Inclusions`` with an arm surface): the arms' whole facet
  surface is an obstacle of the IPC barrier, from the total time the arm starts to turn
  (:class:`~skvalve.fem.contact.obstacles.Obstacle` ``active_from``).

Approximated (a note on the model)
----------------------------------
* ``*Friction, rough`` and ``*Surface Behavior, no separation`` between the arms and the leaflets (the clip's
  ``Rough_Interaction``: once touching, bonded): the IPC barrier plus a tie after capture
  (:class:`~skvalve.fem.contact.tie.ObstacleTie`): a leaflet vertex within ``ContactOptions.tie_within`` of an arm
  at an accepted step is held by a stiff spring to that material point of the arm from then on. Captures are decided
  per accepted step, not at the instant of first touch, and the bond is elastic (stiffness
  :data:`~skvalve.valve.setup.TIE_FACTOR` times the peak pressure over ``dhat``), not rigid.
* Contact with an arm starts when it starts to turn (the start of *Clip close*), not with the step that defines it
  (*Clip capture*): the leaflets closed in the step before overlap the parked arms, which the barrier cannot start
  from; the capture step's released pressure reopens the valve first.

Still refused, with the file line
---------------------------------
Rigid bodies of other element types, free rigid bodies (a reference-node dof not prescribed in some step), a
nonzero reference-node translation or a rotation about its local 1- or 2-axis; connectors that could act (a
rotational connection type, or an end node not held in dofs 1-3); ``*Transform`` on other nodes; nonzero rotations
on other nodes; contact or bonded interactions with rigid surfaces that are not modelled arms; and a dof of a
leaflet or chordae node that is prescribed in some steps only (``OP=NEW`` releasing it, or a condition first
defined after the first step): the prescribed dofs of the implicit model are the same in every step.

The Texas TriValve 1.0 clip repair (``Clipping_QuasiStatic.inp``)
-----------------------------------------------------------------
Four rigid clip arms (parts ``Clip-1-1``, ``Clip-1-2``, ``Clip-2-1``, ``Clip-2-2``: 3544 ``R3D4`` facets each,
``*Rigid Body`` on reference nodes 1-4), three explicit steps (total time 0-2.5):

1. *Annulus Approximation* (time 1): annulus displacements (``Amp-3``, 0-0.5) and pressure 0.00567 MPa (``Amp-1``,
   0.5-1.0); leaflet self-contact; clip arms parked (reference nodes held in dofs 1-5 at model level, rotation dof 6
   held at 0).
2. *Clip capture* (time 0.5): the pressure is released (``s2_Amp-1``, 1 -> 0) so the valve reopens; penalty contact
   pairs ``Clip-k.Contact_Surf`` / ``Leaflet_Surfaces_Outer`` with ``Rough_Interaction`` and general contact of
   ``Leaflet_Surfaces_Outer`` with each ``Clip-k.Slide_Surf`` (friction 0.001).
3. *Clip close* (time 1): the arms turn about their reference nodes, dof 6 in the local axes of ``*Transform``
   ("Datum csys-k-2"), by +-1.134464 rad (65 deg, clip 1) and +-0.610865 rad (35 deg, clip 2) with ``Amp-3``
   (0-0.5), then the pressure returns (``Amp-1``, 0.5-1.0).

The two ``Slot`` connectors join the reference nodes of each clip's two arms, all of whose translations are held:
inert. All of this is modelled; the bonded (rough, no-separation) contact is approximated as above.
Re-opening in step 2 under zero pressure is an unloading path for the quasi-static solver; the damping used for
closing helps, but the open state is then only approximately the step-1 reference.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from ..io.abaqus import AbaqusModel, Location
from .clip import connector_issues, rigid_body_issues
from .history import History, amplitude_table, condition_histories, selected_steps, step_windows

__all__ = ["UnsupportedFeature", "UnsupportedInputError", "unsupported_features", "approximation_notes",
           "check_supported"]

_MODELLED_TYPES = ("C3D8", "C3D8R", "C3D8H", "C3D8RH", "C3D8I", "S4", "S4R", "S4R5", "T3D2", "T3D2H")


@dataclass(frozen=True)
class UnsupportedFeature:
    """One keyword the model cannot represent: as written, where, and why it matters."""

    keyword: str
    location: Location
    reason: str
    step: int | None = None  # None: model level
    touches_model: bool = False  # acts on leaflet or chordae nodes in every step

    def __str__(self) -> str:
        return f"{self.location}: {self.keyword}: {self.reason}"


class UnsupportedInputError(ValueError):
    """The input uses keywords that the valve model cannot represent (``features``, each with its file line)."""

    def __init__(self, path, features: list[UnsupportedFeature]) -> None:
        self.features = features
        lines = "\n  ".join(str(f) for f in features)
        super().__init__(f"{path}: {len(features)} keyword(s) the valve model cannot represent (building it would "
                         f"give a different model; see skvalve.valve.support):\n  {lines}")


@dataclass
class _Modelled:
    """What the input's rigid parts come to: arm elements, arm reference nodes, inert connector elements."""

    arm_elements: set[int]
    reference_nodes: set[int]
    connector_elements: set[int]
    features: list[UnsupportedFeature]


def _histories(abaqus: AbaqusModel, step: int | None) -> dict[tuple[int, int], History]:
    steps = selected_steps(abaqus, step)
    amplitudes, total = amplitude_table(abaqus)
    return condition_histories(abaqus, steps, step_windows(steps), amplitudes, total)


def _rigid_parts(abaqus: AbaqusModel, histories: dict[tuple[int, int], History]) -> _Modelled:
    out = _Modelled(set(), set(), set(), [])
    for body, issues in zip(abaqus.rigid_bodies, rigid_body_issues(abaqus, histories), strict=True):
        out.features += [UnsupportedFeature(i.keyword, i.location, i.reason) for i in issues]
        if not issues:
            out.arm_elements.update(np.asarray(body.elements).tolist())
            out.reference_nodes.add(int(body.reference_node))
    for section, issues in zip(abaqus.connector_sections, connector_issues(abaqus, histories), strict=True):
        out.features += [UnsupportedFeature(i.keyword, i.location, i.reason) for i in issues]
        if not issues:
            out.connector_elements.update(np.asarray(section.elements).tolist())
    return out


def _rigid_surfaces(abaqus: AbaqusModel, arm_elements: set[int]) -> tuple[set[str], set[str]]:
    """Names (upper case) of the surfaces on rigid elements, and of those entirely on modelled arms."""
    rigid = set()
    for block in abaqus.element_blocks:
        if block.element_type.startswith("R3D"):
            rigid.update(block.indices.tolist())
    on_rigid, on_arms = set(), set()
    for name, surface in abaqus.surfaces.items():
        elements = set(np.concatenate([np.asarray(g.elements) for g in surface.faces]).tolist()) if surface.faces \
            else set()
        if elements & rigid:
            on_rigid.add(name.upper())
            if elements <= arm_elements:
                on_arms.add(name.upper())
    return on_rigid, on_arms


def _interaction_uses(step, on_arms: set[str]) -> list[tuple[str, bool, Location]]:
    """(interaction, used with a modelled arm surface, where) for each contact definition of the step."""
    uses = [(pair.interaction.upper(), any(s.upper() in on_arms for s in pair.surfaces), pair.location)
            for pair in step.contact_pairs]
    contact = step.general_contact
    if contact is not None:
        uses += [(p[2].upper(), any(s.strip().upper() in on_arms for s in p[:2]), contact.location)
                 for p in contact.property_assignments if len(p) > 2]
    return uses


def unsupported_features(abaqus: AbaqusModel, step: int | None = None) -> list[UnsupportedFeature]:
    """Every keyword of the input (all steps, or step ``step`` alone) that the model cannot represent, model level
    (``step`` None) and per step, in file order."""
    histories = _histories(abaqus, step)
    parts = _rigid_parts(abaqus, histories)
    found = list(parts.features)
    blocks: dict[tuple[str, Location], list[str]] = defaultdict(list)
    for block in abaqus.element_blocks:
        if block.element_type in _MODELLED_TYPES:
            continue
        accepted = parts.arm_elements if block.element_type.startswith("R3D") else \
            parts.connector_elements if block.element_type.startswith("CONN") else set()
        if not set(block.indices.tolist()) <= accepted:
            blocks[(block.element_type, block.location)].append(block.scope or "assembly")
    for (element_type, location), scopes in blocks.items():
        found.append(UnsupportedFeature(f"*Element, type={element_type}", location,
                                        f"element type not modelled (in {', '.join(scopes)})"))
    modelled = np.unique(np.concatenate([b.connectivity.ravel() for b in abaqus.element_blocks
                                         if b.element_type in _MODELLED_TYPES] or [np.zeros(0, np.int64)]))
    for transform in abaqus.transforms:
        if set(np.asarray(transform.nodes).tolist()) <= parts.reference_nodes:
            continue  # the axes of a clip arm's rotation
        found.append(UnsupportedFeature("*Transform", transform.location,
                                        f"local nodal axes on {transform.nset} (conditions there are in those axes)",
                                        touches_model=bool(np.isin(transform.nodes, modelled).any())))
    on_rigid, on_arms = _rigid_surfaces(abaqus, parts.arm_elements)
    index = {id(s): k for k, s in enumerate(abaqus.steps)}
    steps = selected_steps(abaqus, step)
    found += _condition_features(abaqus.boundary_conditions, None, parts.reference_nodes)
    found += _changing_dofs(histories, modelled, [index[id(s)] for s in steps])
    for s in steps:
        k = index[id(s)]
        found += _condition_features(s.boundary_conditions, k, parts.reference_nodes)
        for pair in s.contact_pairs:
            others = [name for name in pair.surfaces if name.upper() in on_rigid and name.upper() not in on_arms]
            if others:
                found.append(UnsupportedFeature("*Contact Pair", pair.location, f"contact with the rigid surface(s) "
                                                f"{', '.join(others)}", k))
        contact = s.general_contact
        if contact is not None:
            others = sorted({name for item in contact.inclusions for name in item
                             if name.upper() in on_rigid and name.upper() not in on_arms})
            if others:
                found.append(UnsupportedFeature("*Contact Inclusions", contact.location,
                                                f"general contact with the rigid surface(s) {', '.join(others)}", k))
        for name in sorted({name for name, with_arm, _ in _interaction_uses(s, on_arms) if not with_arm}):
            interaction = abaqus.interactions.get(name)
            if interaction is not None and (interaction.rough or interaction.no_separation):
                found.append(UnsupportedFeature("*Surface Interaction", interaction.location,
                                                f"{interaction.name}: {_bond(interaction)} (bonded contact)", k))
    return sorted(found, key=lambda f: (str(f.location.file), f.location.line))


def _bond(interaction) -> str:
    return " and ".join(label for label, on in (("*Friction, rough", interaction.rough),
                                                ("*Surface Behavior, no separation", interaction.no_separation)) if on)


def _condition_features(conditions, step: int | None, reference_nodes: set[int]) -> list[UnsupportedFeature]:
    """Prescribed non-zero rotations (dofs 4-6) on nodes other than clip-arm reference nodes."""
    return [UnsupportedFeature("*Boundary", bc.location, f"rotation dof {bc.first_dof}-{bc.last_dof} = {bc.value:g} "
                               f"on {bc.target}", step, touches_model=step is None)
            for bc in conditions if bc.last_dof > 3 and bc.value != 0.0
            and not set(np.asarray(bc.nodes).tolist()) <= reference_nodes]


def _changing_dofs(histories: dict[tuple[int, int], History], modelled: np.ndarray,
                   step_index: list[int]) -> list[UnsupportedFeature]:
    """Translation dofs of mesh nodes prescribed in some steps only, one feature per line that adds or releases."""
    mesh = set(modelled.tolist())
    by_line: dict[Location, list] = defaultdict(list)
    for (node, dof), history in histories.items():
        where = history.changes_at()
        if dof <= 3 and node in mesh and where is not None:
            k = next(k for k in range(1, len(history.segments))
                     if (history.segments[k - 1] is None) != (history.segments[k] is None))
            by_line[where].append((node, dof, step_index[k], history.segments[k] is None))
    found = []
    for where, items in by_line.items():
        released = sum(1 for item in items if item[3])
        found.append(UnsupportedFeature("*Boundary", where, f"{len(items)} node dof(s) prescribed in some steps only "
                                        f"({released} released, {len(items) - released} added after the first step): "
                                        "the prescribed dofs change between steps", items[0][2], touches_model=True))
    return found


def approximation_notes(abaqus: AbaqusModel, step: int | None = None) -> list[str]:
    """What the model represents only approximately (module docstring): bonded contact with the clip arms as the
    barrier with a tie after capture, and arm contact that starts when the arm starts to turn, not with its step."""
    parts = _rigid_parts(abaqus, _histories(abaqus, step))
    if not parts.arm_elements:
        return []
    _, on_arms = _rigid_surfaces(abaqus, parts.arm_elements)
    notes, first = [], None
    for k, s in enumerate(selected_steps(abaqus, step)):
        for name, with_arm, where in _interaction_uses(s, on_arms):
            if not with_arm:
                continue
            first = (k, s.name, where) if first is None else first
            interaction = abaqus.interactions.get(name)
            if interaction is not None and (interaction.rough or interaction.no_separation):
                note = (f"{interaction.location}: {interaction.name} ({_bond(interaction)}) between the clip arms and "
                        "the leaflets is modelled as the IPC barrier with a tie after capture: a leaflet vertex that "
                        "touches an arm at an accepted step is held to its point on the arm by a stiff spring "
                        "(ContactOptions.tie_within)")
                if note not in notes:
                    notes.append(note)
    if first is not None and first[0] > 0:
        notes.append(f"{first[2]}: contact with the clip arms starts in step {first[0] + 1} ({first[1]!r}) in the "
                     "input; the IPC barrier takes each arm in from when it starts to turn")
    return notes


def check_supported(abaqus: AbaqusModel, step: int | None = None, partial: bool = False) -> list[str]:
    """Raise :class:`UnsupportedInputError` listing what the model cannot represent; return the notes of what it
    represents only approximately (:func:`approximation_notes`).

    ``step``: None models all steps; an index models that step alone (``partial`` with None: the first step).
    ``partial``: only what step ``step`` itself uses is refused (its contact, interactions, rotations; a step
    after the first, which starts from the end of the earlier ones), and model-level rotations, local axes and
    step-dependent conditions on leaflet or chordae nodes; the other model-level keywords and the other steps are
    returned as notes instead (the step is then modelled alone, with the rigid parts that it cannot represent inert,
    as Abaqus would treat parts that no condition or contact of the step touches).
    """
    if partial and step is None:
        step = 0
    features = unsupported_features(abaqus, step)
    if not partial:
        if features:
            raise UnsupportedInputError(abaqus.path, features)
        return approximation_notes(abaqus, step)
    refused = [f for f in features if f.step == step or f.touches_model]  # a later step needs the earlier ones
    if refused:
        raise UnsupportedInputError(abaqus.path, refused)
    notes = [f"not modelled (partial build of step {step}): {f}" for f in features]
    return notes + approximation_notes(abaqus, step)
