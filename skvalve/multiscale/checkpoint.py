"""Resumable FE² runs: every converged load step written atomically with the RVE states.

:class:`Checkpoint` is a solver callback. After each converged step it writes one ``.npz`` with the
load factor, the macro solution vector, the committed RVE state of the material
(:class:`~skvalve.multiscale.material.RVEMaterialState`: cross-link positions, F, dx/dF, fiber
stretches) and any extra arrays (e.g. a protocol's edge-displacement schedule), under a temporary
name then renamed, so an interruption never leaves a partial file. :func:`resume` loads the file
into a material built on the same networks and returns ``(u0, t0)`` for :func:`skvalve.fem.solve`;
since every RVE solve is a function of the committed state and F, the resumed run repeats the
uninterrupted one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..io.files import replace_atomically
from .material import RVEMaterial, RVEMaterialState

__all__ = ["Checkpoint", "CheckpointData", "load_checkpoint", "resume"]

_STATE = ("positions", "F", "sensitivity", "fiber_stretch")


@dataclass
class CheckpointData:
    """A checkpoint's content."""

    step: int
    load_factor: float
    u: np.ndarray
    state: RVEMaterialState
    extra: dict[str, np.ndarray]


class Checkpoint:
    """Solver callback writing ``path`` (``.npz``) after every converged step.

    Parameters
    ----------
    path : the checkpoint file (overwritten at each step; the last converged step wins).
    material : the RVE material whose committed state is stored.
    extra : optional callable returning a dict of arrays to store with each step.
    """

    def __init__(self, path, material: RVEMaterial, extra=None) -> None:
        self.path = Path(path)
        if self.path.suffix != ".npz":
            raise ValueError(f"Checkpoint: path must end in .npz, got {self.path}")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.material, self.extra = material, extra
        self.written = 0

    def __call__(self, event) -> None:
        state = self.material.state()
        arrays = {name: getattr(state, name) for name in _STATE}
        extra = {} if self.extra is None else dict(self.extra())
        for key in extra:
            if key in arrays or key in ("u", "step", "load_factor"):
                raise ValueError(f"Checkpoint: extra array name {key!r} is reserved")
        arrays.update({f"extra_{key}": np.asarray(value) for key, value in extra.items()})
        replace_atomically(self.path, lambda p: np.savez(p, u=event.u, step=event.step,
                                                         load_factor=event.load_factor, **arrays))
        self.written += 1


def load_checkpoint(path) -> CheckpointData:
    """Read a file written by :class:`Checkpoint`."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no checkpoint at {path}")
    with np.load(path) as data:
        missing = [name for name in ("u", "step", "load_factor", *_STATE) if name not in data.files]
        if missing:
            raise ValueError(f"{path} is not an FE² checkpoint (missing {missing})")
        state = RVEMaterialState(*(np.array(data[name]) for name in _STATE))
        extra = {name[len("extra_"):]: np.array(data[name]) for name in data.files if name.startswith("extra_")}
        return CheckpointData(int(data["step"]), float(data["load_factor"]), np.array(data["u"]), state, extra)


def resume(material: RVEMaterial, path) -> tuple[np.ndarray, float, CheckpointData]:
    """Load ``path`` into ``material``; returns (u0, t0, data) to continue with ``solve(..., u0=, t0=)``."""
    data = load_checkpoint(path)
    material.set_state(data.state)
    return data.u, data.load_factor, data
