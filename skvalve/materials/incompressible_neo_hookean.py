r"""Incompressible neo-Hookean law (buchanan2014 Eq. 3).

buchanan2014 writes :math:`W = \tfrac{\mu}{2}(I_1 - 3) - p(I_3 - 1)`. Here the law is
stored in its isochoric form

.. math::

    \psi = \frac{\mu}{2}(\bar I_1 - 3), \qquad
    \sigma_\text{law} = \frac{\mu}{J}\,\operatorname{dev}\bar B ,

which equals Eq. 3 wherever :math:`J = 1` and differs from :math:`\mu F` only by a
hydrostatic term. **Convention**: ``pk1``/``cauchy`` return this pressure-free part
(zero at :math:`F = I`, trace-free Cauchy stress); the total stress is
:math:`\sigma = \sigma_\text{law} - p I` with :math:`p` the Lagrange multiplier of the
constraint :math:`J = 1`, found by the analytic solution or by a mixed u/p element.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import Array
from .base import check_positive
from .isotropic import IsotropicInvariantLaw, Partials

__all__ = ["IncompressibleNeoHookean"]


@dataclass(frozen=True)
class IncompressibleNeoHookean(IsotropicInvariantLaw):
    """Incompressible neo-Hookean solid with shear modulus ``mu``."""

    mu: float
    incompressible = True

    def __post_init__(self) -> None:
        check_positive("mu", self.mu)

    def partials(self, I1bar: Array, J: Array, C: Array) -> Partials:
        zero = np.zeros_like(J)
        return Partials(0.5 * self.mu * (I1bar - 3.0), 0.5 * self.mu + zero, zero, zero, zero, zero)
