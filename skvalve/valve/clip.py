r"""Rigid clip arms as kinematic obstacles (the Texas TriValve 1.0 clip repair, ``Clipping_QuasiStatic.inp``).

Each ``*Rigid Body`` of ``R3D4`` facets whose reference node :math:`c` has all six dofs prescribed in every step
becomes an :class:`~skvalve.fem.contact.obstacles.Obstacle` with prescribed motion and no unknowns:

.. math::

    x(t) = c + R\big(\theta(t)\,e_3\big)(X - c), \qquad
    R(\theta e) = I + \sin\theta\,[e]_\times + (1 - \cos\theta)\,[e]_\times^2 \quad\text{(Rodrigues)},

with :math:`X` the facet nodes as placed by their ``*Instance`` (translation, then rotation about the axis through
:math:`a`, :math:`b`: :mod:`skvalve.io.abaqus.mesh`), :math:`\theta(t)` the reference node's dof 6 at total time
(:mod:`.history`), and :math:`e_3` the local 3-axis of the ``*Transform`` (``TYPE=R``) that holds the reference
node: Abaqus gives a point :math:`a` on the local 1-axis and a point :math:`b` in the local 1-2 plane, origin at the
global origin, so

.. math::

    e_1 = \frac{a}{|a|}, \qquad e_2 = \frac{b - (b\cdot e_1)e_1}{|b - (b\cdot e_1)e_1|}, \qquad e_3 = e_1\times e_2
    \;\parallel\; a\times b

(the global axes without a ``*Transform``). The directions of a nodal transform stay fixed in space, so the arm turns
about a fixed axis. Dofs 1-5 of the reference node must be held at zero in every step (no translation, no rotation
about the local 1- and 2-axes); anything else is reported by :func:`rigid_body_issues` with its file line.

The whole facet surface of an arm is used (each quad split into two triangles): the IPC barrier acts on distances and
does not care which side a facet faces, and on the shipped input the arms' ``Contact_Surf`` and ``Slide_Surf`` are
the two halves of the same 3544 facets.

``CONN3D2`` connectors of translational types (``Slot``, ...) whose end nodes are held in dofs 1-3 at zero in every
step cannot act (the relative motion they constrain is zero) and are dropped (:func:`connector_issues`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fem.contact.obstacles import Obstacle
from ..io.abaqus import AbaqusModel, Location, Transform
from .history import History, StepWindow

__all__ = ["ClipArm", "ClipIssue", "rodrigues", "transform_axes", "rigid_body_issues", "connector_issues",
           "clip_arms", "INERT_CONNECTIONS"]

#: Connection types that constrain relative translation only: inert between two nodes that do not translate.
INERT_CONNECTIONS = ("SLOT", "CARTESIAN", "AXIAL", "LINK", "JOIN")
_ARM_TYPES = ("R3D4",)
_UNMODELLED_BODY_OPTIONS = ("PIN NSET", "TIE NSET", "ANALYTICAL SURFACE", "ISOTHERMAL")


@dataclass(frozen=True)
class ClipIssue:
    """Why a rigid body or connector is not modelled: the keyword, its file line and the reason."""

    keyword: str
    location: Location
    reason: str


def rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    r"""The rotation :math:`R = I + \sin\theta\,K + (1 - \cos\theta)K^2`, :math:`K = [e]_\times`, by ``angle``
    :math:`\theta` (rad) about the unit vector :math:`e` along ``axis``."""
    e = np.asarray(axis, dtype=float)
    e = e / np.linalg.norm(e)
    K = np.array([[0.0, -e[2], e[1]], [e[2], 0.0, -e[0]], [-e[1], e[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def transform_axes(transform: Transform) -> np.ndarray:
    r"""The local axes (rows :math:`e_1, e_2, e_3`) of a rectangular ``*Transform`` (module docstring)."""
    a, b = np.asarray(transform.data[:3], dtype=float), np.asarray(transform.data[3:6], dtype=float)
    if transform.transform_type != "R":
        raise ValueError(f"{transform.location}: *Transform TYPE={transform.transform_type}: only rectangular (R) "
                         "local axes are modelled")
    normal = np.cross(a, b)
    if not (np.linalg.norm(a) > 0.0 and np.linalg.norm(normal) > 1e-12 * np.linalg.norm(a) * np.linalg.norm(b)):
        raise ValueError(f"{transform.location}: *Transform points a and b do not span a plane with the origin")
    e1 = a / np.linalg.norm(a)
    e2 = b - (b @ e1) * e1
    e2 /= np.linalg.norm(e2)
    return np.array([e1, e2, np.cross(e1, e2)])


@dataclass
class ClipArm:
    """One rigid arm: its facets (``vertices``, ``triangles``), reference node ``centre``, ``axis`` and angle."""

    name: str
    reference_node: int
    centre: np.ndarray
    axis: np.ndarray
    vertices: np.ndarray
    triangles: np.ndarray
    angle: History
    location: Location

    def rotation(self, t: float) -> np.ndarray:
        r""":math:`R(\theta(t)\,e_3)` at total time ``t``."""
        return rodrigues(self.axis, self.angle.at(t))

    def at(self, t: float) -> np.ndarray:
        """Vertex positions (n, 3) at total time ``t``."""
        return self.centre + (self.vertices - self.centre) @ self.rotation(t).T

    def turns_from(self, windows: list[StepWindow]) -> float:
        """The start (total time) of the first step in which the arm turns; the last step's end if it never does."""
        for window in windows:
            if self.angle.at(window.start) != self.angle.at(window.end):
                return window.start
        return windows[-1].end

    def obstacle(self, active_from: float = 0.0) -> Obstacle:
        """The arm as an :class:`Obstacle` turning about its reference node, no translation, in contact from total
        time ``active_from``."""
        return Obstacle.rigid(self.vertices, self.triangles, _no_translation, self.rotation, self.centre, self.name,
                              active_from)


