r"""How far a step may carry a contact surface before a node could pass through a sheet: a step limit by clearance.

A penalty energy that ignores overlaps past the search depth :math:`g_\max` lets a long step carry a node through a
sheet unseen; worse, the blended penalty fades out over :math:`0.8\,g_\max < h < g_\max`
(:mod:`~skvalve.fem.contact_blend`), where its energy *falls* with depth, so a node that reached the fade is pushed on
through (the 1.0 valve's search depth, 0.50 mm, is more than its two-layer leaflets' thickness, 0.39 mm). Capping
every node's motion at :math:`g_\max` prevents that, but it also holds back the parts of a structure that swing or
slide together. This limit looks at what matters, pair by pair: for a node :math:`i` of the surface and a triangle
:math:`T` it may contact (not a topological neighbour, not excluded by reference distance: the pairs the contact
search itself keeps) that the energy counts as facing (:meth:`~skvalve.fem.contact.SurfaceContact.facing`) and
with the node no deeper than :math:`\tfrac34 g_\max` below the triangle's plane, the gap :math:`g(f)`
(:mod:`~skvalve.fem.contact_geometry`) is followed along the step :math:`f p`, and wherever the node's projection lies
where the pair's band weight is at least ½ (:meth:`~skvalve.fem.contact.SurfaceContact.band_lower` plus
:math:`\beta`: barycentric coordinates :math:`\ge -\beta` opposite a free edge, :math:`\ge 0` opposite a shared one,
past which the node lies over the neighbour, whose pair guards it) it must stay

.. math::

    g(f) \ge -\tfrac34 g_\max :

a node may slide along a sheet, come out of it or come in from the side freely, but no step takes it deeper than
three quarters of the depth, short of the fade-out. So a node never reaches the fade-out from a state where it was
shallower, and the step's energy test sees every barrier. Pairs already deeper are left free: they are in the
fade-out, whose energy lets them go. (A first version allowed half the depth, and held nodes already deeper to the
depth they had: a node held at the edge of a triangle's band 0.32 mm below it, next to a free edge, stopped Ψtc on the
1.0 valve, and one 0.9 of the depth below a triangle of the 1.1 valve stopped the trust region; within the band the
full penalty pushes a node out long before three quarters of the depth. Pairs whose normals were opposed, but too
little for the energy to count them, held a 1.1 node at three quarters of the depth, with nothing pushing it out; so
did a pair at the edge of its band past a shared edge, 0.75 of the depth below the plane of a triangle on a crease.)

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

from .contact import SurfaceContact
from .contact_blend import DEEP_FADE
from .contact_geometry import barycentric

__all__ = ["clearance_fraction"]

#: Samples along the step of a close pair's gap: at least this many ...
MIN_SAMPLES = 8
#: ... and at most this many.
MAX_SAMPLES = 64
#: How deep (a fraction of the search depth) a step may take a node through a triangle: short of the fade-out.
ALLOWED_DEPTH = DEEP_FADE - 0.05  # 0.75
#: The smallest fraction returned (a node held at its floor allows no step along this direction).
MIN_FRACTION = 1e-12
#: Bisection steps on the first sampled crossing.
BISECTIONS = 30
#: A pair is followed if its node can come within the band's reach plus this many search depths of the centroid.
SLACK = 0.75


def clearance_fraction(contact: SurfaceContact, u: np.ndarray, p: np.ndarray) -> float:
    """The largest fraction :math:`f \\le 1` of the step ``p`` from ``u`` (full dof vectors) that carries no node of
    ``contact``'s surface from above to deeper than three quarters of its search depth through a triangle it may
    contact (module docstring)."""
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
    keep = distance < 2.0 * largest
    keep[keep] = contact.may_contact(node[keep], triangle[keep])
    node, triangle, distance = node[keep], triangle[keep], distance[keep]
    corner_ids = triangles[triangle]
    relative = np.linalg.norm(motion[node][:, None, :] - motion[corner_ids], axis=2).max(axis=1)
    reaching = relative > distance  # no other pair can end in its triangle's band within the depth
    node, triangle, corner_ids, relative = node[reaching], triangle[reaching], corner_ids[reaching], relative[reaching]
    if node.size == 0:
        return 1.0
    gap0, _ = _gap_and_band(x, motion, node, corner_ids, 0.0)
    floor = -ALLOWED_DEPTH * depth
    # the pairs the energy sees (facing), not yet in the fade-out (deeper ones: the energy lets them go)
    seen = (gap0 >= floor) & (contact.facing(node, triangle, x) > 0.0)
    # where the pair's band weight is at least 1/2: over the triangle itself (shared edges: a node past one lies over
    # the neighbour, whose pair guards it) and up to beta past a free edge
    lower = contact.band_lower(triangle[seen]) + contact.blend
    node, corner_ids = node[seen], corner_ids[seen]
    if node.size == 0:
        return 1.0

    def violated(f: np.ndarray, which: np.ndarray) -> np.ndarray:
        gap, lam = _gap_and_band(x, motion, node[which], corner_ids[which], f)
        return (gap < floor) & np.all(lam >= lower[which], axis=1)

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
    return max(float(low.min()), MIN_FRACTION)


def _gap_and_band(x, motion, node, corner_ids, f):
    """Gap (n,) and barycentric coordinates (n, 3) of each node over its triangle at ``x + f motion``."""
    f = np.asarray(f, dtype=float).reshape(-1, 1)
    xs = x[node] + f * motion[node]
    c = x[corner_ids] + f[:, :, None] * motion[corner_ids]
    m = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    normal = m / np.linalg.norm(m, axis=1, keepdims=True)
    return np.einsum("ij,ij->i", xs - c[:, 0], normal), barycentric(xs, c)
