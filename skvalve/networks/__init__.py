"""Collagen-fiber network RVEs (Thomas et al. 2019, sections 2.2–2.4).

orientation : SALS orientation tensor H, anisotropy index α, mean direction μ (Eqs. 1–3)
generate    : Delaunay networks clipped to the unit RVE, matched to a target α/μ
library     : seeded, cached library of networks over an α/μ grid
rve         : RVE force balance, volume-averaged Cauchy stress (Eq. 8), consistent tangent
rve_batch   : many RVEs packed for the parallel kernel, warm starts, unchanged RVEs copied
rve_kernels, rve_tangent, dense_cholesky : the numba kernels (envelope Cholesky in a reverse
Cuthill–McKee numbering of the interior cross-links)
plotting    : Fig. 3 / Fig. 6 style plots (imported on demand: needs matplotlib)

`generate` is not re-exported here: the name would shadow the submodule
(use ``from skvalve.networks.generate import generate``).
"""

from skvalve.networks.library import NetworkLibrary, cached_network
from skvalve.networks.network import Network
from skvalve.networks.orientation import (
    anisotropy_index,
    mean_direction,
    network_alpha_mu,
    orientation_tensor,
    project,
)
from skvalve.networks.rve import RVEBatch, RVEResult, RVEState, solve_rve, solve_rve_batch

__all__ = [
    "Network",
    "NetworkLibrary",
    "RVEBatch",
    "RVEResult",
    "RVEState",
    "anisotropy_index",
    "cached_network",
    "mean_direction",
    "network_alpha_mu",
    "orientation_tensor",
    "project",
    "solve_rve",
    "solve_rve_batch",
]
