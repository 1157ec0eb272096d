r"""Bimodular incompressible neo-Hookean law (buchanan2014 Eq. 4).

buchanan2014 writes :math:`W^\pm = \tfrac{\mu^\pm}{2}(I_1 - 3) - p(I_3 - 1)`: the shear modulus
is :math:`\mu^+` where the material fibre along the unit direction :math:`a` is stretched
(tension) and :math:`\mu^-` where it is shortened (compression). Stored, like
:mod:`.incompressible_neo_hookean`, in isochoric form

.. math::

    \psi = \frac{\mu(\lambda_a)}{2}(\bar I_1 - 3), \qquad
    \lambda_a^2 = a\cdot C a, \qquad
    \mu(\lambda_a) = \begin{cases} \mu^+ & \lambda_a > 1 \text{ (tension)}\\
                                    \mu^- & \lambda_a \le 1 \text{ (compression or neutral)}\end{cases}

**Behaviour at the switch.** The selector is piecewise constant, so away from
:math:`\lambda_a = 1` stress and tangent are those of a neo-Hookean solid with the active
modulus (the selector contributes no derivative). Exactly at :math:`\lambda_a = 1`
(:math:`a\cdot Ca = 1` in floating point) the compressive branch :math:`\mu^-` is used;
energy and stress jump by :math:`\tfrac{\mu^+-\mu^-}{2}(\bar I_1-3)` resp. the matching
stress across the switch unless :math:`\bar I_1 = 3` (e.g. F = I, where both are zero), and
the tangent returned there is the one-sided (compressive) tangent. This is the model as
published; no smoothing is applied.

Pressure convention as :mod:`.incompressible_neo_hookean`: ``pk1``/``cauchy`` return the
pressure-free part, total :math:`\sigma = \sigma_\text{law} - pI`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..kinematics import Array
from .base import check_positive
from .isotropic import IsotropicInvariantLaw, Partials

__all__ = ["BimodularNeoHookean", "normalised_direction"]


def normalised_direction(direction: ArrayLike, name: str = "direction") -> Array:
    """Unit vectors of shape ``(3, *batch)`` or ``ValueError`` for bad shape, NaN or zero vectors."""
    a = np.array(direction, dtype=float)
    if a.ndim < 1 or a.shape[0] != 3:
        raise ValueError(f"parameter {name} must have shape (3,) or (3, *batch); got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"parameter {name} must be finite")
    norm = np.sqrt(np.sum(a**2, axis=0))
    if np.any(norm == 0.0):
        raise ValueError(f"parameter {name} contains a zero vector; it needs a non-zero direction")
    a = a / norm
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class BimodularNeoHookean(IsotropicInvariantLaw):
    """Neo-Hookean: ``mu_tension`` if the fibre along ``direction`` is stretched, else ``mu_compression``."""

    mu_tension: float
    mu_compression: float
    direction: Array

    incompressible = True

    def __post_init__(self) -> None:
        check_positive("mu_tension", self.mu_tension)
        check_positive("mu_compression", self.mu_compression)
        object.__setattr__(self, "direction", normalised_direction(self.direction))

    def fibre_stretch_squared(self, C: Array) -> Array:
        r""":math:`\lambda_a^2 = a\cdot Ca`, broadcasting the direction batch against C's batch."""
        a = self.direction
        if a.ndim > 1 and a.ndim - 1 > C.ndim - 2:
            raise ValueError(f"direction batch shape {a.shape[1:]} has more axes than the batch of F {C.shape[2:]}")
        try:
            return np.einsum("I...,IJ...,J...->...", a, C, a)
        except ValueError as err:
            raise ValueError(
                f"direction batch shape {a.shape[1:]} does not broadcast against the batch of F {C.shape[2:]}"
            ) from err

    def active_modulus(self, C: Array) -> Array:
        """The modulus in force at each point: ``mu_tension`` where λ_a > 1, else ``mu_compression``."""
        in_tension = self.fibre_stretch_squared(C) > 1.0
        return np.where(in_tension, self.mu_tension, self.mu_compression)

    def partials(self, I1bar: Array, J: Array, C: Array) -> Partials:
        mu = np.broadcast_to(self.active_modulus(C), np.shape(J))
        zero = np.zeros_like(J)
        return Partials(0.5 * mu * (I1bar - 3.0), 0.5 * mu, zero, zero, zero, zero)
