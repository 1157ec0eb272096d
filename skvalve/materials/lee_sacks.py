r"""Isotropic Lee–Sacks-type law of the Texas TriValve leaflets (mathur2022 Eq. 1).

What the Texas TriValve 1.0 leaflet subroutine (``VUANISO_ISO``, properties C0, D, C1, C2)
computes, and the default here:

.. math::

    \psi = \frac{c_0}{2}(\bar I_1 - 3) + \frac{c_1}{2}\Big(e^{c_2(\bar I_1 - 3)^2} - 1\Big)
         + \frac1D (J - 1)^2 .

mathur2022 Eq. 1 prints the exponent without the square, :math:`e^{c_2(I_1-3)}`; that variant
is ``published_equation=True``. **The published equation and the shipped model differ**:
for the same :math:`(c_0, c_1, c_2)` the small-strain shear modulus is :math:`c_0` for the
shipped model and :math:`c_0 + c_1 c_2` for the printed one. Both use :math:`\bar I_1` with
the volumetric penalty :math:`(J-1)^2/D` (bulk modulus :math:`K = 2/D`); ``D=None`` drops it
(incompressible, pressure convention of :mod:`.base`).

Partials with :math:`x = \bar I_1 - 3`, :math:`E = e^{c_2 x^2}` (shipped):
:math:`\psi_{,\bar I} = c_0/2 + c_1 c_2 x E`, :math:`\psi_{,\bar I\bar I} = c_1 c_2 E (1 + 2 c_2 x^2)`;
(printed, :math:`E = e^{c_2 x}`): :math:`\psi_{,\bar I} = c_0/2 + c_1 c_2 E/2`,
:math:`\psi_{,\bar I\bar I} = c_1 c_2^2 E/2`; and :math:`\psi_{,J} = 2(J-1)/D`, :math:`\psi_{,JJ} = 2/D`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import Array
from .base import VolumetricEnergy, check_nonnegative, check_positive
from .isotropic import IsotropicInvariantLaw, Partials

__all__ = ["LeeSacks"]


@dataclass(frozen=True)
class LeeSacks(IsotropicInvariantLaw):
    """Leaflet law ``c0/2 (Ī1-3) + c1/2 (exp(c2 (Ī1-3)^2) - 1) + (J-1)^2/D`` (Texas TriValve)."""

    c0: float
    c1: float
    c2: float
    D: float | None = None
    published_equation: bool = False

    def __post_init__(self) -> None:
        check_positive("c0", self.c0)
        check_nonnegative("c1", self.c1)
        check_nonnegative("c2", self.c2)
        if self.D is not None:
            check_positive("D", self.D)
        if not isinstance(self.published_equation, (bool, np.bool_)):
            raise ValueError(f"parameter published_equation must be True or False; got {self.published_equation!r}")

    @property
    def incompressible(self) -> bool:  # type: ignore[override]
        return self.D is None

    @property
    def shear_modulus(self) -> float:
        """Small-strain shear modulus: ``c0`` (shipped) or ``c0 + c1 c2`` (published Eq. 1)."""
        return self.c0 + (self.c1 * self.c2 if self.published_equation else 0.0)

    @property
    def bulk_modulus(self) -> float:
        return 2.0 / self.D if self.D is not None else float("inf")

    def partials(self, I1bar: Array, J: Array, C: Array) -> Partials:
        c0, c1, c2 = self.c0, self.c1, self.c2
        x = I1bar - 3.0
        with np.errstate(over="ignore"):  # beyond exp's range the energy is +inf: a line search rejects that state
            return self._partials(c0, c1, c2, x, J)

    def _partials(self, c0: float, c1: float, c2: float, x: Array, J: Array) -> Partials:
        if self.published_equation:
            E = np.exp(c2 * x)
            psi = 0.5 * c0 * x + 0.5 * c1 * (E - 1.0)
            d_I = 0.5 * c0 + 0.5 * c1 * c2 * E
            d_II = 0.5 * c1 * c2**2 * E
        else:
            E = np.exp(c2 * x**2)
            psi = 0.5 * c0 * x + 0.5 * c1 * np.expm1(c2 * x**2)
            d_I = 0.5 * c0 + c1 * c2 * x * E
            d_II = c1 * c2 * E * (1.0 + 2.0 * c2 * x**2)
        zero = np.zeros_like(J)
        if self.D is None:
            return Partials(psi, d_I, zero, d_II, zero, zero)
        psi = psi + (J - 1.0) ** 2 / self.D
        return Partials(psi, d_I, 2.0 * (J - 1.0) / self.D, d_II, zero, 2.0 / self.D + zero)

    def split(self) -> tuple[LeeSacks, VolumetricEnergy | None]:
        """``(isochoric part, VolumetricEnergy(2/D, "quadratic"))``; ``(self, None)`` if incompressible."""
        if self.D is None:
            return self, None
        return LeeSacks(self.c0, self.c1, self.c2, None, self.published_equation), VolumetricEnergy(2.0 / self.D)
