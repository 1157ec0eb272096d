r"""Chordae tendineae as cables an implicit solver can carry: chains collapsed between branch points.

The shipped chordae are polylines of 2-node trusses. A node that only joins two bars of a chain has
no stiffness across the chain until the chain is in tension (the truss tangent across a bar is
:math:`N/l`, :mod:`skvalve.fem.elements.truss`), so each such node is a mechanism of the implicit tangent;
a node hanging on one bar is a mechanism in every direction. Here the network is reduced to

* **kept nodes**: nodes anchored to the rest of the model (leaflet nodes, nodes with boundary
  conditions) and branch points (three or more bars);
* **cables**: each chain of two-bar, unanchored nodes between two kept nodes becomes one cable with
  the chain's path length :math:`L = \sum_k |X_{k+1} - X_k|` as rest length. The cable is slack while
  its end-to-end distance is below :math:`L` (curved chains, e.g. the sinusoidal segments that tuned
  the chord lengths in mathur2022) and carries the chain's force once straight;
* **dropped**: dangling branches (unanchored nodes with a single bar, repeatedly) and closed loops of
  unanchored two-bar nodes, reported.

A collapsed cable has the same force as the straightened chain (every bar of a taut chain carries
the same force, the sum of the bar elongations is the chain's), so the model changes only while
the chain is not straight, where the original chain carried no force either (only its slack
stiffness). The bars of one chain must share area and law (checked).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..fem.elements.truss import BarEnd, LawAssignment, bar_response

__all__ = ["CollapsedChordae", "collapse_chains", "tangent_on_free_nodes", "insertion_patches"]


@dataclass
class CollapsedChordae:
    """The reduced chordae network.

    Attributes
    ----------
    ends : (n_cables, 2) node indices of the cable ends (kept nodes).
    rest_length : (n_cables,) chain path lengths.
    straight_length : (n_cables,) reference end-to-end distances (``<= rest_length``).
    group : (n_cables,) the group (section/law number) of each cable.
    chains : original bar indices of each cable, in order from ``ends[:, 0]``.
    kept_nodes : node indices still used by a cable.
    interior_nodes : the collapsed chain nodes (no longer used by any element).
    dropped_bars, dropped_nodes : dangling bars and unanchored nodes removed with them (and loops).
    bars : (n_bars, 2) the original bars (``chains`` and ``dropped_bars`` index them).
    """

    ends: np.ndarray
    rest_length: np.ndarray
    straight_length: np.ndarray
    group: np.ndarray
    chains: list[np.ndarray]
    kept_nodes: np.ndarray
    interior_nodes: np.ndarray
    dropped_bars: np.ndarray
    dropped_nodes: np.ndarray
    bars: np.ndarray
    notes: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """One line: cables, collapsed nodes, dropped bars and nodes."""
        return (f"{len(self.chains)} cables from {sum(len(c) for c in self.chains)} bars; "
                f"{self.interior_nodes.size} chain nodes collapsed; {self.dropped_bars.size} dangling bar(s) and "
                f"{self.dropped_nodes.size} node(s) dropped {self.dropped_nodes[:10].tolist()}")


def _incidence(bars: np.ndarray, n_nodes: int, alive: np.ndarray) -> list[list[int]]:
    incident: list[list[int]] = [[] for _ in range(n_nodes)]
    for b in np.flatnonzero(alive):
        incident[bars[b, 0]].append(int(b))
        incident[bars[b, 1]].append(int(b))
    return incident


def collapse_chains(bars: np.ndarray, coordinates: np.ndarray, anchored: np.ndarray,
                    group: np.ndarray | None = None) -> CollapsedChordae:
    """Collapse chains of two-bar unanchored nodes into cables (module docstring).

    Parameters
    ----------
    bars : (n_bars, 2) node indices.
    coordinates : (n_nodes, 3) reference coordinates.
    anchored : node indices that must stay (attached to solid elements or constrained).
    group : (n_bars,) section/law number of each bar (default all 0); a chain mixing groups raises.
    """
    bars = np.asarray(bars, dtype=np.int64)
    coordinates = np.asarray(coordinates, dtype=float)
    n_nodes = coordinates.shape[0]
    if bars.ndim != 2 or bars.shape[1] != 2:
        raise ValueError(f"bars must have shape (n, 2); got {bars.shape}")
    if bars.size and (bars.min() < 0 or bars.max() >= n_nodes):
        raise ValueError(f"bar node indices must lie in 0..{n_nodes - 1}")
    group = np.zeros(bars.shape[0], dtype=np.int64) if group is None else np.asarray(group, dtype=np.int64)
    is_anchored = np.zeros(n_nodes, dtype=bool)
    is_anchored[np.asarray(anchored, dtype=np.int64)] = True
    length = np.linalg.norm(coordinates[bars[:, 1]] - coordinates[bars[:, 0]], axis=1)

    # 1. prune dangling branches: unanchored nodes with one bar, until none is left
    alive = bars[:, 0] != bars[:, 1]
    dropped_nodes: list[int] = []
    while True:
        degree = np.bincount(bars[alive].ravel(), minlength=n_nodes)
        dangling = np.flatnonzero((degree == 1) & ~is_anchored)
        if dangling.size == 0:
            break
        dropped_nodes.extend(dangling.tolist())
        alive &= ~np.isin(bars, dangling).any(axis=1)
    degree = np.bincount(bars[alive].ravel(), minlength=n_nodes)
    used = degree > 0
    kept = used & (is_anchored | (degree != 2))
    incident = _incidence(bars, n_nodes, alive)

    # 2. walk every chain from a kept node
    visited = np.zeros(bars.shape[0], dtype=bool)
    ends, rest, chains, groups, interior = [], [], [], [], []
    notes = []
    for start in np.flatnonzero(kept):
        for first in incident[start]:
            if visited[first]:
                continue
            chain, node, bar = [], int(start), first
            while True:
                visited[bar] = True
                chain.append(bar)
                node = int(bars[bar, 1] if bars[bar, 0] == node else bars[bar, 0])
                if kept[node]:
                    break
                interior.append(node)
                bar = next(b for b in incident[node] if b != bar)
            chain_groups = np.unique(group[chain])
            if chain_groups.size != 1:
                raise ValueError(f"chordae chain of bars {chain[:5]}... mixes sections/laws {chain_groups.tolist()}")
            if node == start:
                notes.append(f"closed chain of {len(chain)} bars at node {start} dropped")
                dropped_nodes.extend(int(n) for n in bars[chain].ravel() if not kept[n])
                continue
            ends.append((int(start), node))
            rest.append(float(length[chain].sum()))
            chains.append(np.asarray(chain, dtype=np.int64))
            groups.append(int(chain_groups[0]))
    loops = np.flatnonzero(alive & ~visited)  # cycles of unanchored two-bar nodes only
    if loops.size:
        notes.append(f"{loops.size} bar(s) in closed loops without an anchor dropped")
        dropped_nodes.extend(np.unique(bars[loops]).tolist())
    ends_arr = np.asarray(ends, dtype=np.int64).reshape(-1, 2)
    straight = np.linalg.norm(coordinates[ends_arr[:, 1]] - coordinates[ends_arr[:, 0]], axis=1)
    dropped_bars = np.flatnonzero(~alive & (bars[:, 0] != bars[:, 1]))
    dropped_bars = np.union1d(dropped_bars, loops)
    interior_arr = np.unique(np.asarray(interior, dtype=np.int64))
    return CollapsedChordae(
        ends=ends_arr, rest_length=np.asarray(rest), straight_length=straight,
        group=np.asarray(groups, dtype=np.int64), chains=chains, kept_nodes=np.unique(ends_arr),
        interior_nodes=interior_arr, dropped_bars=dropped_bars,
        dropped_nodes=np.unique(np.asarray(dropped_nodes, dtype=np.int64)), bars=bars, notes=notes,
    )


def tangent_on_free_nodes(ends: np.ndarray, coordinates: np.ndarray, rest_length: np.ndarray, area: np.ndarray,
                          laws: LawAssignment, fixed: np.ndarray,
                          slack_stretch: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Dense tangent of cables in their reference state on the nodes not in ``fixed``, and those nodes.

    Its smallest eigenvalues show whether the network has zero-stiffness directions (mechanisms) once the
    nodes it hangs from (leaflets, papillary tips) are held.
    """
    ends = np.asarray(ends, dtype=np.int64)
    X = np.asarray(coordinates, dtype=float)
    state = bar_response(X[ends[:, 0]], X[ends[:, 1]], rest_length, area, laws, True, slack_stretch)
    free = np.setdiff1d(np.unique(ends), fixed)
    local = np.full(X.shape[0], -1)
    local[free] = np.arange(free.size)
    dofs = (3 * local[ends][:, :, None] + np.arange(3)).reshape(-1, 6)
    dofs[np.repeat(local[ends] < 0, 3, axis=1)] = -1
    K = np.zeros((3 * free.size, 3 * free.size))
    for e in range(ends.shape[0]):
        keep = dofs[e] >= 0
        index = dofs[e][keep]
        K[np.ix_(index, index)] += state.matrices[e][np.ix_(keep, keep)]
    return K, free


