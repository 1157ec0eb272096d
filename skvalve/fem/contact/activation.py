r"""Collision meshes per set of active obstacles: an :class:`~.obstacles.Obstacle` joins contact at its ``active_from``.

The collision mesh of :class:`~skvalve.fem.contact.ipc.IPCContact` is the body's surface followed by its obstacles'.
An obstacle that is not yet active (load factor :math:`t <` ``active_from``) is left out of the mesh altogether, so the
body may overlap it then (a clip arm parked where the leaflets close, which only grasps them once they have reopened);
from ``active_from`` on it is in the mesh and the barrier keeps the body off it. Each distinct set of active obstacles
(a *phase*) has its own ipctk ``CollisionMesh``, built once: the body first (the same vertex numbers in every phase),
then the active obstacles in their order.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import ipctk
import numpy as np
import scipy.sparse as sp

from .obstacles import Obstacle

__all__ = ["CollisionPhase", "CollisionPhases"]


@dataclass
class CollisionPhase:
    """The collision mesh while the obstacles flagged in ``key`` are active.

    ``rows``: its vertices' rows in the full collision mesh (body, then every obstacle); ``slices``: each active
    obstacle's rows in this mesh (None when inactive); ``select``: body dofs x this mesh's vertex coordinates."""

    key: tuple[bool, ...]
    mesh: ipctk.CollisionMesh
    rows: np.ndarray
    slices: list[slice | None]
    select: sp.csr_matrix


class CollisionPhases:
    """The phases of one collision mesh (module docstring), built on first use and kept.

    ``rest``: every vertex's rest position (body first); ``body_faces``: the body's triangles; ``obstacle_rows``:
    each obstacle's rows in ``rest``; ``body_filter``: what else keeps body vertices from colliding (e.g. pairs
    closer than a distance in the reference), ``None`` for nothing; ``self_contact`` False: body vertices never
    collide with each other; ``select``: body dofs x every vertex's coordinates."""

    def __init__(self, rest: np.ndarray, n_body: int, body_faces: np.ndarray, obstacles: Sequence[Obstacle],
                 obstacle_rows: Sequence[slice], body_filter: ipctk.CollisionFilter | None, self_contact: bool,
                 select: sp.csr_matrix) -> None:
        self.rest, self.n_body, self.body_faces = rest, n_body, body_faces
        self.obstacles, self.obstacle_rows = list(obstacles), list(obstacle_rows)
        self.body_filter, self.self_contact, self.full_select = body_filter, self_contact, select
        self._built: dict[tuple[bool, ...], CollisionPhase] = {}

    def key(self, t: float) -> tuple[bool, ...]:
        """Which obstacles are active at load factor ``t``."""
        return tuple(bool(t >= obstacle.active_from) for obstacle in self.obstacles)

    def at(self, t: float) -> CollisionPhase:
        """The phase at load factor ``t``."""
        key = self.key(t)
        if key not in self._built:
            self._built[key] = self._build(key)
        return self._built[key]

    def _build(self, key: tuple[bool, ...]) -> CollisionPhase:
        rows, faces, slices = [np.arange(self.n_body)], [self.body_faces], []
        offset = self.n_body
        for active, obstacle, full in zip(key, self.obstacles, self.obstacle_rows, strict=True):
            if not active:
                slices.append(None)
                continue
            count = obstacle.vertices.shape[0]
            rows.append(np.arange(full.start, full.stop))
            faces.append(obstacle.triangles + offset)
            slices.append(slice(offset, offset + count))
            offset += count
        rows = np.concatenate(rows)
        triangles = np.ascontiguousarray(np.concatenate(faces), dtype=np.int32)
        mesh = ipctk.CollisionMesh(np.ascontiguousarray(self.rest[rows]), ipctk.edges(triangles), triangles)
        patches = np.arange(rows.size, dtype=np.int32)
        patches[self.n_body:] = self.n_body  # every obstacle vertex in one patch: no obstacle-obstacle pairs
        if not self.self_contact:
            patches[: self.n_body] = -1
        allowed = ipctk.make_vertex_patches_filter(patches)
        if self.body_filter is not None:
            allowed = allowed & self.body_filter
        mesh.can_collide = allowed
        return CollisionPhase(key, mesh, rows, slices, sp.csr_matrix(self.full_select[:, : 3 * rows.size]))
