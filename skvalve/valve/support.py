r"""What :func:`~skvalve.valve.model.valve_model` cannot model, found before it builds anything.

An input that uses rigid bodies, connectors, prescribed rotations, local nodal axes, contact with rigid
surfaces, rough or no-separation contact, or more than one step would otherwise be built as a *different*
model (the missing parts skipped), so :func:`check_supported` raises :class:`UnsupportedInputError` listing
every such keyword with its file line. ``partial=True`` builds the chosen step alone when that step itself
uses none of them; model-level parts it does not touch (e.g. parked clip arms) become notes.

The Texas TriValve 1.0 clip repair (``Clipping_QuasiStatic.inp``): what a run needs
-----------------------------------------------------------------------------------
The input adds four rigid clip arms (parts ``Clip-1-1``, ``Clip-1-2``, ``Clip-2-1``, ``Clip-2-2``: 3544
``R3D4`` facets each, ``*Rigid Body`` on reference nodes 1-4) and runs three explicit steps:

1. *Annulus Approximation* (time 1): annulus displacements (``Amp-3``, 0-0.5) and pressure
   0.00567 MPa (``Amp-1``, 0.5-1.0); leaflet self-contact as in the diseased input; clip arms parked (their
   reference nodes held in dofs 1-5 at model level, rotation dof 6 held at 0).
2. *Clip capture* (time 0.5): the pressure is released (``s2_Amp-1``, 1 -> 0) so the valve reopens;
   penalty contact pairs ``Clip-k.Contact_Surf`` / ``Leaflet_Surfaces_Outer`` with ``Rough_Interaction``
   (``*Friction, rough``: no slip; ``*Surface Behavior, no separation``: once touching, bonded) and
   general contact of ``Leaflet_Surfaces_Outer`` with each ``Clip-k.Slide_Surf`` (friction 0.001).
3. *Clip close* (time 1): the arms rotate about their reference nodes, dof 6 in the local axes of
   ``*Transform`` ("Datum csys-k-2"), by +-1.134464 rad (65 deg, clip 1) and +-0.610865 rad (35 deg, clip 2)
   with ``Amp-3`` (0-0.5), then the pressure returns (``Amp-1``, 0.5-1.0). Contact of step 2 persists.

The two ``CONN3D2`` ``Slot`` connectors join the reference nodes of each clip's two arms; since all their
translations are prescribed (held), the slot constraint is inactive and can be dropped with a check.

Missing in skvalve, with an estimate of the work (tests included):

* **Prescribed rigid motion of a surface** (no new unknowns: every reference-node dof is prescribed):
  :math:`x(t) = X_R + R(\theta(t)\,e_3)(X - X_R)`, :math:`e_3` the local 3-axis of the ``*Transform``
  (points a, b: :math:`e_1 = a/|a|`, :math:`e_3 \parallel a \times b`), checked against the rotation of
  a point in closed form. About half a day.
* **Contact of leaflet nodes with a moving rigid surface**: node-to-facet penalty against facets whose
  positions are a function of time (no master dofs, so only slave derivatives; finite-difference tangent
  test), frictionless for the slide surfaces. About a day.
* **Rough, no-separation contact**: a history-dependent bond: a node that touches a ``Contact_Surf`` facet
  is tied by a penalty spring to that material point of the clip from then on (state committed per
  converged step and rewound on cut-back). About one to two days, and the riskiest part for Newton
  (a captured leaflet is dragged by the closing arm; explicit dynamics hid this in mass scaling).
* **Multi-step history**: one load path through the three steps (total time 0-2.5) with amplitudes in
  step time, conditions and loads carried over (``OP=MOD``: a carried condition keeps its end-of-step
  value) or replaced (``OP=NEW``), and contact definitions per step; today :func:`valve_model` builds one
  step and :func:`~skvalve.valve.run.close_valve` follows that step's amplitudes. One to two days.
* Re-opening in step 2 under zero pressure is an unloading path for the quasi-static solver; the damping
  used for closing helps but the open state is then only approximately the step-1 reference.

In all about four to six working days, so the clip column of Tables 2-3 is blocked on these; the
annuloplasty (``*MPC LINK``, :mod:`.links`) and the 1.1 valves need none of them.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from ..io.abaqus import AbaqusModel, Location

__all__ = ["UnsupportedFeature", "UnsupportedInputError", "unsupported_features", "check_supported"]

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


def _rigid_surfaces(abaqus: AbaqusModel) -> set[str]:
    rigid = set()
    for block in abaqus.element_blocks:
        if block.element_type.startswith("R3D"):
            rigid.update(block.indices.tolist())
    return {name for name, surface in abaqus.surfaces.items()
            if any(rigid.intersection(np.asarray(g.elements).tolist()) for g in surface.faces)}


def unsupported_features(abaqus: AbaqusModel) -> list[UnsupportedFeature]:
    """Every unsupported keyword of the input, model level (``step`` None) and per step, in file order."""
    found: list[UnsupportedFeature] = []
    for body in abaqus.rigid_bodies:
        label = int(abaqus.node_labels[body.reference_node])
        found.append(UnsupportedFeature("*Rigid Body", body.location, f"rigid body on {body.elset} "
                                        f"({len(body.elements)} elements, reference node {label})"))
    blocks: dict[tuple[str, Location], list[str]] = defaultdict(list)
    for block in abaqus.element_blocks:
        if block.element_type not in _MODELLED_TYPES:
            blocks[(block.element_type, block.location)].append(block.scope or "assembly")
    for (element_type, location), scopes in blocks.items():
        found.append(UnsupportedFeature(f"*Element, type={element_type}", location,
                                        f"element type not modelled (in {', '.join(scopes)})"))
    for section in abaqus.connector_sections:
        found.append(UnsupportedFeature("*Connector Section", section.location,
                                        f"connector {'/'.join(section.connection_types)} on {section.elset}"))
    modelled = np.unique(np.concatenate([b.connectivity.ravel() for b in abaqus.element_blocks
                                         if b.element_type in _MODELLED_TYPES] or [np.zeros(0, np.int64)]))
    for transform in abaqus.transforms:
        found.append(UnsupportedFeature("*Transform", transform.location,
                                        f"local nodal axes on {transform.nset} (conditions there are in those axes)",
                                        touches_model=bool(np.isin(transform.nodes, modelled).any())))
    rigid = _rigid_surfaces(abaqus)
    found += _condition_features(abaqus.boundary_conditions, None)
    for k, step in enumerate(abaqus.steps):
        if k > 0:
            found.append(UnsupportedFeature("*Step", step.location, f"step {k + 1} {step.name!r}: one step is "
                                            "modelled at a time (multi-step history)", k))
        found += _condition_features(step.boundary_conditions, k)
        used_interactions = set()
        for pair in step.contact_pairs:
            used_interactions.add(pair.interaction.upper())
            on_rigid = [s for s in pair.surfaces if s.upper() in rigid]
            if on_rigid:
                found.append(UnsupportedFeature("*Contact Pair", pair.location, f"contact with the rigid surface(s) "
                                                f"{', '.join(on_rigid)}", k))
        contact = step.general_contact
        if contact is not None:
            on_rigid = sorted({s for item in contact.inclusions for s in item if s.upper() in rigid})
            if on_rigid:
                found.append(UnsupportedFeature("*Contact Inclusions", contact.location,
                                                f"general contact with the rigid surface(s) {', '.join(on_rigid)}", k))
            used_interactions.update(p[2].upper() for p in contact.property_assignments if len(p) > 2)
        for name in sorted(used_interactions):
            interaction = abaqus.interactions.get(name)
            if interaction is not None and (interaction.rough or interaction.no_separation):
                kinds = [label for label, on in (("*Friction, rough", interaction.rough),
                                                 ("*Surface Behavior, no separation", interaction.no_separation)) if on]
                found.append(UnsupportedFeature("*Surface Interaction", interaction.location,
                                                f"{interaction.name}: {' and '.join(kinds)} (bonded contact)", k))
    return sorted(found, key=lambda f: (str(f.location.file), f.location.line))


def _condition_features(conditions, step: int | None) -> list[UnsupportedFeature]:
    """Prescribed non-zero rotations (dofs 4-6): a rotation of a rigid body or of a shell node."""
    return [UnsupportedFeature("*Boundary", bc.location, f"rotation dof {bc.first_dof}-{bc.last_dof} = {bc.value:g} "
                               f"on {bc.target}", step, touches_model=step is None)
            for bc in conditions if bc.last_dof > 3 and bc.value != 0.0]


def check_supported(abaqus: AbaqusModel, step: int = 0, partial: bool = False) -> list[str]:
    """Raise :class:`UnsupportedInputError` listing what the model cannot represent.

    ``partial``: only what step ``step`` itself uses is refused (its contact, interactions, rotations; a step
    after the first, which starts from the end of the earlier ones), and
    model-level rotations and local axes on leaflet or chordae nodes; the other model-level keywords and the
    other steps are returned as notes instead (the step is then modelled alone,
    with the rigid parts inert, as Abaqus would treat parts that no condition or contact of the step touches).
    """
    features = unsupported_features(abaqus)
    if not partial:
        if features:
            raise UnsupportedInputError(abaqus.path, features)
        return []
    refused = [f for f in features if f.step == step or f.touches_model]  # a later step needs the earlier ones
    if refused:
        raise UnsupportedInputError(abaqus.path, refused)
    return [f"not modelled (partial build of step {step}): {f}" for f in features]