def insertion_patches(cells: np.ndarray, points: np.ndarray, ends: np.ndarray, rest_length: np.ndarray
                      ) -> tuple[tuple[BarEnd, BarEnd], np.ndarray, np.ndarray]:
    r"""Cable ends spread over the leaflet around their insertion: a distributing coupling.

    A cable end at a vertex of the leaflet mesh becomes the average of all vertices of the cells around it
    (equal weights; the force goes to them in equal shares) instead of a point load on one node, which on
    leaflets as soft as the TriValve's (:math:`C_0 = 1` kPa) distorts the few elements around the node far
    beyond what the cable's neighbourhood sees in a tissue where chordae fan out as they insert. Ends at
    vertices no cell uses (papillary tips, branch points) stay single. The patch centroid lies within about
    half an element of the node, so each cable's rest length is shifted by the change of its reference chord,
    keeping its slack (path length minus chord) and its force-free reference state:

    .. math::

        L' = L + \big(|X'_b - X'_a| - |X_b - X_a|\big), \qquad \lambda'_s = |X'_b - X'_a| / L'.

    Parameters: ``cells`` (n_nodes_per_cell, n_cells), ``points`` (3, n_vertices), cable ``ends`` (n, 2),
    ``rest_length`` (n,). Returns the two :class:`~skvalve.fem.elements.truss.BarEnd`, the new rest lengths and the
    slack stretches.
    """
    n_vertices = points.shape[1]
    owner = np.repeat(np.arange(cells.shape[1]), cells.shape[0])
    order = np.argsort(cells.T.ravel(), kind="stable")
    vertex_sorted = cells.T.ravel()[order]
    first = np.searchsorted(vertex_sorted, np.arange(n_vertices + 1))
    X = points.T
    built = []
    for column in range(2):
        rows = []
        for vertex in ends[:, column]:
            around = owner[order[first[vertex]:first[vertex + 1]]]
            rows.append(np.unique(cells[:, around]) if around.size else np.array([vertex]))
        width = max(len(r) for r in rows)
        nodes = np.array([np.pad(r, (0, width - len(r)), constant_values=r[0]) for r in rows], dtype=np.int64)
        weights = np.array([np.pad(np.full(len(r), 1.0 / len(r)), (0, width - len(r))) for r in rows])
        built.append(BarEnd(nodes, weights))
    chord = np.linalg.norm(X[ends[:, 1]] - X[ends[:, 0]], axis=1)
    centres = [np.einsum("nk,nkd->nd", end.weights, X[end.nodes]) for end in built]
    new_chord = np.linalg.norm(centres[1] - centres[0], axis=1)
    rest = rest_length + (new_chord - chord)
    return (built[0], built[1]), rest, np.minimum(new_chord / rest, 1.0)
