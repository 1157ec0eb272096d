r"""The biaxial leaflet sample of Thomas et al. (2019) §2.5: hex mesh, α/μ map, networks per element.

Geometry and mesh (§2.5): a 7 × 7 × 0.406 mm block, x circumferential (axis 1), y radial (axis 2),
z through the thickness, 28 × 28 × 3 trilinear hexahedra (2352 elements; 8 Gauss points each: 18 816
RVEs). Coarser meshes of the same block are used for quick runs.

The α/μ map. The paper's SALS map (Fig. 2e) is published only as a figure; what it states in numbers
are the three networks of Fig. 6: N1 in the belly (α = 41 %), N2 near the left boundary (27 %), N3 near
the top boundary (28 %), with the fibers mostly circumferential. The default field
(:func:`default_alpha_mu`) reproduces exactly these values with the simplest smooth shape: α is 41 %
in the centre and falls, with the distance ``d`` to the nearest edge, to an edge value of 27 % (left,
right, bottom) rising to 28 % at the top edge,

.. math::

    \alpha = \alpha_e + (\alpha_c - \alpha_e)\, s\!\left(\frac{d - d_0}{d_1 - d_0}\right),\qquad
    \alpha_e = 27 + (28 - 27)\, s\!\left(\frac{\eta - 0.5}{\eta_3 - 0.5}\right),

with the smoothstep :math:`s(\xi) = 3\xi^2 - 2\xi^3` clipped to [0, 1], η = y/7 mm, η₃ = 0.91 the
height of N3 (so α_e = 27 % below mid-height, 28 % from N3's height up),
:math:`d_0` = 1 mm, :math:`d_1` = 3 mm (N2 and N3 lie in the edge band, N1 in the plateau);
μ = 0° (circumferential) everywhere. A user map replaces it: an array of (α, μ) per element, or a
callable ``(x, y) -> (alpha, mu)`` of element-centre coordinates in metres.

Networks. Each element gets the library network (:class:`~skvalve.networks.NetworkLibrary`, an α
grid in steps of ``alpha_step`` and the requested μ values, ``copies`` seeds per cell) whose target is
nearest to its (α, μ); neighbouring elements with the same target get different seeds (copy =
element index modulo ``copies``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import skfem

from ...fem.meshes import box
from ...networks.library import NetworkLibrary
from ...networks.network import Network
from . import data

__all__ = ["Sample", "build_sample", "default_alpha_mu", "sample_mesh"]


@dataclass
class Sample:
    """A meshed sample with one network per element.

    mesh : the hex mesh (metres; boundaries left/right (x), bottom/top (y), front/back (z)).
    alpha, mu : (n_elements,) target anisotropy index (%) and mean direction (°) per element.
    networks : one :class:`Network` per element.
    network_alpha : (n_elements,) α the assigned network actually has (projected, Eq. 2).
    markers : element index of the paper's networks N1, N2, N3 (Fig. 4/6) in this mesh.
    """

    mesh: skfem.MeshHex
    alpha: np.ndarray
    mu: np.ndarray
    networks: list[Network]
    network_alpha: np.ndarray
    markers: dict[str, int]

    @property
    def size(self) -> tuple[float, float, float]:
        p = self.mesh.p
        return tuple(float(p[a].max() - p[a].min()) for a in range(3))

    @property
    def n_elements(self) -> int:
        return self.mesh.nelements


def sample_mesh(divisions: tuple[int, int, int] = data.MESH_DIVISIONS) -> skfem.MeshHex:
    """The §2.5 block (metres) with ``divisions`` = (nx, ny, nz) hexes (paper: 28 × 28 × 3)."""
    divisions = tuple(int(n) for n in divisions)
    if len(divisions) != 3 or min(divisions) < 1:
        raise ValueError(f"sample_mesh: divisions must be three positive integers, got {divisions}")
    return box(divisions, lengths=tuple(s * 1e-3 for s in data.SAMPLE_SIZE_MM))


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def default_alpha_mu(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Default (α %, μ °) at in-plane points (metres) of the 7 × 7 mm sample (module docstring)."""
    width, height = data.SAMPLE_SIZE_MM[0] * 1e-3, data.SAMPLE_SIZE_MM[1] * 1e-3
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    distance = np.minimum.reduce([x, width - x, y, height - y]) * 1e3  # mm to the nearest edge
    eta = y / height
    eta_n3 = data.NETWORK_LOCATIONS["N3"][1]
    edge = data.ALPHA_N2 + (data.ALPHA_N3 - data.ALPHA_N2) * _smoothstep((eta - 0.5) / (eta_n3 - 0.5))
    d0, d1 = data.DEFAULT_MAP_EDGE_BAND_MM
    alpha = edge + (data.ALPHA_N1 - edge) * _smoothstep((distance - d0) / (d1 - d0))
    return alpha, np.zeros_like(alpha)


