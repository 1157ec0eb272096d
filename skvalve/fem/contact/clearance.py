r"""How far a step may carry a contact surface before a node could pass through a sheet: a step limit by clearance.

A penalty energy that ignores overlaps past the search depth :math:`g_\max` lets a long step carry a node through a
sheet unseen; worse, the blended penalty fades out over :math:`0.8\,g_\max < h < g_\max`
(:mod:`~skvalve.fem.contact.blend`), where its energy *falls* with depth, so a node that reached the fade is pushed on
through (the 1.0 valve's search depth, 0.50 mm, is more than its two-layer leaflets' thickness, 0.39 mm). Capping
every node's motion at :math:`g_\max` prevents that, but it also holds back the parts of a structure that swing or
slide together. This limit looks at what matters, pair by pair: for a node :math:`i` of the surface and a triangle
:math:`T` it may contact (not a topological neighbour, not excluded by reference distance: the pairs the contact
search itself keeps) that the energy counts as facing (:meth:`~skvalve.fem.contact.SurfaceContact.facing`) and
with the node no deeper than :math:`\tfrac34 g_\max` below the triangle's plane, the gap :math:`g(f)`
(:mod:`~skvalve.fem.contact.geometry`) is followed along the step :math:`f p`, and wherever the node's projection lies
where the pair's band weight is at least ½ (:meth:`~skvalve.fem.contact.SurfaceContact.band_lower` plus
:math:`\beta`: barycentric coordinates :math:`\ge -\beta` opposite a free edge, :math:`\ge 0` opposite a shared one,
past which the node lies over the neighbour, whose pair guards it) it must stay

.. math::

    g(f) \ge -\tfrac34 g_\max :

a node may slide along a sheet, come out of it or come in from the side freely, but no step takes it deeper than
three quarters of the depth, short of the fade-out. So no step carries a node from a shallower state into the
fade-out, and the step's energy test sees the barrier. Pairs already at 0.74 of the depth or deeper are let go: a node
that the forces hold at its floor despite the full penalty would otherwise stop every step (this happened on the 1.1
valve), and from there on only the energy test stands in its way. With the contact's depth barrier
(``SurfaceContact(barrier=...)``, :func:`~skvalve.fem.contact.laws.depth_barrier`) the energy itself grows without
bound towards this floor, so the forces that press a node in are met before it gets there.

Earlier rules each stopped a valve run at one node held at its floor: half the depth, with nodes already deeper held
to their depth (a node at the edge of a band next to a free edge, 0.32 mm below it, stopped Ψtc on the 1.0 valve; one
0.9 of the depth below a 1.1 triangle, the trust region); normals merely opposed instead of facing as the energy counts
them; the whole band past a shared edge (0.75 of the depth below a triangle on a crease, over its neighbour).

While the penalty is zero (at the load factor of the contact's last assembly, which is the step's: both solvers
assemble at the step's load before they limit it) the limit lets every step through: there is no barrier to cross
unseen, and a node held at its floor would have nothing to push it back.

:math:`g(f)` is sampled at :math:`\max(8, 4 m/g_\max)` points (at most 64; :math:`m` the largest motion of a node
relative to a triangle's corner), so that between samples a gap changes by about a quarter of the depth, and the first
crossing is bisected. Only the pairs that can reach are followed: with
:math:`c_T` the centroid, :math:`r_T` the largest centroid-corner distance and :math:`m_{iT} = \max_{v\in T}\lvert
p_i - p_v\rvert` the node's largest motion relative to any point of the triangle (which moves by a convex
combination of its corners' motions), a projection in the band lies within :math:`(1 + 6\beta) r_T` of the centroid,
so a pair with :math:`\lvert x_i - c_T\rvert - m_{iT} > (1 + 6\beta) r_T + \tfrac34 g_\max` cannot cross; the others
are found with ``scipy.spatial.cKDTree.sparse_distance_matrix`` between the nodes and the centroids.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from .blend import BARRIER_FLOOR
from .geometry import barycentric, plane_gap
from .penalty import SurfaceContact

__all__ = ["clearance_fraction"]

#: Samples along the step of a close pair's gap: at least this many ...
MIN_SAMPLES = 8
#: ... and at most this many.
MAX_SAMPLES = 64
#: How deep (a fraction of the search depth) a step may take a node through a triangle: short of the fade-out.
ALLOWED_DEPTH = BARRIER_FLOOR - 0.01  # 0.75: the barrier's floor lies just past it
#: A pair whose node is this deep already is let go (just short of the allowed depth: a node the forces hold at its
#: floor would otherwise stop every step).
RELEASED_DEPTH = ALLOWED_DEPTH - 0.01
#: A pair that allows less than this fraction of a step is let go (held at its floor, it would stop every step).
MIN_FRACTION = 1e-9
#: Bisection steps on the first sampled crossing.
BISECTIONS = 30
#: A pair is followed if its node can come within the band's reach plus this many search depths of the centroid.
SLACK = 0.75


def clearance_fraction(contact: SurfaceContact, u: np.ndarray, p: np.ndarray) -> float:
    """The largest fraction :math:`f \\le 1` of the step ``p`` from ``u`` (full dof vectors) that carries no node of
    ``contact``'s surface from above to deeper than three quarters of its search depth through a triangle it may
    contact (module docstring)."""
    t = contact.last_load_factor
    if t is not None and not contact.penalty(t) > 0.0:  # no penalty acting (yet): no barrier a step could cross
        return 1.0
    n_u = contact.space.n_u
    nodes, triangles = contact.surface.nodes, contact.surface.triangles
    x = contact.X + u[:n_u].reshape(-1, 3)
    motion = p[:n_u].reshape(-1, 3)
    largest = float(np.linalg.norm(motion[nodes], axis=1).max(initial=0.0))
    if largest == 0.0:
        return 1.0
    depth = contact.max_penetration
    band = -2.0 * max(contact.blend, contact.tolerance)
    corners = x[triangles]
    centroid = corners.mean(axis=1)
    # a projection in the band lies within (1 - 3 band) r_T of the centroid
    reach = (1.0 - 3.0 * band) * np.linalg.norm(corners - centroid[:, None], axis=2).max(axis=1) + SLACK * depth
    near = cKDTree(x[nodes]).sparse_distance_matrix(cKDTree(centroid), 2.0 * largest + float(reach.max()),
                                                    output_type="ndarray")
    node, triangle = nodes[near["i"]], near["j"].astype(np.int64)
    distance = near["v"] - reach[triangle]
    # |p_i| + max_v |p_v| bounds the relative motion: a cheap first cut before the exclusions and the exact bound
    speed = np.linalg.norm(motion, axis=1)
    keep = speed[node] + speed[triangles].max(axis=1)[triangle] > distance
    keep[keep] = contact.may_contact(node[keep], triangle[keep])
    node, triangle, distance = node[keep], triangle[keep], distance[keep]
    corner_ids = triangles[triangle]
    relative = np.linalg.norm(motion[node][:, None, :] - motion[corner_ids], axis=2).max(axis=1)
    reaching = relative > distance  # no other pair can end in its triangle's band within the depth
    node, triangle, corner_ids, relative = node[reaching], triangle[reaching], corner_ids[reaching], relative[reaching]
    if node.size == 0:
        return 1.0
    gap0, _ = plane_gap(x[node], x[corner_ids])
    floor = -ALLOWED_DEPTH * depth
    # the pairs the energy sees (facing), short of the floor (a node held at its floor is let go: nothing else moves)
    seen = (gap0 > -RELEASED_DEPTH * depth) & (contact.facing(node, triangle, x) > 0.0)
    # where the pair's band weight is at least 1/2: over the triangle itself (shared edges: a node past one lies over
    # the neighbour, whose pair guards it) and up to beta past a free edge
    lower = contact.band_lower(triangle[seen]) + contact.blend
    node, corner_ids = node[seen], corner_ids[seen]
    if node.size == 0:
        return 1.0

    def violated(f: np.ndarray, which: np.ndarray) -> np.ndarray:
        """Pairs ``which`` past the floor at ``x + f motion`` (``f`` one per pair), with the projection in the band."""
        f = f[:, None]
        xs = x[node[which]] + f * motion[node[which]]
        c = x[corner_ids[which]] + f[:, :, None] * motion[corner_ids[which]]
        hit = plane_gap(xs, c)[0] < floor
        hit[hit] = np.all(barycentric(xs[hit], c[hit]) >= lower[which[hit]], axis=1)  # the band only where deep
        return hit

    samples = int(min(MAX_SAMPLES, max(MIN_SAMPLES, math.ceil(4.0 * float(relative.max()) / depth))))
    crossing = np.full(node.size, np.inf)
    everyone = np.arange(node.size)
    for f in np.linspace(0.0, 1.0, samples + 1)[1:]:
        open_pairs = everyone[np.isinf(crossing)]
        hit = violated(np.full(open_pairs.size, f), open_pairs)
        crossing[open_pairs[hit]] = f
    which = everyone[np.isfinite(crossing)]
    if which.size == 0:
        return 1.0
    high = crossing[which]
    low = high - 1.0 / samples  # the last sample at which the pair was fine
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        hit = violated(middle, which)
        high = np.where(hit, middle, high)
        low = np.where(hit, low, middle)
    held = low < MIN_FRACTION  # crossing at once: held at its floor (or at a crease of the gap); let go, as above
    return 1.0 if np.all(held) else float(low[~held].min())

