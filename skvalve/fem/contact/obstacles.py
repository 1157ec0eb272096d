r"""Kinematic obstacles for barrier contact: surfaces whose motion is prescribed, and fixed planes.

An :class:`Obstacle` is a triangulated surface whose vertices move with the load factor, :math:`y(t) = Y + w(t)`
(rigid clip arms closing on a leaflet, a punch, a moving wall); it carries no degrees of freedom, so the solver
never changes it, but the collision-free step of :class:`~skvalve.fem.contact.ipc.IPCContact` follows it along the
straight path :math:`y(t_0) \to y(t_1)` of each step. A :class:`Plane` is an unbounded fixed half-space boundary
(:math:`(x - x_0)\cdot n \ge 0` is free space); ipctk treats it exactly (plane–vertex pairs only).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Obstacle", "Plane"]


@dataclass
class Obstacle:
    """A triangulated surface with prescribed motion.

    Parameters
    ----------
    vertices : (n, 3) reference positions.
    triangles : (m, 3) vertex indices; the side the body is on does not matter (the barrier acts on distances).
    motion : ``t -> (n, 3)`` displacement of the vertices at load factor ``t`` (``None``: fixed).
    name : shown in error messages.
    active_from : load factor from which the body collides with it; before, the body may overlap it (a clip arm
        parked where the leaflets close, in contact only once they have reopened). At ``active_from`` the body must
        be clear of it (:class:`~skvalve.fem.contact.ipc.IPCContact` refuses an intersecting state).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    motion: Callable[[float], np.ndarray] | None = None
    name: str = "obstacle"
    active_from: float = 0.0

    def __post_init__(self) -> None:
        self.vertices = np.array(self.vertices, dtype=float)
        self.triangles = np.array(self.triangles, dtype=np.int64)
        if self.vertices.ndim != 2 or self.vertices.shape[1] != 3 or self.vertices.shape[0] < 3:
            raise ValueError(f"obstacle {self.name!r}: vertices must have shape (n >= 3, 3); got {self.vertices.shape}")
        if not np.all(np.isfinite(self.vertices)):
            raise ValueError(f"obstacle {self.name!r}: vertices must be finite")
        if self.triangles.ndim != 2 or self.triangles.shape[1] != 3 or self.triangles.shape[0] == 0:
            raise ValueError(f"obstacle {self.name!r}: triangles must have shape (m > 0, 3); got "
                             f"{self.triangles.shape}")
        if not np.isfinite(self.active_from):
            raise ValueError(f"obstacle {self.name!r}: active_from must be finite; got {self.active_from!r}")
        if self.triangles.min() < 0 or self.triangles.max() >= self.vertices.shape[0]:
            raise ValueError(f"obstacle {self.name!r}: triangle vertex indices must lie in "
                             f"0..{self.vertices.shape[0] - 1}")

    def at(self, t: float) -> np.ndarray:
        """Vertex positions (n, 3) at load factor ``t``."""
        if self.motion is None:
            return self.vertices.copy()
        w = np.asarray(self.motion(float(t)), dtype=float)
        if w.shape != self.vertices.shape:
            raise ValueError(f"obstacle {self.name!r}: motion({t!r}) returned shape {w.shape}; expected "
                             f"{self.vertices.shape}")
        if not np.all(np.isfinite(w)):
            raise ValueError(f"obstacle {self.name!r}: motion({t!r}) is not finite")
        return self.vertices + w

    @classmethod
    def rigid(cls, vertices: np.ndarray, triangles: np.ndarray, translation: Callable[[float], np.ndarray],
              rotation: Callable[[float], np.ndarray] | None = None, centre: np.ndarray | None = None,
              name: str = "obstacle", active_from: float = 0.0) -> Obstacle:
        r"""A rigid body: :math:`y(t) = c + R(t)(Y - c) + a(t)` with ``translation`` :math:`a(t)` (3,) and
        ``rotation`` :math:`R(t)` (3, 3) about ``centre`` :math:`c` (default the vertices' mean)."""
        Y = np.array(vertices, dtype=float)
        c = Y.mean(axis=0) if centre is None else np.asarray(centre, dtype=float)

        def motion(t: float) -> np.ndarray:
            R = np.eye(3) if rotation is None else np.asarray(rotation(t), dtype=float)
            return (Y - c) @ R.T + c + np.asarray(translation(t), dtype=float) - Y

        return cls(Y, triangles, motion, name, active_from)

    @classmethod
    def rectangle(cls, centre, normal, size: float, divisions: int = 1,
                  motion: Callable[[float], np.ndarray] | None = None, name: str = "rectangle") -> Obstacle:
        """A square of side ``size`` centred at ``centre`` normal to ``normal``, split into ``divisions``² quads of
        two triangles; ``motion(t)`` a (3,) translation (``None``: fixed)."""
        centre = np.asarray(centre, dtype=float)
        n = np.asarray(normal, dtype=float)
        n = n / np.linalg.norm(n)
        helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        e1 = np.cross(n, helper)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        s = np.linspace(-0.5 * size, 0.5 * size, divisions + 1)
        a, b = np.meshgrid(s, s, indexing="ij")
        vertices = centre + a.reshape(-1, 1) * e1 + b.reshape(-1, 1) * e2
        index = np.arange(vertices.shape[0]).reshape(divisions + 1, divisions + 1)
        p, q, r, w = index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel()
        triangles = np.concatenate([np.stack([p, q, r], axis=1), np.stack([p, r, w], axis=1)])
        if motion is None:
            return cls(vertices, triangles, None, name)
        return cls.rigid(vertices, triangles, motion, name=name)


@dataclass
class Plane:
    """A fixed plane through ``point`` with unit ``normal`` pointing to the free side."""

    point: np.ndarray
    normal: np.ndarray
    name: str = field(default="plane")

    def __post_init__(self) -> None:
        self.point = np.array(self.point, dtype=float).ravel()
        normal = np.array(self.normal, dtype=float).ravel()
        if self.point.shape != (3,) or normal.shape != (3,) or not np.all(np.isfinite(np.r_[self.point, normal])):
            raise ValueError(f"plane {self.name!r}: point and normal must be 3 finite numbers each")
        length = float(np.linalg.norm(normal))
        if not length > 0.0:
            raise ValueError(f"plane {self.name!r}: the normal must not vanish")
        self.normal = normal / length

    def distance(self, x: np.ndarray) -> np.ndarray:
        """Signed distances (n,) of points ``x`` (n, 3) from the plane (positive on the free side)."""
        return (np.asarray(x, dtype=float) - self.point) @ self.normal
