r"""Scalar derivatives a law hands to the compiled assembly kernel (:mod:`skvalve.fem.elements.fused`).

A law states its strain energy in a few scalar arguments; the tensor algebra that turns their
derivatives into the stress, the tangent and the element matrices is written once in the kernel.

* :class:`InvariantDerivatives` — :math:`\psi(\bar I_1, J, I_4)` with :math:`\bar I_1 = J^{-2/3}\operatorname{tr}C`,
  :math:`J = \det F` and :math:`I_4 = a\cdot C a` for a unit direction :math:`a` (absent when the law does
  not depend on a direction): the first partials :math:`\psi_{,1}, \psi_{,J}, \psi_{,4}` and the second
  partials :math:`\psi_{,11}, \psi_{,1J}, \psi_{,JJ}, \psi_{,14}, \psi_{,J4}, \psi_{,44}`.
* :class:`PrincipalDerivatives` — :math:`\psi(c_1, c_2, c_3)` of the principal values :math:`c_a = \lambda_a^2`
  of :math:`C` (Ogden): :math:`\partial\psi/\partial c_a` and :math:`\partial^2\psi/\partial c_a\partial c_b`.

Arrays broadcast against the batch shape of the deformation gradients they were computed for.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..kinematics import Array

__all__ = ["InvariantDerivatives", "PrincipalDerivatives"]


@dataclass(frozen=True)
class InvariantDerivatives:
    r"""Partials of :math:`\psi(\bar I_1, J, I_4)`; ``direction`` is :math:`a` (shape ``(3, *batch)``) or None."""

    d_1: Array
    d_J: Array
    d_11: Array
    d_1J: Array
    d_JJ: Array
    d_4: Array | float = 0.0
    d_14: Array | float = 0.0
    d_J4: Array | float = 0.0
    d_44: Array | float = 0.0
    direction: Array | None = None


@dataclass(frozen=True)
class PrincipalDerivatives:
    r"""``first[a]`` :math:`=\partial\psi/\partial c_a` ``(3, *batch)``, ``second[a, b]`` ``(3, 3, *batch)``."""

    first: Array
    second: Array
