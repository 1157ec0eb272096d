r"""How far a step may carry a contact surface before a node could pass through a sheet: a step limit by clearance.

A penalty energy that ignores overlaps past the search depth :math:`g_\max` lets a long step carry a node through a
sheet unseen. Capping every node's motion at :math:`g_\max` prevents that, but it also holds back the parts of a
structure that swing together, or are far from any other sheet (the thin 1.1 valve leaflets: 0.16 mm). This limit
looks at relative motion instead. For a node :math:`i` of the surface and a triangle :math:`T` it may contact (not a
topological neighbour, not excluded by reference distance: the pairs the contact search itself keeps), with
:math:`c_T` the centroid and :math:`r_T` the largest centroid-corner distance,

.. math::

    d_{iT} = \max(0, \lvert x_i - c_T\rvert - r_T) \le \operatorname{dist}(x_i, T), \qquad
    m_{iT} = \max_{v \in T} \lvert p_i - p_v\rvert ,

a lower bound on the distance and an upper bound on the node's motion relative to any point of the triangle (which
moves by a convex combination of its corners' motions). The step :math:`f p` brings the node at most
:math:`\tfrac12 g_\max` past the triangle when :math:`f\,m_{iT} \le d_{iT} + \tfrac12 g_\max`: a node that was not
past a face ends short of the deep fade-out of the blended penalty (from :math:`0.8\,g_\max` on), whose energy
falls with depth, so it cannot cross that barrier in one step unseen by the energy test (the 1.0 valve's search depth,
0.50 mm, is also more than its two-layer leaflets' thickness, 0.39 mm). The fraction of the step that may be taken is

.. math::

    f = \min\Big(1, \min_{iT} \frac{d_{iT} + \tfrac12 g_\max}{m_{iT}}\Big)

over the pairs with :math:`d_{iT} < 2\max_k\lvert p_k\rvert` (no other pair can close its distance), found with
``scipy.spatial.cKDTree.sparse_distance_matrix`` between the nodes and the centroids.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .contact import SurfaceContact

__all__ = ["clearance_fraction"]


def clearance_fraction(contact: SurfaceContact, u: np.ndarray, p: np.ndarray) -> float:
    """The largest fraction :math:`f \\le 1` of the step ``p`` from ``u`` (full dof vectors) that can carry no node
    of ``contact``'s surface more than half its search depth through a triangle it may contact (module docstring)."""
    n_u = contact.space.n_u
    nodes, triangles = contact.surface.nodes, contact.surface.triangles
    x = contact.X + u[:n_u].reshape(-1, 3)
    motion = p[:n_u].reshape(-1, 3)
    largest = float(np.linalg.norm(motion[nodes], axis=1).max(initial=0.0))
    allowance = 0.5 * contact.max_penetration
    if 2.0 * largest <= allowance:  # no pair's relative motion can pass the allowance
        return 1.0
    corners = x[triangles]
    centroid = corners.mean(axis=1)
    reach = np.linalg.norm(corners - centroid[:, None], axis=2).max(axis=1)
    near = cKDTree(x[nodes]).sparse_distance_matrix(cKDTree(centroid), 2.0 * largest + float(reach.max()),
                                                    output_type="ndarray")
    node, triangle = nodes[near["i"]], near["j"].astype(np.int64)
    distance = np.maximum(near["v"] - reach[triangle], 0.0)
    keep = distance < 2.0 * largest
    keep[keep] = contact.may_contact(node[keep], triangle[keep])
    node, triangle, distance = node[keep], triangle[keep], distance[keep]
    if node.size == 0:
        return 1.0
    relative = np.linalg.norm(motion[node][:, None, :] - motion[triangles[triangle]], axis=2).max(axis=1)
    bound = relative > distance + allowance
    if not np.any(bound):
        return 1.0
    return float(np.min((distance[bound] + allowance) / relative[bound]))