def _no_translation(t: float) -> np.ndarray:
    return np.zeros(3)


def _label(abaqus: AbaqusModel, node: int) -> str:
    scope = abaqus.scopes[int(abaqus.node_scopes[node])]
    return f"{scope + '.' if scope else ''}{int(abaqus.node_labels[node])}"


def _element_rows(abaqus: AbaqusModel, elements: np.ndarray) -> tuple[list[str], np.ndarray, list[str]]:
    """Element types, the first four nodes of each (-1 padded) and the scopes of global ``elements``."""
    elements = np.asarray(elements, dtype=np.int64)
    rows = np.full((elements.size, 4), -1, dtype=np.int64)
    types = np.full(elements.size, "", dtype=object)
    scopes = np.full(elements.size, "", dtype=object)
    for block in abaqus.element_blocks:
        hit = (elements >= block.offset) & (elements < block.offset + len(block.labels))
        if np.any(hit):
            conn = np.asarray(block.connectivity)[elements[hit] - block.offset]
            k = min(conn.shape[1], 4)
            rows[np.flatnonzero(hit)[:, None], np.arange(k)] = conn[:, :k]
            types[hit], scopes[hit] = block.element_type, block.scope
    return types.tolist(), rows, scopes.tolist()


def _not_held(histories: dict[tuple[int, int], History], node: int,
              dofs: range) -> list[tuple[int, bool, Location | None]]:
    """The dofs of ``node`` not prescribed to zero in every step: (dof, free, the line to blame or None); ``free``:
    not prescribed in some step, else prescribed to a nonzero value."""
    bad = []
    for dof in dofs:
        history = histories.get((node, dof))
        if history is None or not history.always:
            bad.append((dof, True, None if history is None else history.changes_at()))
            continue
        moving = next((s for s in history.segments if s.value != 0.0 or (s.ramp_from or 0.0) != 0.0), None)
        if moving is not None:
            bad.append((dof, False, moving.location))
    return bad


def _axes_of(abaqus: AbaqusModel) -> dict[int, Transform]:
    return {int(n): transform for transform in abaqus.transforms for n in transform.nodes}


