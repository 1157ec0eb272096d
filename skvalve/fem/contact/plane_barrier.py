r"""The IPC barrier of surface vertices against fixed planes, in closed form.

ipctk 1.6.1 builds plane–vertex pairs only for distances below :math:`\hat d/2` (measured: a vertex at
:math:`0.8\,\hat d` from a plane gets no pair, at :math:`0.2\,\hat d` it does), so its barrier jumps from 0 to
:math:`b(\hat d^2/4) > 0` there: an energy with a step, which no line search can follow. A plane–vertex pair is simple
enough to write down: with :math:`d_i = (x_i - x_0)\cdot n` and :math:`s = d_i^2`,

.. math::

    B = \frac{\kappa}{\hat d^{\,3}} \sum_{d_i < \hat d} A_i\, b(s_i), \qquad
    \frac{\partial B}{\partial x_i} = \frac{\kappa A_i}{\hat d^{\,3}}\, 2 d_i\, b'(s_i)\, n, \qquad
    \frac{\partial^2 B}{\partial x_i^2} = \frac{\kappa A_i}{\hat d^{\,3}}\,\big(2 b'(s_i) + 4 s_i\, b''(s_i)\big)\,
    n\otimes n,

.. math::

    b(s) = -(s - \hat s)^2 \ln\frac{s}{\hat s}, \quad
    b'(s) = -2(s - \hat s)\ln\frac{s}{\hat s} - \frac{(s - \hat s)^2}{s}, \quad
    b''(s) = -2\ln\frac{s}{\hat s} - \frac{4(s - \hat s)}{s} + \frac{(s - \hat s)^2}{s^2},

(:math:`\hat s = \hat d^2`; the same area weight :math:`A_i` and physical scaling as ipctk's pairs, which it matches
where ipctk builds them). The PSD projection clamps the scalar curvature at 0. The collision-free step of a straight
move :math:`d_i \to d_i + \tau\,\Delta d_i` is the first :math:`\tau` at which some :math:`d_i` vanishes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .obstacles import Plane

__all__ = ["PlaneBarrier"]


@dataclass
class PlaneBarrier:
    """The barrier of collision vertices ``0..n-1`` (their area weights ``area``) against ``planes``."""

    planes: list[Plane]
    area: np.ndarray
    dhat: float

    def _distances(self, V: np.ndarray) -> list[np.ndarray]:
        return [plane.distance(V[: self.area.size]) for plane in self.planes]

    def energy(self, V: np.ndarray, stiffness: float) -> float:
        """:math:`B` at collision-vertex positions ``V`` (inf when a vertex is on or behind a plane)."""
        total = 0.0
        for d in self._distances(V):
            if np.any(d <= 0.0):
                return float("inf")
            near = d < self.dhat
            total += float(self.area[near] @ _b(d[near] ** 2, self.dhat ** 2))
        return stiffness * total / self.dhat ** 3

    def derivatives(self, V: np.ndarray, stiffness: float, hessian: bool):
        """Gradient (3 n_vertices,) and, when ``hessian``, the exact and the PSD-projected Hessians (sparse)."""
        n = V.shape[0]
        grad = np.zeros((n, 3))
        rows, cols, exact, clamped = [], [], [], []
        scale = stiffness / self.dhat ** 3
        sh = self.dhat ** 2
        for plane, d in zip(self.planes, self._distances(V), strict=True):
            near = np.flatnonzero(d < self.dhat)
            if near.size == 0:
                continue
            s = d[near] ** 2
            first, second = _b_derivatives(s, sh)
            weight = scale * self.area[near]
            grad[near] += (weight * 2.0 * d[near] * first)[:, None] * plane.normal
            if hessian:
                curvature = weight * (2.0 * first + 4.0 * s * second)
                nn = np.outer(plane.normal, plane.normal).ravel()
                dofs = 3 * near[:, None] + np.arange(3)
                rows.append(np.repeat(dofs, 3, axis=1).ravel())
                cols.append(np.tile(dofs, (1, 3)).ravel())
                exact.append((curvature[:, None] * nn).ravel())
                clamped.append((np.maximum(curvature, 0.0)[:, None] * nn).ravel())
        if not hessian:
            return grad.ravel(), None, None
        shape = (3 * n, 3 * n)
        if not rows:
            empty = sp.csc_matrix(shape)
            return grad.ravel(), empty, empty
        r, c = np.concatenate(rows), np.concatenate(cols)
        return (grad.ravel(), sp.csc_matrix((np.concatenate(exact), (r, c)), shape=shape),
                sp.csc_matrix((np.concatenate(clamped), (r, c)), shape=shape))

    def step_fraction(self, V0: np.ndarray, V1: np.ndarray) -> float:
        """The first share :math:`\\tau \\in (0, 1]` of the straight move ``V0 -> V1`` at which a vertex reaches a
        plane (1 when none does)."""
        fraction = 1.0
        for d0, d1 in zip(self._distances(V0), self._distances(V1), strict=True):
            crossing = d1 <= 0.0
            if np.any(crossing):
                fraction = min(fraction, float(np.min(d0[crossing] / (d0[crossing] - d1[crossing]))))
        return fraction


def _b(s: np.ndarray, sh: float) -> np.ndarray:
    return -((s - sh) ** 2) * np.log(s / sh)


def _b_derivatives(s: np.ndarray, sh: float) -> tuple[np.ndarray, np.ndarray]:
    log = np.log(s / sh)
    first = -2.0 * (s - sh) * log - (s - sh) ** 2 / s
    second = -2.0 * log - 4.0 * (s - sh) / s + (s - sh) ** 2 / s ** 2
    return first, second