def marker_elements(mesh: skfem.MeshHex) -> dict[str, int]:
    """Elements of N1 (centre, top layer), N2 (left, mid-height) and N3 (top, mid-width), Fig. 4."""
    centres = mesh.p[:, mesh.t].mean(axis=1)
    markers = {}
    for name, (fx, fy) in data.NETWORK_LOCATIONS.items():
        target = np.array([fx * data.SAMPLE_SIZE_MM[0], fy * data.SAMPLE_SIZE_MM[1], data.SAMPLE_SIZE_MM[2]]) * 1e-3
        markers[name] = int(np.argmin(np.linalg.norm(centres - target[:, None], axis=0)))
    return markers


def build_sample(
    divisions: tuple[int, int, int] = data.MESH_DIVISIONS,
    alpha_mu: np.ndarray | Callable | None = None,
    n_fibers: int = data.FIBERS_PER_RVE,
    alpha_step: float = 1.0,
    copies: int = 3,
    seed: int = 0,
    library_directory=None,
) -> Sample:
    """Mesh the sample and assign a library network to every element.

    Parameters
    ----------
    divisions : hexes along x, y, z (paper: 28, 28, 3).
    alpha_mu : None for :func:`default_alpha_mu`; an (n_elements, 2) array of (α %, μ °); or a
        callable ``(x, y) -> (alpha, mu)`` on element-centre coordinates (metres).
    n_fibers : fibers per network (paper: ~450).
    alpha_step, copies, seed : library grid spacing in α, seeds per grid cell, base seed.
    library_directory : network cache (default: the user cache of :mod:`skvalve.networks.library`).
    """
    mesh = sample_mesh(divisions)
    n = mesh.nelements
    centres = mesh.p[:, mesh.t].mean(axis=1)
    if alpha_mu is None:
        alpha, mu = default_alpha_mu(centres[0], centres[1])
    elif callable(alpha_mu):
        alpha, mu = (np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy() for v in alpha_mu(centres[0], centres[1]))
    else:
        values = np.asarray(alpha_mu, dtype=float)
        if values.shape != (n, 2):
            raise ValueError(f"build_sample: alpha_mu array must have shape ({n}, 2) (alpha, mu per element), "
                             f"got {values.shape}")
        alpha, mu = values[:, 0].copy(), values[:, 1].copy()
    bad = ~(np.isfinite(alpha) & np.isfinite(mu) & (alpha >= 0.0) & (alpha < 95.0))
    if np.any(bad):
        e = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"build_sample: element {e} has alpha={alpha[e]!r}, mu={mu[e]!r} (need finite, 0 <= alpha < 95)"
        )
    mu = (mu + 90.0) % 180.0 - 90.0
    grid_alpha = np.arange(np.floor(alpha.min() / alpha_step), np.ceil(alpha.max() / alpha_step) + 1) * alpha_step
    grid_mu = np.unique(np.round(mu, 6))
    library = NetworkLibrary(grid_alpha, grid_mu, per_cell=copies, n_fibers=n_fibers, seed=seed,
                             directory=library_directory)
    networks = [library.nearest(alpha[e], mu[e], copy=e) for e in range(n)]
    network_alpha = np.array([float(net.meta.get("alpha", np.nan)) for net in networks])
    return Sample(mesh, alpha, mu, networks, network_alpha, marker_elements(mesh))
