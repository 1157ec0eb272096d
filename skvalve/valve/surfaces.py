r"""Contact surfaces of an Abaqus input on the hexahedra of a :class:`~skvalve.valve.model.ValveModel`.

An element-face surface of the input (``*Surface, type=ELEMENT``) becomes quadrilateral faces of the model's
mesh, oriented away from the hex that owns them (:class:`~skvalve.fem.contact.ContactSurface`):

* **bricks** (C3D8/C3D8R, the 1.0 inputs): face ``Sk`` of the element is face ``Sk`` of its hex
  (:data:`~skvalve.io.abaqus.HEX_FACE_NODES`);
* **extruded shells** (S4/S4R, the 1.1 inputs; :mod:`.extrude`): a shell element becomes a *stack* of
  ``layers`` hexes through its thickness, hex ``k`` between node layers ``k`` and ``k + 1`` (layer 0 on the
  ``SNEG`` side). ``SPOS`` is face ``S2`` (corners 5–8) of the top hex, ``SNEG`` face ``S1`` (corners 1–4)
  of the bottom hex.

**Shell surfaces are double-sided by default.** Abaqus/Explicit's general contact, and self-contact in its
contact-pair algorithm, act on both sides of every shell facet and on the free edges of the surface even when
the surface names one side only (Abaqus/CAE User's Guide, "Defining contact surfaces on structural elements").
The 1.1 inputs rely on it: their one surface ``LEAFLET_SURFACES`` is the ``SPOS`` (ventricular, pressure-loaded)
side, while the leaflets coapt on their atrial (``SNEG``) sides, as the 1.0 inputs state explicitly (pressure on
``Leaflet_Surfaces_Outer``, contact on ``Leaflet_Surfaces_Inner`` and the rim). So ``double_sided=True`` maps a
shell face to **both skins** of its stack plus the **rim**: every edge of the surface's quad mesh used by only
one of its shells is a free edge, and shell edge :math:`j` (nodes :math:`j \to j+1`, :math:`j = 0..3`) is hex
face ``S(j+3)`` of each hex of the stack (``S3`` = corners 1-2-6-5, ..., ``S6`` = 4-1-5-8), the stack's side
wall; this is the shell counterpart of the 1.0 bricks' ``LEAFLET_RIM_TIP``. The reader accepts no element-based
edge faces on shells (Abaqus names them only for edge loads), so a rim-tip surface of a shell input would reach
this module as ``SPOS``/``SNEG`` faces and get its rim from the same rule. ``double_sided=False`` keeps the
side written in the input.

**Both skins and the penetration depth.** The two skins of one stack lie a shell thickness :math:`h` apart
with opposing normals, so a node of one skin looks like a node that has passed through the other by :math:`h`.
:class:`~skvalve.fem.contact.SurfaceContact` ignores passes deeper than ``max_penetration``; with
double-sided shells it must be below the current thickness of the thinnest stack
(:func:`thinnest_stack` gives the reference one; the leaflets thin as they stretch, hence a fraction such as
:math:`h/4`). A node that passes through a skin by more than that is caught by the other skin.

Vertices are the model's own (a face is taken from the model's hexes, found through
``ValveModel.element_source``); faces that two surfaces share are kept once.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from ..fem.contact import ContactSurface
from ..io.abaqus import HEX_FACE_NODES, AbaqusModel
from ..io.abaqus.elements import is_shell_like
from .model import ABAQUS_TO_SKFEM_HEX, ValveModel

__all__ = ["CONTACT_SURFACES_1_0", "SHELL_EDGE_HEX_FACE", "contact_surface", "contact_surface_names",
           "shell_stacks", "thinnest_stack"]

#: The contact surfaces of the Texas TriValve 1.0 inputs (inner leaflet faces and the rim tips).
CONTACT_SURFACES_1_0 = ("LEAFLET_SURFACES_INNER", "LEAFLET_RIM_TIP")
#: Hex face (Abaqus C3D8 labels) over shell edge ``j`` (shell nodes ``j`` -> ``j + 1``) in an extruded stack.
SHELL_EDGE_HEX_FACE = ("S3", "S4", "S5", "S6")
_ABAQUS_FROM_SKFEM = np.argsort(ABAQUS_TO_SKFEM_HEX)
_BRICK_NODES = 8


def contact_surface_names(abaqus: AbaqusModel, step: int = 0) -> tuple[str, ...]:
    """The surfaces that the input puts in contact (model-level and step ``step``'s contact pairs and
    general-contact inclusions), in order of first appearance. Raises ``ValueError`` if there are none or
    if general contact includes "all exterior faces" (no named surface to map)."""
    pairs = list(abaqus.contact_pairs)
    inclusions: list[tuple[str, ...]] = []
    if abaqus.steps:
        chosen = abaqus.steps[step]
        pairs += chosen.contact_pairs
        if chosen.general_contact is not None:
            inclusions = chosen.general_contact.inclusions
            if any(len(item) == 0 for item in inclusions):
                raise ValueError(f"{chosen.general_contact.location}: general contact includes all exterior faces; "
                                 "name the contact surfaces explicitly")
    names: dict[str, str] = {}
    for group in [pair.surfaces for pair in pairs] + inclusions:
        for name in group:
            names.setdefault(name.strip().upper(), name.strip())
    if not names:
        raise ValueError(f"{abaqus.path}: no contact surfaces in the input (no *Contact Pair or *Contact Inclusions)")
    return tuple(names.values())


def shell_stacks(model: ValveModel) -> dict[int, np.ndarray]:
    """Global element index -> its hexes in the model, bottom (``SNEG`` side) first.

    A brick has a stack of one. Raises ``ValueError`` if a stack's hexes do not sit on top of one another
    (the top face of hex ``k`` is the bottom face of hex ``k + 1``).
    """
    order = np.argsort(model.element_source, kind="stable")
    sources = model.element_source[order]
    starts = np.flatnonzero(np.r_[True, sources[1:] != sources[:-1]])
    stacks = dict(zip(sources[starts].tolist(), np.split(order, starts[1:]), strict=True))
    corners = model.mesh.t.T[:, _ABAQUS_FROM_SKFEM]
    lower = np.concatenate([s[:-1] for s in stacks.values()]).astype(np.int64)
    upper = np.concatenate([s[1:] for s in stacks.values()]).astype(np.int64)
    bad = np.flatnonzero(np.any(corners[lower, 4:] != corners[upper, :4], axis=1))
    if bad.size:
        raise ValueError(f"hexes {lower[bad][:10].tolist()} and {upper[bad][:10].tolist()} come from one element but "
                         "are not stacked (not an extrusion of the model builder)")
    return stacks


def thinnest_stack(model: ValveModel, abaqus: AbaqusModel) -> float | None:
    """Smallest reference distance between the two skins (face centroids) of an extruded shell stack;
    ``None`` for a model without shells."""
    types = _element_types(abaqus)
    corners = model.mesh.t.T[:, _ABAQUS_FROM_SKFEM]
    X = model.mesh.p.T
    thickness = [np.linalg.norm(X[corners[s[-1], 4:]].mean(axis=0) - X[corners[s[0], :4]].mean(axis=0))
                 for e, s in shell_stacks(model).items() if is_shell_like(types[e][0])]
    return float(min(thickness)) if thickness else None


def contact_surface(abaqus: AbaqusModel, model: ValveModel, names=None, *, double_sided: bool = True,
                    step: int = 0) -> ContactSurface:
    """The union of the named element-face surfaces as a :class:`ContactSurface` on the model's vertices.

    ``names``: surface names (default: :func:`contact_surface_names` of step ``step``). Bricks: faces S1–S6;
    extruded shells: ``SPOS``/``SNEG`` on the stack's outer skins, and with ``double_sided`` both skins and the
    rim (module docstring). Faces are oriented away from their hex. Raises ``ValueError`` naming the surface
    and element label for an element the model does not hold or a face that does not exist on it.
    """
    names = contact_surface_names(abaqus, step) if names is None else tuple(names)
    types = _element_types(abaqus)
    stacks = shell_stacks(model)
    corners = model.mesh.t.T[:, _ABAQUS_FROM_SKFEM]
    faces: list[np.ndarray] = []
    owners: list[np.ndarray] = []
    shells: list[int] = []
    for name in names:
        surface = abaqus.surface(name)
        for group in surface.faces:
            face = group.face.upper()
            for element in np.asarray(group.elements, dtype=np.int64).tolist():
                element_type, label = types.get(element, ("?", element))
                stack = stacks.get(element)
                if stack is None:
                    raise ValueError(f"contact surface {name!r}: element {label} ({element_type}) is not part of "
                                     "the model's mesh")
                if is_shell_like(element_type):
                    sides = ("SPOS", "SNEG") if double_sided else (face,)
                    if face not in ("SPOS", "SNEG"):
                        raise ValueError(f"contact surface {name!r}: face {face} of shell element {label}; shells "
                                         "have SPOS and SNEG")
                    for side in sides:
                        hexes, local = (stack[-1:], "S2") if side == "SPOS" else (stack[:1], "S1")
                        faces.append(corners[hexes][:, list(HEX_FACE_NODES[local])])
                        owners.append(hexes)
                    shells.append(element)
                elif face in HEX_FACE_NODES and stack.size == 1:
                    faces.append(corners[stack][:, list(HEX_FACE_NODES[face])])
                    owners.append(stack)
                else:
                    raise ValueError(f"contact surface {name!r}: face {face} of element {label} ({element_type}) "
                                     "is not a brick face S1..S6 or a shell face SPOS/SNEG")
    if double_sided and shells:
        rim, rim_owner = _rim_faces(abaqus, np.unique(shells), stacks, corners)
        faces.append(rim)
        owners.append(rim_owner)
    quads = np.vstack(faces) if faces else np.zeros((0, 4), dtype=np.int64)
    owner = np.concatenate(owners) if owners else np.zeros(0, dtype=np.int64)
    _, first = np.unique(np.sort(quads, axis=1), axis=0, return_index=True)
    first = np.sort(first)
    X = model.mesh.p.T
    inside = X[corners[owner[first]]].mean(axis=1)
    return ContactSurface.from_quads(X, quads[first], inside)


def _rim_faces(abaqus: AbaqusModel, shells: np.ndarray, stacks: dict[int, np.ndarray], corners: np.ndarray):
    """Side faces of the stacks along the free edges of the shells' quad mesh (edges used by one shell)."""
    connectivity = _element_connectivity(abaqus, shells)
    edges = np.stack([connectivity, np.roll(connectivity, -1, axis=1)], axis=2)  # (n, 4, 2) shell edge j: j -> j+1
    keys = [tuple(sorted(pair)) for pair in edges.reshape(-1, 2).tolist()]
    uses = Counter(keys)
    free = np.array([uses[key] == 1 for key in keys]).reshape(-1, 4)
    faces, owners = [], []
    for row, edge in zip(*np.nonzero(free), strict=True):
        stack = stacks[int(shells[row])]
        faces.append(corners[stack][:, list(HEX_FACE_NODES[SHELL_EDGE_HEX_FACE[edge]])])
        owners.append(stack)
    if not faces:
        return np.zeros((0, 4), dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.vstack(faces), np.concatenate(owners)


def _element_types(abaqus: AbaqusModel) -> dict[int, tuple[str, int]]:
    """Global element index -> (element type, label)."""
    out: dict[int, tuple[str, int]] = {}
    for block in abaqus.element_blocks:
        for index, label in zip(block.indices.tolist(), block.labels.tolist(), strict=True):
            out[index] = (block.element_type, label)
    return out


def _element_connectivity(abaqus: AbaqusModel, elements: np.ndarray) -> np.ndarray:
    """Connectivity rows (global node indices) of the given global element indices (last definition wins)."""
    rows: dict[int, np.ndarray] = {}
    for block in abaqus.element_blocks:
        for index, row in zip(block.indices.tolist(), block.connectivity, strict=True):
            rows[index] = row
    return np.array([rows[int(e)][:4] for e in elements], dtype=np.int64)
