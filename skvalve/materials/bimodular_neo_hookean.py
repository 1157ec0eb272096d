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
published (``smoothing = 0``, the default).

**Smoothed switch** (``smoothing = δ > 0``), for Newton's method in finite elements, where
the jump stalls the iteration: with :math:`I_4 = a\cdot Ca`, :math:`A = a\otimes a`,

.. math::

    \mu(I_4) = \mu^- + (\mu^+ - \mu^-)\,\tfrac12\big[1 + \tanh((I_4 - 1)/\delta)\big],
    \qquad \psi = \mu(I_4)\,\psi_1, \quad \psi_1 = \tfrac12(\bar I_1 - 3),

    S = \mu S_1 + 2\mu'\psi_1 A, \qquad
    \mathbb{C} = \mu\,\mathbb{C}_1 + 2\mu'(S_1\otimes A + A\otimes S_1) + 4\mu''\psi_1 A\otimes A,

:math:`S_1, \mathbb{C}_1` being the stress and elasticity of :math:`\psi_1`. As
:math:`\delta \to 0` it tends to the published law; :math:`\delta = 10^{-2}` spreads the switch
over a fibre strain of about ±0.5 %.

Pressure convention as :mod:`.incompressible_neo_hookean`: ``pk1``/``cauchy`` return the
pressure-free part, total :math:`\sigma = \sigma_\text{law} - pI`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..kinematics import Array
from .base import check_array, check_nonnegative, check_positive
from .derivatives import InvariantDerivatives
from .incompressible_neo_hookean import IncompressibleNeoHookean
from .isotropic import IsotropicInvariantLaw, Partials, outer

__all__ = ["BimodularNeoHookean", "normalised_direction"]


def normalised_direction(direction: ArrayLike, name: str = "direction") -> Array:
    """Unit vectors of shape ``(3, *batch)``; ``ValueError`` for bad shape, NaN or zero vectors, ``TypeError`` for
    anything but numbers (strings, None, ...)."""
    a = check_array(name, direction, finite=False)  # TypeError naming the parameter for strings, None, ...
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
    smoothing: float = 0.0

    incompressible = True

    def __post_init__(self) -> None:
        check_positive("mu_tension", self.mu_tension)
        check_positive("mu_compression", self.mu_compression)
        check_nonnegative("smoothing", self.smoothing)
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

    # ------------------------------------------------------------ smoothed switch
    def _smooth_modulus(self, C: Array) -> tuple[Array, Array, Array]:
        """μ(I4), μ'(I4), μ''(I4) of the tanh switch (docstring of the module)."""
        th = np.tanh((self.fibre_stretch_squared(C) - 1.0) / self.smoothing)
        jump = self.mu_tension - self.mu_compression
        mu = self.mu_compression + 0.5 * jump * (1.0 + th)
        d_mu = 0.5 * jump * (1.0 - th**2) / self.smoothing
        dd_mu = -jump * th * (1.0 - th**2) / self.smoothing**2
        return mu, d_mu, dd_mu

    def _structure_tensor(self, C: Array) -> Array:
        a = self.direction  # batch axes aligned from the right, as in fibre_stretch_squared
        a = a.reshape((3,) + (1,) * (C.ndim - 1 - a.ndim) + a.shape[1:])
        return np.broadcast_to(np.einsum("I...,J...->IJ...", a, a), C.shape)

    def energy_C(self, C: Array) -> Array:
        if self.smoothing == 0.0:
            return super().energy_C(C)
        return self._smooth_modulus(C)[0] * _UNIT.energy_C(C)

    def stress_C(self, C: Array) -> Array:
        if self.smoothing == 0.0:
            return super().stress_C(C)
        mu, d_mu, _ = self._smooth_modulus(C)
        return mu * _UNIT.stress_C(C) + 2.0 * d_mu * _UNIT.energy_C(C) * self._structure_tensor(C)

    def response_C(self, C: Array) -> tuple[Array, Array]:
        if self.smoothing == 0.0:
            return super().response_C(C)
        mu, d_mu, dd_mu = self._smooth_modulus(C)
        S1, CC1 = _UNIT.response_C(C)
        psi1 = _UNIT.energy_C(C)
        A = self._structure_tensor(C)
        S = mu * S1 + 2.0 * d_mu * psi1 * A
        CC = mu * CC1 + 2.0 * d_mu * (outer(S1, A) + outer(A, S1)) + 4.0 * dd_mu * psi1 * outer(A, A)
        return S, CC

    def invariant_derivatives(self, I1bar: Array, J: Array, C: Array) -> InvariantDerivatives:
        r"""Partials of :math:`\psi = \mu(I_4)(\bar I_1 - 3)/2` in :math:`(\bar I_1, J, I_4)` (fused kernel).

        :math:`\psi_{,1} = \mu/2`, :math:`\psi_{,4} = \mu'\psi_1`, :math:`\psi_{,14} = \mu'/2`,
        :math:`\psi_{,44} = \mu''\psi_1` (smoothed switch); the published switch has only :math:`\psi_{,1}`.
        """
        if self.smoothing == 0.0:
            return super().invariant_derivatives(I1bar, J, C)
        mu, d_mu, dd_mu = (np.broadcast_to(x, np.shape(J)) for x in self._smooth_modulus(C))
        psi1 = 0.5 * (I1bar - 3.0)
        zero = np.zeros_like(J)
        a = self.direction  # batch axes aligned from the right, as in fibre_stretch_squared
        a = a.reshape((3,) + (1,) * (np.ndim(J) + 1 - a.ndim) + a.shape[1:])
        return InvariantDerivatives(0.5 * mu, zero, zero, zero, zero, d_mu * psi1, 0.5 * d_mu, zero, dd_mu * psi1,
                                    np.broadcast_to(a, (3,) + np.shape(J)))


#: ψ1 = (Ī1 − 3)/2, the unit-modulus neo-Hookean energy the smoothed switch multiplies.
_UNIT = IncompressibleNeoHookean(1.0)
