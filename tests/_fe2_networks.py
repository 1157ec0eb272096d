"""Networks shared by the FE² tests."""

import numpy as np

from skvalve.networks.network import Network


def affine_network(seed: int, n_fibers: int = 25) -> Network:
    """Fibers between random points on different faces of the unit cube: no interior cross-links."""
    rng = np.random.default_rng(seed)
    nodes, face = [], []
    for _ in range(2 * n_fibers):
        f = int(rng.integers(6))
        point = rng.uniform(-0.5, 0.5, 3)
        point[f // 2] = 0.5 if f % 2 else -0.5
        nodes.append(point)
        face.append(f)
    fibers = [[2 * k, 2 * k + 1] for k in range(n_fibers) if face[2 * k] != face[2 * k + 1]]
    return Network(np.array(nodes), np.array(fibers), np.ones(len(nodes), bool), np.array(face))
