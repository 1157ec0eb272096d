r"""Uniaxial laws for one-dimensional elements (trusses, cables): nominal stress of the stretch.

A uniaxial law gives the nominal (first Piola–Kirchhoff) stress :math:`P(\lambda)` and its slope
:math:`dP/d\lambda` as functions of the axial stretch :math:`\lambda = l/L`. A truss of reference
cross-section :math:`A` carries the axial force :math:`N = A\,P(\lambda)` — the convention Abaqus
uses for hyperelastic trusses (force = original area x nominal stress), which stays exact for an
incompressible material whose current area is :math:`A/\lambda`.

**Incompressible Ogden in uniaxial stress.** With principal stretches
:math:`(\lambda, \lambda^{-1/2}, \lambda^{-1/2})` the Abaqus Ogden energy (mathur2022 Eq. 2,
:mod:`skvalve.materials.ogden`) is
:math:`W(\lambda) = \sum_i \tfrac{2\mu_i}{\alpha_i^2}(\lambda^{\alpha_i} + 2\lambda^{-\alpha_i/2} - 3)`, so

.. math::

    P = \frac{dW}{d\lambda} = \sum_i \frac{2\mu_i}{\alpha_i}\big(\lambda^{\alpha_i - 1}
        - \lambda^{-\alpha_i/2 - 1}\big), \qquad
    \frac{dP}{d\lambda} = \sum_i \frac{2\mu_i}{\alpha_i}\big((\alpha_i - 1)\lambda^{\alpha_i - 2}
        + (\tfrac{\alpha_i}{2} + 1)\lambda^{-\alpha_i/2 - 2}\big).

The small-strain Young's modulus is :math:`dP/d\lambda(1) = 3\sum_i\mu_i`. Terms with tiny
:math:`\alpha_i` (the septal chordae of the Texas TriValve have :math:`\alpha \approx 10^{-4}`) are
evaluated as :math:`\lambda^{-1}(\operatorname{expm1}(\alpha L) - \operatorname{expm1}(-\alpha L/2))/\alpha`,
:math:`L = \ln\lambda`, without cancellation. The compressibility :math:`D_i` of a 3D Ogden law does
not enter: in uniaxial stress the material is taken incompressible, as Abaqus does for hyperelastic
trusses.

**Tension only (cable).** :class:`TensionOnly` switches a law on in tension and keeps a small linear
slack spring in parallel at all stretches,

.. math::

    P = k_s(\lambda - \lambda_s) + w(\lambda)\,P_\text{law}(\max(\lambda, 1)),
    \qquad k_s = \varepsilon\,E_0, \qquad E_0 = \frac{dP_\text{law}}{d\lambda}(1),

with ``slack_fraction`` :math:`\varepsilon` (default :math:`10^{-4}`), the slack stretch
:math:`\lambda_s \le 1` at which the cable is force-free (default 1; a collapsed chordae chain uses its
reference end-to-end distance over its path length, so the model starts stress-free) and the switch
:math:`w = H(\lambda - 1)` (a step), or with ``transition`` :math:`\delta > 0` the C1 ramp
:math:`w = 3x^2 - 2x^3`, :math:`x = \operatorname{clip}((\lambda - 1)/\delta, 0, 1)`, which spreads the
jump of the slope from :math:`k_s` to :math:`k_s + E_0` over :math:`1 \le \lambda \le 1 + \delta` so that
Newton does not cycle across the kink. The stress is continuous either way. The slack spring keeps a
slack cable from being a zero-stiffness mechanism of an implicit solver while its force stays of order
:math:`\varepsilon E_0 A`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from .base import check_positive
from .ogden import Ogden

__all__ = ["UniaxialLaw", "OgdenUniaxial", "LinearUniaxial", "TensionOnly"]


@runtime_checkable
class UniaxialLaw(Protocol):
    """Anything with ``nominal_stress(stretch) -> (P, dP/dstretch)`` (arrays of the stretch's shape)."""

    def nominal_stress(self, stretch: ArrayLike) -> tuple[np.ndarray, np.ndarray]: ...


def _positive_stretch(stretch: ArrayLike, who: str) -> np.ndarray:
    stretch = np.asarray(stretch, dtype=float)
    if not np.all(np.isfinite(stretch)) or np.any(stretch <= 0.0):
        bad = np.flatnonzero(~(np.isfinite(stretch) & (stretch > 0.0)).ravel())[0]
        raise ValueError(f"{who}: stretch must be positive and finite; got {stretch.ravel()[bad]!r} at index {bad}")
    return stretch


def _ogden_bracket(x: np.ndarray) -> np.ndarray:
    """:math:`e^x + 2e^{-x/2} - 3` without cancellation: its Taylor series
    :math:`\\tfrac34x^2 + \\tfrac18x^3 + \\tfrac{3}{64}x^4 + \\tfrac{1}{128}x^5` where :math:`|x| < 10^{-3}`."""
    small = np.abs(x) < 1e-3
    series = x * x * (0.75 + x * (0.125 + x * (3.0 / 64.0 + x / 128.0)))
    return np.where(small, series, np.expm1(x) + 2.0 * np.expm1(-0.5 * x))


@dataclass(frozen=True)
class OgdenUniaxial:
    """Incompressible N-term Ogden law (Abaqus convention) in uniaxial stress.

    ``mu``, ``alpha``: the Abaqus Ogden parameters :math:`\\mu_i, \\alpha_i` (MPa, -).
    """

    mu: tuple[float, ...]
    alpha: tuple[float, ...]

    def __post_init__(self) -> None:
        law = Ogden(self.mu, self.alpha)  # validates lengths, finiteness, mu > 0, alpha != 0
        object.__setattr__(self, "mu", law.mu)
        object.__setattr__(self, "alpha", law.alpha)

    @classmethod
    def from_ogden(cls, law: Ogden) -> OgdenUniaxial:
        """The uniaxial response of a 3D :class:`~skvalve.materials.Ogden` law (its ``D`` is ignored)."""
        return cls(law.mu, law.alpha)

    @property
    def young_modulus(self) -> float:
        """Small-strain modulus :math:`dP/d\\lambda(1) = 3\\sum\\mu_i`."""
        return 3.0 * float(sum(self.mu))

    def nominal_stress(self, stretch: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Nominal stress :math:`P(\\lambda)` and :math:`dP/d\\lambda` (module docstring)."""
        lam = _positive_stretch(stretch, "OgdenUniaxial")
        log = np.log(lam)
        P = np.zeros_like(lam)
        dP = np.zeros_like(lam)
        for m, a in zip(self.mu, self.alpha, strict=True):
            c = 2.0 * m / a
            # lam^(a-1) - lam^(-a/2-1) = (expm1(a L) - expm1(-a L/2)) / lam, exact for small a
            P += c * (np.expm1(a * log) - np.expm1(-0.5 * a * log)) / lam
            dP += c * ((a - 1.0) * lam ** (a - 2.0) + (0.5 * a + 1.0) * lam ** (-0.5 * a - 2.0))
        return P, dP

    def energy(self, stretch: ArrayLike) -> np.ndarray:
        """Stored energy per reference volume :math:`W(\\lambda)` (module docstring), zero at :math:`\\lambda = 1`."""
        log = np.log(_positive_stretch(stretch, "OgdenUniaxial"))
        W = np.zeros_like(log)
        for m, a in zip(self.mu, self.alpha, strict=True):
            W += 2.0 * m / a**2 * _ogden_bracket(a * log)
        return W


@dataclass(frozen=True)
class LinearUniaxial:
    """Linear nominal stress :math:`P = E(\\lambda - 1)` (a reference law for tests and slack branches)."""

    modulus: float

    def __post_init__(self) -> None:
        check_positive("modulus", self.modulus)

    @property
    def young_modulus(self) -> float:
        return float(self.modulus)

    def nominal_stress(self, stretch: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        lam = _positive_stretch(stretch, "LinearUniaxial")
        return self.modulus * (lam - 1.0), np.full_like(lam, float(self.modulus))

    def energy(self, stretch: ArrayLike) -> np.ndarray:
        """:math:`W = E(\\lambda - 1)^2/2`."""
        lam = _positive_stretch(stretch, "LinearUniaxial")
        return 0.5 * self.modulus * (lam - 1.0) ** 2


@dataclass(frozen=True)
class TensionOnly:
    """A cable: ``law`` in tension plus a parallel slack spring ``slack_fraction * E0`` (module docstring)."""

    law: UniaxialLaw
    slack_fraction: float = 1e-4
    transition: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.law, UniaxialLaw):
            raise TypeError(f"law must have nominal_stress(stretch); got {type(self.law).__name__}")
        check_positive("slack_fraction", self.slack_fraction)
        if self.slack_fraction >= 1.0:
            raise ValueError(f"slack_fraction must be below 1; got {self.slack_fraction!r}")
        if not (np.isfinite(self.transition) and 0.0 <= self.transition < 1.0):
            raise ValueError(f"transition must lie in [0, 1); got {self.transition!r}")
        P1, E0 = self.law.nominal_stress(np.ones(1))
        if abs(float(P1[0])) > 1e-12 * max(abs(float(E0[0])), 1.0) or not float(E0[0]) > 0.0:
            raise ValueError("TensionOnly needs a law that is stress-free with a positive slope at stretch 1")
        object.__setattr__(self, "_slack_stiffness", self.slack_fraction * float(E0[0]))

    @property
    def slack_stiffness(self) -> float:
        """:math:`k_s = \\varepsilon\\,dP/d\\lambda(1)` (stress units)."""
        return self._slack_stiffness  # type: ignore[attr-defined]

    @property
    def young_modulus(self) -> float:
        return float(self.law.nominal_stress(np.ones(1))[1][0])

    def nominal_stress(self, stretch: ArrayLike, slack_stretch: ArrayLike = 1.0, scale: float = 1.0
                       ) -> tuple[np.ndarray, np.ndarray]:
        """:math:`P` and :math:`dP/d\\lambda`; ``slack_stretch`` :math:`\\lambda_s \\le 1` (broadcast); ``scale``
        multiplies the taut law only (a continuation that softens the cable keeps its slack spring)."""
        lam = _positive_stretch(stretch, "TensionOnly")
        lam_s = np.asarray(slack_stretch, dtype=float)
        if np.any(~(lam_s > 0.0) | (lam_s > 1.0)):
            raise ValueError("TensionOnly: slack_stretch must lie in (0, 1]")
        k = self.slack_stiffness
        Pl, dPl = self.law.nominal_stress(np.maximum(lam, 1.0))
        if self.transition > 0.0:
            x = np.clip((lam - 1.0) / self.transition, 0.0, 1.0)
            w, dw = x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x) / self.transition
        else:
            w, dw = (lam >= 1.0).astype(float), np.zeros_like(lam)
        P = k * (lam - lam_s) + scale * w * Pl
        dP = k + scale * (dw * Pl + w * dPl)
        return P, dP

    def energy(self, stretch: ArrayLike, slack_stretch: ArrayLike = 1.0, scale: float = 1.0) -> np.ndarray:
        r""":math:`W = \tfrac{k_s}{2}(\lambda - \lambda_s)^2 + \int_1^{\max(\lambda, 1)} w\,P_\text{law}\,d\lambda'`
        (the integral of :meth:`nominal_stress`): on the ramp :math:`1 \le \lambda' \le 1 + \delta` by 12-point
        Gauss–Legendre quadrature (exact to rounding for the smooth integrand on an interval of length
        :math:`\delta`), beyond it the law's own energy difference. Needs ``law.energy``."""
        lam = _positive_stretch(stretch, "TensionOnly")
        lam_s = np.asarray(slack_stretch, dtype=float)
        taut = np.maximum(lam, 1.0)
        W = 0.5 * self.slack_stiffness * (lam - lam_s) ** 2
        if self.transition == 0.0:
            return W + scale * self.law.energy(taut)
        top = 1.0 + self.transition
        ramp_end = np.minimum(taut, top)
        nodes, weights = np.polynomial.legendre.leggauss(12)
        half = 0.5 * (ramp_end - 1.0)
        points = 1.0 + half[..., None] * (nodes + 1.0)
        x = (points - 1.0) / self.transition
        integrand = x * x * (3.0 - 2.0 * x) * self.law.nominal_stress(points)[0]
        ramp = half * (integrand @ weights)
        beyond = self.law.energy(np.maximum(taut, top)) - self.law.energy(np.full_like(taut, top))
        return W + scale * (ramp + beyond)

