r"""Amplitudes: a load or prescribed value as a function of (step) time, as in Abaqus ``*Amplitude``.

An amplitude is given by points :math:`(t_i, A_i)` with increasing :math:`t_i`.

* :class:`SmoothStep` (``definition=SMOOTH STEP``): between consecutive points

  .. math::

      A(t) = A_i + (A_{i+1} - A_i)\,\xi^3(10 - 15\xi + 6\xi^2), \qquad
      \xi = \frac{t - t_i}{t_{i+1} - t_i},

  the quintic with :math:`A(t_i) = A_i`, :math:`A(t_{i+1}) = A_{i+1}` and zero first and second
  derivatives at both points, so loads start and stop without jerk.
* :class:`Tabular` (``definition=TABULAR``, the default): piecewise linear.

Both hold the first value before :math:`t_0` and the last value after :math:`t_n` (Abaqus's
behaviour for these definitions). Calling an amplitude with the solver's load factor ``t`` makes it a
``p(t)``/``value(t)`` callable for :class:`~skvalve.fem.loads.FollowerPressure` and Dirichlet values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["Amplitude", "SmoothStep", "Tabular", "GeometricRamp", "smooth_step_polynomial"]


def smooth_step_polynomial(xi: ArrayLike) -> np.ndarray:
    r""":math:`\xi^3(10 - 15\xi + 6\xi^2)` for :math:`\xi` clipped to [0, 1]."""
    xi = np.clip(np.asarray(xi, dtype=float), 0.0, 1.0)
    return xi**3 * (10.0 - 15.0 * xi + 6.0 * xi**2)


@dataclass(frozen=True)
class Amplitude:
    """Points ``times`` (strictly increasing) and ``values``; ``name`` for messages."""

    times: tuple[float, ...]
    values: tuple[float, ...]
    name: str = "amplitude"

    def __post_init__(self) -> None:
        times = np.atleast_1d(np.asarray(self.times, dtype=float))
        values = np.atleast_1d(np.asarray(self.values, dtype=float))
        if times.ndim != 1 or times.shape != values.shape or times.size == 0:
            raise ValueError(f"amplitude {self.name!r}: need as many times as values (>= 1); got "
                             f"{times.shape} and {values.shape}")
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(values))):
            raise ValueError(f"amplitude {self.name!r}: times and values must be finite")
        if np.any(np.diff(times) <= 0.0):
            raise ValueError(f"amplitude {self.name!r}: times must be strictly increasing; got {times.tolist()}")
        object.__setattr__(self, "times", tuple(times.tolist()))
        object.__setattr__(self, "values", tuple(values.tolist()))

    def _interval(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Index of the left point of each time's interval and the local coordinate xi in [0, 1]."""
        times = np.asarray(self.times)
        if times.size == 1:
            return np.zeros(t.shape, dtype=int), np.zeros(t.shape)
        i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
        xi = np.clip((t - times[i]) / (times[i + 1] - times[i]), 0.0, 1.0)
        return i, xi

    def _shape(self, xi: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def __call__(self, t: ArrayLike) -> float | np.ndarray:
        """The amplitude at time(s) ``t``."""
        t_arr = np.asarray(t, dtype=float)
        if not np.all(np.isfinite(t_arr)):
            raise ValueError(f"amplitude {self.name!r}: time must be finite; got {t!r}")
        values = np.asarray(self.values)
        if values.size == 1:
            out = np.full(t_arr.shape, values[0])
        else:
            i, xi = self._interval(t_arr)
            out = values[i] + (values[i + 1] - values[i]) * self._shape(xi)
        return float(out) if out.ndim == 0 else out


class SmoothStep(Amplitude):
    """Abaqus ``SMOOTH STEP`` amplitude (quintic between points, module docstring)."""

    def _shape(self, xi: np.ndarray) -> np.ndarray:
        return smooth_step_polynomial(xi)


class Tabular(Amplitude):
    """Abaqus ``TABULAR`` amplitude (linear between points)."""

    def _shape(self, xi: np.ndarray) -> np.ndarray:
        return xi


@dataclass(frozen=True)
class GeometricRamp:
    r"""A continuation factor from ``start`` to 1 between ``t_start`` and ``t_end``, smooth and geometric:

    .. math::

        s(t) = s_0^{\,1 - S(\xi)}, \qquad \xi = \frac{t - t_\text{start}}{t_\text{end} - t_\text{start}},

    with :math:`S` the smooth-step polynomial (:func:`smooth_step_polynomial`), so :math:`\ln s` moves from
    :math:`\ln s_0` to 0 without jumps in its first two derivatives (equal ratios per equal step near the
    middle); :math:`s = s_0` before ``t_start`` and 1 after ``t_end``.
    """

    start: float
    t_start: float
    t_end: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.start) and self.start > 0.0):
            raise ValueError(f"GeometricRamp: start must be positive and finite; got {self.start!r}")
        if not (np.isfinite(self.t_start) and np.isfinite(self.t_end) and self.t_end > self.t_start):
            raise ValueError(f"GeometricRamp: need t_start < t_end; got {self.t_start!r}, {self.t_end!r}")

    def __call__(self, t: float) -> float:
        xi = (t - self.t_start) / (self.t_end - self.t_start)
        return float(self.start ** (1.0 - float(smooth_step_polynomial(xi))))
