"""Seeded, cached library of networks over an α/μ grid (Thomas 2019 section 2.3, "library of
network files").  Each network is generated once by :func:`generate` and stored as ``.npz``
in a user cache directory (``$SKVALVE_CACHE/networks`` if set, else ``~/.cache/skvalve/networks``),
never inside the package.  File names encode every generation input (α and μ to 0.01; the exact
targets are checked against the stored metadata), so a cache hit returns exactly what ``generate`` would.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from skvalve.networks.generate import generate
from skvalve.networks.network import Network

FORMAT_VERSION = 1


def cache_dir() -> Path:
    """Default network cache: $SKVALVE_CACHE/networks or ~/.cache/skvalve/networks."""
    root = os.environ.get("SKVALVE_CACHE")
    base = Path(root) if root else Path.home() / ".cache" / "skvalve"
    return base / "networks"


def network_file(alpha: float, mu: float, n_fibers: int, seed: int) -> str:
    return f"net_v{FORMAT_VERSION}_a{alpha:06.2f}_m{mu:+07.2f}_n{n_fibers}_s{seed}.npz"


def cached_network(
    alpha: float, mu: float, n_fibers: int = 450, seed: int = 0, directory: str | Path | None = None
) -> Network:
    """Load the network for (α, μ, n_fibers, seed) from the cache, generating it if missing."""
    folder = Path(directory) if directory is not None else cache_dir()
    path = folder / network_file(alpha, mu, n_fibers, seed)
    if path.exists():
        cached = Network.load(path)
        # the file name rounds α and μ to 0.01: serve the file only if it was made for these exact targets
        if cached.meta.get("alpha_target") == float(alpha) and cached.meta.get("mu_target") == float(mu):
            return cached
    network = generate(alpha, mu, n_fibers=n_fibers, seed=seed)
    folder.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    network.save(tmp)
    tmp.replace(path)  # atomic: concurrent readers never see a partial file
    return network


class NetworkLibrary:
    """Networks over a grid of target (α, μ) with ``per_cell`` seeds each."""

    def __init__(
        self,
        alphas: Iterable[float],
        mus: Iterable[float],
        per_cell: int = 1,
        n_fibers: int = 450,
        seed: int = 0,
        directory: str | Path | None = None,
    ):
        self.alphas = np.asarray(list(alphas), dtype=float)
        self.mus = np.asarray(list(mus), dtype=float)
        if self.alphas.size == 0 or self.mus.size == 0 or per_cell < 1:
            raise ValueError("NetworkLibrary: need at least one alpha, one mu and per_cell >= 1")
        self.per_cell, self.n_fibers, self.seed = int(per_cell), int(n_fibers), int(seed)
        self.directory = directory
        self._networks: dict[tuple[int, int, int], Network] = {}

    def get(self, i_alpha: int, i_mu: int, copy: int = 0) -> Network:
        key = (i_alpha, i_mu, copy)
        if key not in self._networks:
            seed = self.seed + copy
            self._networks[key] = cached_network(
                float(self.alphas[i_alpha]), float(self.mus[i_mu]), self.n_fibers, seed, self.directory
            )
        return self._networks[key]

    def nearest(self, alpha: float, mu: float, copy: int = 0) -> Network:
        """Network whose target is closest to (α, μ); μ compared axially (mod 180°)."""
        i_alpha = int(np.argmin(np.abs(self.alphas - alpha)))
        mu_distance = np.abs((self.mus - mu + 90.0) % 180.0 - 90.0)
        return self.get(i_alpha, int(np.argmin(mu_distance)), copy % self.per_cell)

    def build(self) -> int:
        """Generate (or load) every network of the grid; returns how many there are."""
        for i in range(self.alphas.size):
            for j in range(self.mus.size):
                for c in range(self.per_cell):
                    self.get(i, j, c)
        return len(self._networks)
