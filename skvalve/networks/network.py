"""The fiber-network container shared by the generator, the orientation tools and the RVE solver.

A network lives in the undeformed, dimensionless RVE: the cube [−½, ½]³ (unit volume,
Thomas et al. 2019 section 2.3).  Nodes on the cube faces are *boundary* cross-links that
follow the macroscopic deformation; the others are free *interior* cross-links.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

import numpy as np

FACE_NAMES = ("-x", "+x", "-y", "+y", "-z", "+z")
INTERIOR = -1


def _text(value, kind: str) -> str:
    """Metadata value as text that parses back exactly (repr keeps every bit of a float)."""
    return repr(float(value)) if kind == "float" else str(int(value)) if kind == "int" else str(value)


@dataclass
class Network:
    """Fibers between cross-links in the unit RVE.

    nodes : (n, 3) reference positions in [−½, ½]³.
    fibers : (m, 2) node indices of each straight fiber.
    boundary : (n,) True for cross-links on the RVE faces.
    face : (n,) face index 0..5 in the order of ``FACE_NAMES`` (−1 for interior nodes).
    meta : free-form generation data (target α, μ, stretch, seed, ...).
    """

    nodes: np.ndarray
    fibers: np.ndarray
    boundary: np.ndarray
    face: np.ndarray
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.nodes = np.ascontiguousarray(self.nodes, dtype=float)
        self.fibers = np.ascontiguousarray(self.fibers, dtype=np.int64)
        self.boundary = np.ascontiguousarray(self.boundary, dtype=bool)
        self.face = np.ascontiguousarray(self.face, dtype=np.int64)
        n = len(self.nodes)
        if self.nodes.ndim != 2 or self.nodes.shape[1] != 3:
            raise ValueError(f"Network.nodes must have shape (n, 3), got {self.nodes.shape}")
        if not np.all(np.isfinite(self.nodes)):
            raise ValueError("Network.nodes must be finite (found NaN or inf)")
        if self.fibers.ndim != 2 or self.fibers.shape[1] != 2:
            raise ValueError(f"Network.fibers must have shape (m, 2), got {self.fibers.shape}")
        if self.boundary.shape != (n,) or self.face.shape != (n,):
            raise ValueError("Network.boundary and Network.face must have shape (n,)")
        if self.fibers.size and (self.fibers.min() < 0 or self.fibers.max() >= n):
            raise ValueError("Network.fibers refers to a node index outside 0..n-1")
        if np.any(self.fibers[:, 0] == self.fibers[:, 1]):
            raise ValueError("Network.fibers contains a fiber from a node to itself")

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_fibers(self) -> int:
        return len(self.fibers)

    def fiber_vectors(self, positions: np.ndarray | None = None) -> np.ndarray:
        """End-to-end vectors x_b − x_a of every fiber (reference positions by default)."""
        x = self.nodes if positions is None else positions
        return x[self.fibers[:, 1]] - x[self.fibers[:, 0]]

    def fiber_lengths(self, positions: np.ndarray | None = None) -> np.ndarray:
        return np.linalg.norm(self.fiber_vectors(positions), axis=1)

    @property
    def total_length(self) -> float:
        """Dimensionless total fiber length L of Eqs. 6–8."""
        return float(self.fiber_lengths().sum())

    def save(self, path: str | Path | BinaryIO) -> None:
        """Store as a compressed ``.npz`` (a path or a binary stream); meta values must be bool,
        int, float or str and come back with their types from :meth:`load`."""
        kinds = {bool: "bool", int: "int", float: "float", str: "str"}
        meta_types = []
        for key, value in self.meta.items():
            kind = next((name for cls, name in kinds.items() if type(value) is cls), None)
            if kind is None:
                kind = "int" if isinstance(value, np.integer) else "float" if isinstance(value, np.floating) else None
            if kind is None:
                raise TypeError(f"Network.save: meta[{key!r}] must be bool, int, float or str, got {type(value)}")
            meta_types.append(kind)
        np.savez_compressed(
            path,
            nodes=self.nodes,
            fibers=self.fibers,
            boundary=self.boundary,
            face=self.face,
            meta_keys=np.array(list(self.meta.keys()), dtype=str),
            meta_values=np.array([_text(v, t) for v, t in zip(self.meta.values(), meta_types, strict=True)], dtype=str),
            meta_types=np.array(meta_types, dtype=str),
        )

    @classmethod
    def load(cls, path: str | Path) -> Network:
        """Read a file written by :meth:`save` (never unpickles: ``allow_pickle=False``).

        Raises ValueError/KeyError/OSError (or zipfile.BadZipFile, EOFError) for a file that is
        not such a network.
        """
        parse = {"bool": lambda v: v == "True", "int": int, "float": float, "str": str}
        with np.load(path, allow_pickle=False) as data:
            if not hasattr(data, "files"):
                raise ValueError(f"{path}: not an .npz archive")
            keys, values = data["meta_keys"], data["meta_values"]
            types = data["meta_types"] if "meta_types" in data.files else np.array(["float"] * len(keys))
            meta = {}
            for key, value, kind in zip(keys, values, types, strict=True):
                if str(kind) not in parse:
                    raise ValueError(f"{path}: unknown metadata type {kind!r}")
                meta[str(key)] = parse[str(kind)](str(value))
            return cls(data["nodes"], data["fibers"], data["boundary"], data["face"], meta)
