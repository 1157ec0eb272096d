r"""Lift nodes parked deep inside another sheet back towards it, a repair of a relaxation's state.

The blended penalty fades out past :math:`0.8\,g_\max` (:mod:`~skvalve.fem.contact.blend`): there its energy falls
with depth, so a node that a long relaxation carried that deep is pushed on rather than back, and the relaxation
stalls with the node parked half-way through the other leaflet (on the 1.0 diseased valve: 20-odd nodes, a held
relative residual stuck near 1e-4 for four sessions). :func:`lift_parked_nodes` moves each node whose overlap
:math:`h = -g` exceeds ``level`` :math:`g_\max` straight out along the normal :math:`n` of the sheet it faces, by

.. math::

    \Delta = h - \text{target}\;g_\max ,\qquad x_i \leftarrow x_i + \Delta\,n ,

so that its gap to that triangle's plane becomes exactly :math:`-\text{target}\;g_\max` (:func:`plane_gap` is linear
in the node's position along the normal), inside the barrier's range where the energy pushes it out. The facing
sheet is the pair with the largest facing factor among the node's pairs deeper than half the depth (blended contact)
or the node's one pair (closest-triangle rule).

Each node moves alone (``columns=True``: with the vertices behind it through its own sheet, which keeps the sheet's
thickness but shears its neighbours). A move is halved, up to ``halvings`` times, while it would fold one of the
moved vertices' hexes (a corner Jacobian of the trilinear map :math:`\le 0`, or below its value before the move where
it was already folded), change the stretch :math:`\lvert x_i - x_j\rvert / \lvert X_i - X_j\rvert` to another
vertex :math:`j` of those hexes by more than ``max_stretch_change`` (0.2, the trust region's bound per step), or fail
``accept``; the node is left where it is (listed in ``refused``) if no halved move passes. The stretch bound does not
bound the forces: the loaded Texas TriValve leaflets sit deep in their exponential law, where lifts within it met
210 N (1.0 diseased) and 8e8 N (1.0 annuloplasty) at one node; :func:`force_limit` as ``accept`` halves such lifts
until the forces stay below a limit (one assembly per trial). Nodes with a prescribed displacement or at the end of
a constraint link never move (``held``; :func:`closure_held_nodes` lists them for a closure), nor do columns that
reach them. Lifted nodes may uncover others, so the search repeats ``sweeps`` times; a node whose lift was halved
may move again in the next sweep. The moved state is not an equilibrium: the relaxation starts again from it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import skfem

from ..fem.contact import SurfaceContact
from ..fem.contact.geometry import plane_gap
from ..fem.errors import NonPositiveJacobianError
from ..fem.problem import Problem
from .closure import ClosureSetup
from .extrude import hex_corner_jacobians
from .model import ABAQUS_TO_SKFEM_HEX

__all__ = ["COLUMN_COSINE", "ParkedLift", "closure_held_nodes", "force_limit", "lift_parked_nodes"]

#: A vertex behind a lifted node belongs to its column when their edge is this close to the lift's direction.
COLUMN_COSINE = 0.7


@dataclass
class ParkedLift:
    """What :func:`lift_parked_nodes` did: the moved displacement and, per lifted node, the lift (mm)."""

    u: np.ndarray
    lifted: np.ndarray       # (k,) scalar node ids, in the order they moved (a node once per sweep it moved in)
    lifts: np.ndarray        # (k,) distance moved along the facing normal
    refused: np.ndarray      # nodes past the level that no halved lift moved (folds, stretch, held, ``accept``)
    deeper_before: int       # nodes deeper than the level before
    deeper_after: int        # and after

    def __str__(self) -> str:
        largest = f", largest {self.lifts.max():.4g}" if self.lifts.size else ""
        return (f"lifted {self.lifted.size} parked nodes{largest}; {self.refused.size} refused (no halved lift "
                f"passed the tests); nodes past the level: {self.deeper_before} before, {self.deeper_after} after")


def _parked(contact: SurfaceContact, u: np.ndarray, level: float) -> tuple[np.ndarray, object]:
    pairs = contact.active_pairs(u)
    overlap = -pairs.gap
    return np.unique(pairs.node[overlap > level * contact.max_penetration]), pairs


def _grouped(keys: np.ndarray, values: np.ndarray, n: int) -> list[np.ndarray]:
    """For each key 0..n-1, the values listed with it (in their order)."""
    order = np.argsort(keys, kind="stable")
    starts = np.searchsorted(keys[order], np.arange(n + 1))
    return np.split(values[order], starts[1:-1])


def _neighbours(mesh: skfem.MeshHex) -> list[np.ndarray]:
    """Each vertex's neighbours along the hex edges."""
    ends = np.hstack([mesh.edges, mesh.edges[::-1]])
    return _grouped(ends[0], ends[1], mesh.p.shape[1])


