"""Seeded, cached library of networks over an α/μ grid (Thomas 2019 section 2.3, "library of
network files").  Each network is generated once by :func:`generate` and stored as ``.npz``
in a user cache directory (``$SKVALVE_CACHE/networks`` if set, else ``~/.cache/skvalve/networks``),
never inside the package.  File names encode every generation input (α and μ to 0.01; the exact
targets are checked against the stored metadata), so a cache hit returns exactly what ``generate``
returns, metadata types included.

Concurrency and damage.  A network is written to a uniquely named temporary file in the cache
folder and moved over the final name with an atomic ``os.replace``: concurrent writers of the
same network (parallel workers building one library) each publish a complete file, the last
one wins, and readers never see a partial file.  A cache file that cannot be read as a network
(empty, truncated, not a zip archive, arrays missing or malformed) is regenerated and replaced,
with a :class:`CacheWarning` naming the file; it is never unpickled (``allow_pickle=False``).
"""

from __future__ import annotations

import os
import tempfile
import warnings
import zipfile
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from skvalve.networks.generate import check_request, generate
from skvalve.networks.network import Network

FORMAT_VERSION = 2  # 2: metadata stored with its types


class CacheWarning(UserWarning):
    """A network cache file was unreadable and has been regenerated."""


def cache_dir() -> Path:
    """Default network cache: $SKVALVE_CACHE/networks or ~/.cache/skvalve/networks."""
    root = os.environ.get("SKVALVE_CACHE")
    base = Path(root) if root else Path.home() / ".cache" / "skvalve"
    return base / "networks"


def network_file(alpha: float, mu: float, n_fibers: int, seed: int) -> str:
    """Cache file name of one generation request (α, μ rounded to 0.01 in the name only)."""
    return f"net_v{FORMAT_VERSION}_a{alpha:06.2f}_m{mu:+07.2f}_n{n_fibers}_s{seed}.npz"


def _reason(err: Exception) -> str:
    """A short cause without library internals (no zip/pickle/EOF jargon)."""
    if isinstance(err, KeyError):
        return f"no array {err}"
    if isinstance(err, (zipfile.BadZipFile, EOFError)) or "pickle" in str(err):
        return "empty, truncated or of another format"
    return str(err).splitlines()[0][:120] if str(err) else "unreadable"


def _read(path: Path, alpha: float, mu: float) -> Network | None:
    """The cached network at ``path`` if it is readable and made for exactly (α, μ); else None."""
    try:
        cached = Network.load(path)
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as err:
        warnings.warn(
            f"network cache file {path} is damaged or not a network file ({_reason(err)}); regenerating it",
            CacheWarning,
            stacklevel=3,
        )
        return None
    # the file name rounds α and μ to 0.01: serve the file only if it was made for these exact targets
    if cached.meta.get("alpha_target") == float(alpha) and cached.meta.get("mu_target") == float(mu):
        return cached
    return None


def _write_atomically(network: Network, path: Path) -> None:
    """Save to a unique temporary file next to ``path``, then ``os.replace`` it onto ``path``."""
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.stem + ".", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            network.save(stream)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def cached_network(
    alpha: float, mu: float, n_fibers: int, seed: int = 0, directory: str | Path | None = None
) -> Network:
    """Load the network for (α, μ, n_fibers, seed) from the cache, generating it if missing.

    Parameters are those of :func:`~skvalve.networks.generate.generate` (checked before any file
    access); ``directory`` defaults to :func:`cache_dir`.
    """
    check_request(n_fibers, seed)
    folder = Path(directory) if directory is not None else cache_dir()
    path = folder / network_file(alpha, mu, n_fibers, seed)
    cached = _read(path, alpha, mu)
    if cached is not None:
        return cached
    network = generate(alpha, mu, n_fibers=n_fibers, seed=seed)
    folder.mkdir(parents=True, exist_ok=True)
    _write_atomically(network, path)
    return network


class NetworkLibrary:
    """Networks over a grid of target (α, μ) with ``per_cell`` seeds each, ``n_fibers`` fibers each."""

    def __init__(
        self,
        alphas: Iterable[float],
        mus: Iterable[float],
        per_cell: int = 1,
        *,
        n_fibers: int,
        seed: int = 0,
        directory: str | Path | None = None,
    ):
        self.alphas = np.asarray(list(alphas), dtype=float)
        self.mus = np.asarray(list(mus), dtype=float)
        if self.alphas.size == 0 or self.mus.size == 0 or per_cell < 1:
            raise ValueError("NetworkLibrary: need at least one alpha, one mu and per_cell >= 1")
        check_request(n_fibers, seed)
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