def rigid_body_issues(abaqus: AbaqusModel, histories: dict[tuple[int, int], History]) -> list[list[ClipIssue]]:
    """For each ``*Rigid Body`` (in input order) what keeps it from being a clip arm (empty: it is one)."""
    transforms = _axes_of(abaqus)
    out = []
    for body in abaqus.rigid_bodies:
        issues: list[ClipIssue] = []
        rp = body.reference_node
        label = _label(abaqus, rp)
        types = set(_element_rows(abaqus, body.elements)[0])
        if not types or not types <= set(_ARM_TYPES):
            issues.append(ClipIssue("*Rigid Body", body.location, f"rigid body on {body.elset}: elements "
                                    f"{', '.join(sorted(types)) or 'none'}; only R3D4 facet arms are modelled"))
        options = [key for key in body.parameters if key.upper() in _UNMODELLED_BODY_OPTIONS]
        if options:
            issues.append(ClipIssue("*Rigid Body", body.location, f"rigid body on {body.elset}: "
                                    f"{', '.join(o.upper() for o in options)} not modelled"))
        bad = _not_held(histories, rp, range(1, 7))
        free = [(dof, where) for dof, is_free, where in bad if is_free]
        if free:
            changes = "".join(f"; dof {d} prescribed or released from line {w.line} on" for d, w in free if w)
            issues.append(ClipIssue("*Rigid Body", body.location, f"reference node {label}: dof(s) "
                                    f"{', '.join(str(d) for d, _ in free)} not prescribed in every step{changes} (a "
                                    "free rigid body is not modelled)"))
        for dof, _, where in (item for item in bad if not item[1] and item[0] < 6):
            what = "translation" if dof <= 3 else "rotation"
            issues.append(ClipIssue("*Boundary", where, f"reference node {label}: nonzero {what} in dof {dof} "
                                    "(only a rotation about the local 3-axis, dof 6, is modelled)"))
        transform = transforms.get(rp)
        if transform is not None:
            try:
                transform_axes(transform)
            except ValueError as err:
                issues.append(ClipIssue("*Transform", transform.location, str(err).split(": ", 1)[-1]))
        out.append(issues)
    return out


def connector_issues(abaqus: AbaqusModel, histories: dict[tuple[int, int], History]) -> list[list[ClipIssue]]:
    """For each ``*Connector Section`` what could make it act (empty: inert, dropped)."""
    out = []
    for section in abaqus.connector_sections:
        issues: list[ClipIssue] = []
        kinds = [c.upper() for c in section.connection_types if c]
        active = [c for c in kinds if c not in INERT_CONNECTIONS]
        if active or not kinds:
            issues.append(ClipIssue("*Connector Section", section.location, f"connector {'/'.join(kinds) or '?'} on "
                                    f"{section.elset}: only translational types ({', '.join(INERT_CONNECTIONS)}) "
                                    "between nodes held in dofs 1-3 are modelled (as inert)"))
        _, rows, _ = _element_rows(abaqus, section.elements)
        loose = [_label(abaqus, int(node)) for node in np.unique(rows[rows >= 0])
                 if _not_held(histories, int(node), range(1, 4))]
        if loose:
            issues.append(ClipIssue("*Connector Section", section.location, f"connector on {section.elset}: node(s) "
                                    f"{', '.join(loose)} not held at zero in dofs 1-3 in every step, so the connector "
                                    "would act (not modelled)"))
        out.append(issues)
    return out


def _triangles(quads: np.ndarray) -> np.ndarray:
    """Quads (and triangles with -1 or a repeated last node) split into triangles, degenerate ones dropped."""
    tri = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    ok = (tri >= 0).all(axis=1) & (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return tri[ok]


def clip_arms(abaqus: AbaqusModel, histories: dict[tuple[int, int], History]) -> list[ClipArm]:
    """The rigid bodies that are clip arms (:func:`rigid_body_issues` finds nothing), in input order."""
    transforms = _axes_of(abaqus)
    arms = []
    for body, issues in zip(abaqus.rigid_bodies, rigid_body_issues(abaqus, histories), strict=True):
        if issues:
            continue
        _, rows, scopes = _element_rows(abaqus, body.elements)
        nodes, local = np.unique(rows[rows >= 0], return_inverse=True)
        quads = np.full(rows.shape, -1, dtype=np.int64)
        quads[rows >= 0] = local
        rp = body.reference_node
        transform = transforms.get(rp)
        axis = transform_axes(transform)[2] if transform is not None else np.array([0.0, 0.0, 1.0])
        name = scopes[0] if scopes and scopes[0] and len(set(scopes)) == 1 else (body.elset or f"rigid body {rp}")
        arms.append(ClipArm(name, rp, abaqus.nodes[rp].copy(), axis, abaqus.nodes[nodes].copy(), _triangles(quads),
                            histories[(rp, 6)], body.location))
    return arms