def _cells_of_vertices(mesh: skfem.MeshHex) -> list[np.ndarray]:
    """Each vertex's hexes."""
    return _grouped(mesh.t.T.ravel(), np.repeat(np.arange(mesh.t.shape[1]), mesh.t.shape[0]), mesh.p.shape[1])


def _column(node: int, direction: np.ndarray, x: np.ndarray, neighbours: list[np.ndarray]) -> list[int]:
    """``node`` and the vertices behind it through its sheet's thickness: from each, the edge neighbour most nearly
    along ``direction`` (cosine >= COLUMN_COSINE), until there is none."""
    column = [int(node)]
    while True:
        candidates = np.setdiff1d(neighbours[column[-1]], column)
        if candidates.size == 0:
            return column
        edges = x[candidates] - x[column[-1]]
        cosine = edges @ direction / np.linalg.norm(edges, axis=1)
        best = int(np.argmax(cosine))
        if cosine[best] < COLUMN_COSINE:
            return column
        column.append(int(candidates[best]))


def lift_parked_nodes(contact: SurfaceContact, u: np.ndarray, mesh: skfem.MeshHex, level: float = 0.7,
                      target: float = 0.6, sweeps: int = 3, halvings: int = 8, held: np.ndarray | None = None,
                      max_stretch_change: float = 0.2, columns: bool = False,
                      accept: Callable[[np.ndarray, list[int]], bool] | None = None) -> ParkedLift:
    """Move the nodes deeper than ``level`` g_max to ``target`` g_max along their facing sheet's normal (module
    docstring). ``mesh``: the hex mesh of ``contact``'s space (its cells are checked); ``held``: scalar node ids that
    must not move; ``columns``: move each node with the vertices behind it through its own sheet (default: the node
    alone, which squeezes its sheet); ``accept(trial_u, moved_vertices)``: a further test of each trial move (e.g.
    :func:`force_limit`); ``u`` is not changed."""
    if not (0.0 < target < level < 1.0):
        raise ValueError(f"lift_parked_nodes: need 0 < target < level < 1 (fractions of the search depth); "
                         f"got target={target!r}, level={level!r}")
    if not (math.isfinite(max_stretch_change) and max_stretch_change > 0.0):
        raise ValueError(f"lift_parked_nodes: max_stretch_change must be positive; got {max_stretch_change!r}")
    if int(sweeps) < 1 or int(halvings) < 0:
        raise ValueError(f"lift_parked_nodes: sweeps must be >= 1 and halvings >= 0; got {sweeps!r}, {halvings!r}")
    n_u = contact.space.n_u
    u = np.array(u, dtype=float, copy=True)
    if u.size < n_u or not np.all(np.isfinite(u[:n_u])):
        raise ValueError(f"lift_parked_nodes: u must hold {n_u} finite displacement values")
    depth, X = contact.max_penetration, mesh.p.T
    hexes = mesh.t.T[:, np.argsort(ABAQUS_TO_SKFEM_HEX)]
    cells_of = _cells_of_vertices(mesh)
    neighbours = _neighbours(mesh) if columns else None
    is_held = np.zeros(X.shape[0], dtype=bool)
    if held is not None:
        is_held[np.asarray(held, dtype=np.int64).ravel()] = True

    def acceptable(trial: np.ndarray, moved: list[int], floor: float, cells: np.ndarray) -> bool:
        """No corner of the moved vertices' hexes folds further, no stretch to an unmoved vertex changes too much."""
        x_old, x_new = X + u[:n_u].reshape(-1, 3), X + trial[:n_u].reshape(-1, 3)
        if hex_corner_jacobians(x_new, hexes[cells]).min() <= floor:
            return False
        for vertex in moved:
            others = np.setdiff1d(mesh.t[:, cells_of[vertex]].ravel(), moved)
            reference = np.linalg.norm(X[others] - X[vertex], axis=1)
            change = np.linalg.norm(x_new[others] - x_new[vertex], axis=1) \
                - np.linalg.norm(x_old[others] - x_old[vertex], axis=1)
            if np.max(np.abs(change) / reference) > max_stretch_change:
                return False
        return True

    before, _ = _parked(contact, u, level)
    lifted, lifts, refused = [], [], set()
    for _ in range(int(sweeps)):
        nodes, pairs = _parked(contact, u, level)
        nodes = nodes[~np.isin(nodes, list(refused)) & ~is_held[nodes]]
        if nodes.size == 0:
            break
        overlap = -pairs.gap
        for node in nodes:
            mine = np.flatnonzero((pairs.node == node) & (overlap > 0.5 * depth))
            pick = mine[np.argmax(pairs.facing[mine])] if pairs.facing is not None else mine[0]
            x = X + u[:n_u].reshape(-1, 3)
            gap, normal = plane_gap(x[node][None], x[contact.surface.triangles[pairs.triangle[pick]]][None])
            lift = -float(gap[0]) - target * depth
            if lift <= 0.0:
                continue  # an earlier lift in this sweep moved the sheet
            moved = _column(node, normal[0], x, neighbours) if columns else [int(node)]
            if is_held[moved].any():
                refused.add(int(node))
                continue
            cells = np.unique(np.concatenate([cells_of[vertex] for vertex in moved])).astype(np.int64)
            floor = min(0.0, float(hex_corner_jacobians(x, hexes[cells]).min()))
            dofs = (3 * np.asarray(moved)[:, None] + np.arange(3)).ravel()
            for _ in range(int(halvings) + 1):
                trial = u.copy()
                trial[dofs] += np.tile(lift * normal[0], len(moved))
                if acceptable(trial, moved, floor, cells) and (accept is None or accept(trial, moved)):
                    u = trial
                    lifted.append(int(node))
                    lifts.append(lift)
                    break
                lift *= 0.5
            else:
                refused.add(int(node))
    after, _ = _parked(contact, u, level)
    return ParkedLift(u, np.asarray(lifted, dtype=np.int64), np.asarray(lifts), np.asarray(sorted(refused),
                      dtype=np.int64), int(before.size), int(after.size))


