r"""Isotropic laws written as :math:`\psi(\bar I_1, J)`: stress and tangent by the chain rule.

With :math:`\bar I_1 = J^{-2/3} I_1` and :math:`J = \sqrt{\det C}` the derivatives with
respect to :math:`C` are (:math:`C^{-1}` written :math:`G`)

.. math::

    \frac{\partial J}{\partial C} = \frac J2 G, \qquad
    \frac{\partial \bar I_1}{\partial C} = J^{-2/3}\Big(I - \frac{I_1}{3} G\Big),

    \frac{\partial^2 J}{\partial C^2} = \frac J4 G\otimes G - \frac J2 \mathbb{G}, \qquad
    \frac{\partial^2 \bar I_1}{\partial C^2} = -\frac{J^{-2/3}}{3}(I\otimes G + G\otimes I)
        + \frac{\bar I_1}{9} G\otimes G + \frac{\bar I_1}{3}\mathbb{G},

with :math:`\mathbb{G}_{IJKL} = \tfrac12 (G_{IK}G_{JL} + G_{IL}G_{JK}) = -\partial G_{IJ}/\partial C_{KL}`.
Then :math:`S = 2(\psi_{,\bar I}\,\partial\bar I_1/\partial C + \psi_{,J}\,\partial J/\partial C)`
and :math:`\mathbb{C} = 4\,\partial^2\psi/\partial C^2` collects the products of the
second partials :math:`\psi_{,\bar I\bar I}, \psi_{,\bar I J}, \psi_{,JJ}` with the first
derivatives plus :math:`\psi_{,\bar I}` and :math:`\psi_{,J}` times the second derivatives.
A law only states :math:`\psi` and its five partials (:meth:`IsotropicInvariantLaw.partials`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..kinematics import Array, determinant, identity_like, inverse
from .base import Hyperelastic
from .derivatives import InvariantDerivatives

__all__ = ["IsotropicInvariantLaw", "Partials", "outer", "jacobian_second_derivative"]


class Partials(NamedTuple):
    """ψ and its partial derivatives in :math:`(\\bar I_1, J)`."""

    psi: Array
    d_I: Array
    d_J: Array
    d_II: Array
    d_IJ: Array
    d_JJ: Array


def outer(A: Array, B: Array) -> Array:
    r"""Dyadic product :math:`(A\otimes B)_{IJKL} = A_{IJ} B_{KL}` of tensor fields."""
    return np.einsum("IJ...,KL...->IJKL...", A, B)


def jacobian_second_derivative(J: Array, G: Array) -> tuple[Array, Array, Array]:
    r"""``(G⊗G, 𝔾, ∂²J/∂C²)`` with :math:`\partial^2 J/\partial C^2 = \tfrac J4 G\otimes G - \tfrac J2 \mathbb{G}`.

    :math:`G = C^{-1}` and :math:`\mathbb{G}_{IJKL} = \tfrac12 (G_{IK}G_{JL} + G_{IL}G_{JK})`.
    """
    GG = outer(G, G)
    Gsym = 0.5 * (np.einsum("IK...,JL...->IJKL...", G, G) + np.einsum("IL...,JK...->IJKL...", G, G))
    return GG, Gsym, 0.25 * J * GG - 0.5 * J * Gsym


class IsotropicInvariantLaw(Hyperelastic):
    r"""Base for laws :math:`\psi(\bar I_1, J)`; ``C`` is passed too for direction-dependent laws."""

    def partials(self, I1bar: Array, J: Array, C: Array) -> Partials:  # pragma: no cover - abstract
        raise NotImplementedError

    def _kinematic_terms(self, C: Array):
        J = np.sqrt(determinant(C))
        G = inverse(C)
        I1 = np.trace(C)
        Jm23 = J ** (-2.0 / 3.0)
        I1bar = Jm23 * I1
        eye = identity_like(C)
        dI = Jm23 * (eye - I1 / 3.0 * G)
        dJ = 0.5 * J * G
        return J, G, I1bar, Jm23, eye, dI, dJ

    def energy_C(self, C: Array) -> Array:
        J, _, I1bar, *_ = self._kinematic_terms(C)
        return self.partials(I1bar, J, C).psi

    def stress_C(self, C: Array) -> Array:
        J, _, I1bar, _, _, dI, dJ = self._kinematic_terms(C)
        p = self.partials(I1bar, J, C)
        return 2.0 * (p.d_I * dI + p.d_J * dJ)

    def elasticity_C(self, C: Array) -> Array:
        return self.response_C(C)[1]

    def response_C(self, C: Array) -> tuple[Array, Array]:
        J, G, I1bar, Jm23, eye, dI, dJ = self._kinematic_terms(C)
        p = self.partials(I1bar, J, C)
        S = 2.0 * (p.d_I * dI + p.d_J * dJ)
        GG, Gsym, d2J = jacobian_second_derivative(J, G)
        d2I = -Jm23 / 3.0 * (outer(eye, G) + outer(G, eye)) + I1bar / 9.0 * GG + I1bar / 3.0 * Gsym
        CC = 4.0 * (
            p.d_II * outer(dI, dI)
            + p.d_IJ * (outer(dI, dJ) + outer(dJ, dI))
            + p.d_JJ * outer(dJ, dJ)
            + p.d_I * d2I
            + p.d_J * d2J
        )
        return S, CC

    def invariant_derivatives(self, I1bar: Array, J: Array, C: Array) -> InvariantDerivatives:
        r"""The partials of :meth:`partials` for the compiled kernel (:mod:`skvalve.fem.elements.fused`); no
        :math:`I_4`."""
        p = self.partials(I1bar, J, C)
        return InvariantDerivatives(p.d_I, p.d_J, p.d_II, p.d_IJ, p.d_JJ)
