r"""Compressible neo-Hookean law in the Bonet & Wood form.

.. math::

    \psi = \frac{\mu}{2}(I_1 - 3) - \mu \ln J + \frac{\lambda}{2} (\ln J)^2,
    \qquad
    \sigma = \frac{\mu}{J}(B - I) + \frac{\lambda \ln J}{J} I,

the Cauchy stress being thomas2019 Eq. 10 (and Eq. 13 in principal form). In the
small-strain limit it is linear elasticity with Lamé constants :math:`(\lambda, \mu)`.
Written in :math:`(\bar I_1, J)` with :math:`I_1 = J^{2/3}\bar I_1`:
:math:`\psi_{,\bar I} = \tfrac{\mu}{2}J^{2/3}`,
:math:`\psi_{,J} = \tfrac{\mu}{3}\bar I_1 J^{-1/3} - \tfrac{\mu}{J} + \tfrac{\lambda\ln J}{J}`,
:math:`\psi_{,\bar I J} = \tfrac{\mu}{3}J^{-1/3}`,
:math:`\psi_{,JJ} = -\tfrac{\mu}{9}\bar I_1 J^{-4/3} + \tfrac{\mu}{J^2} + \tfrac{\lambda(1-\ln J)}{J^2}`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import Array
from .base import VolumetricEnergy, check_positive, check_scalar
from .isotropic import IsotropicInvariantLaw, Partials

__all__ = ["NeoHookean", "lame_from_shear_poisson"]


def lame_from_shear_poisson(G: float, nu: float) -> tuple[float, float]:
    r"""Lamé constants :math:`(\mu, \lambda) = (G, 2G\nu/(1-2\nu))`; needs :math:`-1<\nu<1/2`."""
    G = check_positive("G", G)
    nu = check_scalar("nu", nu)
    if not (-1.0 < nu < 0.5):
        raise ValueError(f"parameter nu (Poisson's ratio) must lie in (-1, 0.5); got {nu!r}")
    return G, 2.0 * G * nu / (1.0 - 2.0 * nu)


@dataclass(frozen=True)
class NeoHookean(IsotropicInvariantLaw):
    """Compressible neo-Hookean solid with shear modulus ``mu`` and Lamé constant ``lmbda``."""

    mu: float
    lmbda: float

    def __post_init__(self) -> None:
        check_positive("mu", self.mu)
        check_scalar("lmbda", self.lmbda)
        # A negative lambda is admissible down to nu > -1, i.e. lambda > -2 mu / 3.
        if not (np.isfinite(self.lmbda) and self.lmbda > -2.0 * self.mu / 3.0):
            raise ValueError(f"parameter lmbda must exceed -2 mu / 3 (positive bulk modulus); got {self.lmbda!r}")

    @classmethod
    def from_shear_poisson(cls, G: float, nu: float) -> NeoHookean:
        """Build from shear modulus ``G`` and Poisson's ratio ``nu`` (thomas2019: G, ν)."""
        mu, lmbda = lame_from_shear_poisson(G, nu)
        return cls(mu=mu, lmbda=lmbda)

    @property
    def poisson_ratio(self) -> float:
        return self.lmbda / (2.0 * (self.lmbda + self.mu))

    @property
    def bulk_modulus(self) -> float:
        """Small-strain bulk modulus :math:`\\lambda + 2\\mu/3`."""
        return self.lmbda + 2.0 * self.mu / 3.0

    def partials(self, I1bar: Array, J: Array, C: Array) -> Partials:
        mu, lm = self.mu, self.lmbda
        lnJ = np.log(J)
        J13 = np.cbrt(J)
        psi = 0.5 * mu * (J13**2 * I1bar - 3.0) - mu * lnJ + 0.5 * lm * lnJ**2
        d_I = 0.5 * mu * J13**2
        d_J = mu / 3.0 * I1bar / J13 - mu / J + lm * lnJ / J
        d_II = np.zeros_like(J)
        d_IJ = mu / 3.0 / J13
        d_JJ = -mu / 9.0 * I1bar / J13**4 + mu / J**2 + lm * (1.0 - lnJ) / J**2
        return Partials(psi, d_I, d_J, d_II, d_IJ, d_JJ)

    def split(self) -> tuple[NeoHookean, VolumetricEnergy | None]:
        r"""Rest :math:`\tfrac{\mu}{2}(I_1-3) - \mu\ln J` plus :math:`U = \tfrac{\lambda}{2}(\ln J)^2`."""
        if self.lmbda <= 0.0:
            return self, None
        return NeoHookean(self.mu, 0.0), VolumetricEnergy(self.lmbda, "log")
