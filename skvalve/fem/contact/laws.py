r"""Contact pressure laws :math:`p(h)` of an overlap :math:`h \ge 0` and their energies :math:`\psi`, :math:`\psi' = p`.

* :func:`rounded_penalty`: the penalty :math:`\varepsilon h` rounded over its first :math:`h_0`,

  .. math::

      p(h) = \begin{cases} \varepsilon h^2/(2h_0) & 0 < h < h_0 \\ \varepsilon(h - h_0/2) & h \ge h_0 \end{cases},

  so that force and stiffness are continuous when a pair switches on.
* :func:`depth_barrier`: a barrier that adds nothing above :math:`h_s` and whose pressure grows without bound as the
  overlap approaches a floor :math:`h_f`. With the clearance :math:`r = h_f - h` and :math:`\hat r = h_f - h_s`,

  .. math::

      \psi_b(h) = -\varepsilon\,(r - \hat r)^2 \ln\frac{r}{\hat r}, \qquad 0 < r < \hat r ,

  the log barrier of incremental potential contact (Li et al., ACM Trans. Graph. 39(4), 2020, Eq. 6) measured
  from the floor instead of from touching, :math:`C^2` at :math:`h_s` (value, slope and curvature vanish there).
  Its pressure is :math:`\varepsilon(2(r-\hat r)\ln(r/\hat r) + (r-\hat r)^2/r) \approx \varepsilon\hat r^2/r` near the
  floor, so a force that presses a node into a sheet is met before the node reaches the floor. The floor lies just
  past the clearance limit's (:mod:`~skvalve.fem.contact.clearance`), which no guarded step crosses. Past the cutoff
  :math:`r_c = 10^{-2}\hat r` (about :math:`100\,\varepsilon\hat r` of pressure) the pressure falls smoothly to zero by
  the start of the deep fade (``saturate``) and the energy stays at the value it has there: finite at every state,
  never a NaN, and bounded, for the pairs the clearance limit does not guard (already that deep when the contact
  switches on, or deep past a free edge), which the fade then lets go; an unbounded continuation there made the fade
  pull those nodes through with newtons (209 N of residual on the 1.0 valve).

Why the barrier: with the penalty alone, a force greater than about :math:`\varepsilon h_f A` on a node of tributary
area :math:`A` holds the node at the floor of the clearance limit, the step's model (which does not see the floor) keeps
proposing to go deeper, and every further step stops there (two soft blocks show it: ``tests/test_contact_laws.py``).
"""

from __future__ import annotations

import numpy as np

from .geometry import smooth_step

__all__ = ["BARRIER_CUTOFF", "depth_barrier", "rounded_penalty"]

#: Past the clearance r = BARRIER_CUTOFF r_hat the barrier's pressure stops rising and falls to zero by ``saturate``.
BARRIER_CUTOFF = 1e-2


def rounded_penalty(overlap: np.ndarray, penalty: float, smoothing: float):
    """Energy per area psi, pressure p and dp/dh of the rounded penalty at overlaps ``h`` >= 0 (module docstring)."""
    h, h0 = np.asarray(overlap, dtype=float), float(smoothing)
    if h0 == 0.0:
        return 0.5 * penalty * h**2, penalty * h, np.full_like(h, penalty)
    rounded = h < h0
    energy = np.where(rounded, penalty * h**3 / (6.0 * h0), penalty * (0.5 * h**2 - 0.5 * h0 * h + h0**2 / 6.0))
    pressure = np.where(rounded, penalty * h**2 / (2.0 * h0), penalty * (h - 0.5 * h0))
    stiffness = np.where(rounded, penalty * h / h0, penalty)
    return energy, pressure, stiffness


def _log_barrier(r: np.ndarray, width: float):
    """B(r) = -(r - w)^2 ln(r / w) for 0 < r < w (zero above) and its first two derivatives in r."""
    r = np.minimum(r, width)
    d, log = r - width, np.log(r / width)
    value = -d**2 * log
    first = -2.0 * d * log - d**2 / r
    second = -2.0 * log - 4.0 * d / r + d**2 / r**2
    return value, first, second


def depth_barrier(overlap: np.ndarray, penalty: float, start: float, floor: float, saturate: float):
    """Energy per area, pressure and dp/dh of the depth barrier (module docstring) at overlaps ``h`` >= 0: zero for
    ``h`` <= ``start``, growing without bound towards ``floor`` up to the cutoff, past which the pressure falls
    smoothly to zero by ``saturate`` and the energy stays at its value there."""
    if not 0.0 <= start < floor < saturate:
        raise ValueError(f"contact barrier: need 0 <= start < floor < saturate; got start {start!r}, floor {floor!r}, "
                         f"saturate {saturate!r}")
    h = np.asarray(overlap, dtype=float)
    width = floor - start
    cutoff = floor - BARRIER_CUTOFF * width
    value, first, second = _log_barrier(np.maximum(floor - h, BARRIER_CUTOFF * width), width)
    energy, pressure, stiffness = penalty * value, -penalty * first, penalty * second  # dr/dh = -1
    # past the cutoff: p = p_c (1 - S(t)), t = (h - h_c)/w, whose integral is p_c (h - h_c - w I(t)), I = int_0^t S
    fall = saturate - cutoff
    t = np.maximum(h - cutoff, 0.0) / fall
    past = t > 0.0
    step, slope, _ = smooth_step(t)
    tc = np.minimum(t, 1.0)
    integral = tc**4 * (2.5 + tc * (-3.0 + tc)) + np.maximum(t - 1.0, 0.0)
    energy = np.where(past, energy + pressure * fall * (t - integral), energy)
    stiffness = np.where(past, -pressure * slope / fall, stiffness)
    pressure = np.where(past, pressure * (1.0 - step), pressure)
    return energy, pressure, stiffness
