r"""How far a step may carry a contact surface before a node could pass through a sheet: a step limit by clearance.

A penalty energy that ignores overlaps past the search depth :math:`g_\max` lets a long step carry a node through a
sheet unseen. Capping every node's motion at :math:`g_\max` prevents that, but it also holds back the parts of a
structure that swing together, or are far from any other sheet (the thin 1.1 valve leaflets: 0.16 mm). This limit
looks at relative motion instead. Let :math:`h_j` be the longest edge of the triangles at node :math:`j`, so every
point of a triangle lies within :math:`h_j` of its corner :math:`j`. For surface nodes :math:`i, j` with step
motions :math:`p_i, p_j`, ask

.. math::

    f\,\lvert p_i - p_j\rvert \le \max(0, \lvert x_i - x_j\rvert - h_j) + g_\max
    \quad\text{and the same with } i, j \text{ swapped.}

Then for a triangle :math:`T` with corners :math:`v` the right-hand side with :math:`j = v` is at most
:math:`\operatorname{dist}(x_i, T) + g_\max`, and any point of :math:`T` moves by a convex combination of its
corners' motions, so the step :math:`f p` moves node :math:`i` relative to :math:`T` by at most
:math:`\operatorname{dist}(x_i, T) + g_\max`: no node ends deeper than the search depth through a triangle it was
not already touching. The fraction of the step that may be taken is the largest such :math:`f \le 1`, over the node
pairs closer than :math:`2\max_k\lvert p_k\rvert + \max_k h_k` (no other pair can close its distance), found with
``scipy.spatial.cKDTree.query_pairs``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .contact import SurfaceContact

__all__ = ["clearance_fraction"]


def clearance_fraction(contact: SurfaceContact, u: np.ndarray, p: np.ndarray) -> float:
    """The largest fraction :math:`f \\le 1` of the step ``p`` from ``u`` (full dof vectors) that can carry no node
    of ``contact``'s surface more than its search depth through a triangle (module docstring)."""
    n_u = contact.space.n_u
    nodes, triangles = contact.surface.nodes, contact.surface.triangles
    x = contact.X + u[:n_u].reshape(-1, 3)
    motion = p[:n_u].reshape(-1, 3)[nodes]
    largest = float(np.linalg.norm(motion, axis=1).max(initial=0.0))
    depth = contact.max_penetration
    if 2.0 * largest <= depth:  # no pair's relative motion can pass the depth
        return 1.0
    corners = x[triangles]
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    edge = np.zeros(x.shape[0])
    np.maximum.at(edge, triangles.ravel(), np.repeat(longest, 3))
    edge = edge[nodes]  # h_j of each surface node
    points = x[nodes]
    pairs = cKDTree(points).query_pairs(2.0 * largest + float(edge.max()), output_type="ndarray")
    if pairs.size == 0:
        return 1.0
    i, j = pairs[:, 0], pairs[:, 1]
    relative = np.linalg.norm(motion[i] - motion[j], axis=1)
    allowed = np.maximum(np.linalg.norm(points[i] - points[j], axis=1) - np.maximum(edge[i], edge[j]), 0.0) + depth
    bound = relative > allowed
    if not np.any(bound):
        return 1.0
    return float(np.min(allowed[bound] / relative[bound]))