def closure_held_nodes(setup: ClosureSetup) -> np.ndarray:
    """Vertices a lift must not move: those with a prescribed displacement component and the ends of the model's
    LINK bars (annuloplasty ring ties)."""
    fixed = setup.problem.pattern.fixed
    nodes = [fixed[fixed < setup.problem.space.n_u] // 3]
    if setup.model.links is not None and setup.model.links.size:
        nodes.append(setup.model.links.ends.ravel())
    return np.unique(np.concatenate(nodes)).astype(np.int64)


def force_limit(problem: Problem, t: float, max_force: float, mesh: skfem.MeshHex) -> Callable[[np.ndarray, list[int]],
                                                                                          bool]:
    """An ``accept`` test for :func:`lift_parked_nodes`: the residual force (N, free components, at load factor ``t``)
    on every vertex of the moved vertices' hexes stays at most ``max_force`` and no element inverts (one assembly per
    trial). On the loaded Texas TriValve leaflets (Lee–Sacks :math:`c_2` = 3–32, deep in the exponential) a lone node
    lifted 0.08 mm met forces of 210 N (1.0 diseased) and 8e8 N (1.0 annuloplasty)."""
    if not (math.isfinite(max_force) and max_force > 0.0):
        raise ValueError(f"force_limit: max_force must be positive; got {max_force!r}")
    fixed = problem.pattern.fixed
    n_u = problem.space.n_u
    incident = _cells_of_vertices(mesh)

    def accept(trial: np.ndarray, moved: list[int]) -> bool:
        try:
            residual, _ = problem.assemble(trial, t, tangent=False)
        except NonPositiveJacobianError:
            return False
        residual = np.array(residual[:n_u], copy=True)
        residual[fixed[fixed < n_u]] = 0.0
        cells = np.concatenate([incident[vertex] for vertex in moved]).astype(np.int64)
        near = np.unique(mesh.t[:, cells])
        forces = np.linalg.norm(residual.reshape(-1, 3)[near], axis=1)
        return bool(np.all(np.isfinite(forces)) and forces.max() <= max_force)

    return accept
