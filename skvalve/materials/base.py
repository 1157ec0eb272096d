r"""Hyperelastic material interface: a strain energy of :math:`C`, stress and tangent derived.

A law supplies the strain energy :math:`\psi(C)`, the second Piola–Kirchhoff stress
:math:`S = 2\,\partial\psi/\partial C` and the material elasticity tensor
:math:`\mathbb{C} = 2\,\partial S/\partial C = 4\,\partial^2\psi/\partial C\,\partial C`.
Everything a solver needs in terms of :math:`F` follows here once for all laws:

.. math::

    P = F S, \qquad \sigma = J^{-1} P F^T, \qquad
    \mathbb{A}_{iJkL} = \frac{\partial P_{iJ}}{\partial F_{kL}}
                      = \delta_{ik} S_{JL} + F_{iI} F_{kK} \mathbb{C}_{IJKL}.

Arrays keep tensor indices first and batch axes last (see :mod:`skvalve.kinematics`).

Incompressible laws (``incompressible = True``) return only the part of the stress that
the deformation determines; the hydrostatic pressure is a Lagrange multiplier supplied
by the formulation (an analytic solution or a mixed u/p element). Their total stress is
:math:`P = P_\text{law}(F) - p\,J F^{-T}`, :math:`\sigma = \sigma_\text{law} - p I`.

Laws with a volumetric–rest split :math:`\psi(F) = \hat\psi(F) + U(J)` expose it via
:meth:`Hyperelastic.split` so that a mixed u/p element can treat :math:`U` separately.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike

from ..kinematics import Array, as_tensor_field, determinant, right_cauchy_green

__all__ = ["Hyperelastic", "VolumetricEnergy", "check_positive", "check_nonnegative", "check_scalar", "check_array"]


def _first_index(mask: Array) -> tuple[int, ...]:
    """Batch index of the first True entry of ``mask`` (``()`` for a 0-d mask)."""
    mask = np.asarray(mask)
    if mask.ndim == 0:
        return ()
    return tuple(int(i) for i in np.argwhere(mask)[0])


def _at(index: tuple[int, ...]) -> str:
    return f" at batch index {index}" if index else ""


def check_scalar(name: str, value: float) -> float:
    """Return ``float(value)`` for a real number; ``TypeError`` naming the parameter for anything else.

    Strings (``"2.0"``), ``None``, booleans and arrays with more than one element are rejected here,
    at construction, instead of failing later inside a stress evaluation.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        if isinstance(value, np.ndarray) and value.ndim == 0 and np.issubdtype(value.dtype, np.number):
            return check_scalar(name, value.item())
        raise TypeError(f"parameter {name} must be a real number; got {value!r} of type {type(value).__name__}")
    return float(value)


def check_array(name: str, value: ArrayLike, finite: bool = True) -> np.ndarray:
    """Return ``value`` as a float array: a real number or a regular (nested) sequence or array of real numbers.

    ``TypeError`` naming the parameter for strings, ``None``, booleans, complex numbers or other objects (also as
    entries of a sequence); ``ValueError`` for a ragged sequence and, when ``finite``, for NaN or infinite entries.
    The array counterpart of :func:`check_scalar`, for parameters given per point or per direction.
    """
    if value is None or isinstance(value, (str, bytes)):
        raise TypeError(f"parameter {name} must be a number or an array of numbers; got {value!r}")
    try:
        array = np.asarray(value)
    except ValueError:  # a ragged sequence
        raise ValueError(f"parameter {name} must be a number or a regular array of numbers; got {value!r}") from None
    if array.dtype == object:
        for index in np.ndindex(array.shape):
            check_scalar(f"{name}{list(index) if index else ''}", array[index])
    elif array.dtype.kind not in "iuf":
        raise TypeError(f"parameter {name} must be a number or an array of real numbers; got {value!r} "
                        f"(dtype {array.dtype})")
    array = array.astype(float)
    if finite and not np.all(np.isfinite(array)):
        index = _first_index(~np.isfinite(array))
        raise ValueError(f"parameter {name} must be finite; got {float(array[index])!r}"
                         f"{f' at index {list(index)}' if index else ''}")
    return array


def check_positive(name: str, value: float) -> float:
    """Return ``float(value)`` or raise ``ValueError`` (``TypeError`` for a non-number) naming the parameter."""
    value = check_scalar(name, value)
    if not np.isfinite(value) or value <= 0.0:
        raise ValueError(f"parameter {name} must be positive and finite; got {value!r}")
    return value


def check_nonnegative(name: str, value: float) -> float:
    """Return ``float(value)`` or raise ``ValueError`` (``TypeError`` for a non-number) naming the parameter."""
    value = check_scalar(name, value)
    if not np.isfinite(value) or value < 0.0:
        raise ValueError(f"parameter {name} must be non-negative and finite; got {value!r}")
    return value


@dataclass(frozen=True)
class VolumetricEnergy:
    r"""A volumetric energy :math:`U(J)` with its first two derivatives.

    ``kind`` selects the form: ``"quadratic"`` :math:`U = \tfrac{k}{2}(J-1)^2`
    or ``"log"`` :math:`U = \tfrac{k}{2}(\ln J)^2`; ``modulus`` is :math:`k = U''(1)`.
    (For a split law the small-strain bulk modulus also has a share from the rest.)
    """

    modulus: float
    kind: str = "quadratic"

    def __post_init__(self) -> None:
        check_positive("modulus", self.modulus)
        if self.kind not in ("quadratic", "log"):
            raise ValueError(f"VolumetricEnergy kind must be 'quadratic' or 'log'; got {self.kind!r}")

    def _jacobian(self, J: ArrayLike) -> Array:
        J = np.asarray(J, dtype=float)
        if self.kind == "log" and not np.all(J > 0.0):
            raise ValueError(f"VolumetricEnergy(kind='log'): J must be positive; got min J = {float(np.min(J))!r}")
        return J

    def energy(self, J: ArrayLike) -> Array:
        J = self._jacobian(J)
        if self.kind == "quadratic":
            return 0.5 * self.modulus * (J - 1.0) ** 2
        return 0.5 * self.modulus * np.log(J) ** 2

    def first_derivative(self, J: ArrayLike) -> Array:
        """:math:`U'(J)`, the hydrostatic pressure magnitude (tension positive)."""
        J = self._jacobian(J)
        if self.kind == "quadratic":
            return self.modulus * (J - 1.0)
        return self.modulus * np.log(J) / J

    def second_derivative(self, J: ArrayLike) -> Array:
        J = self._jacobian(J)
        if self.kind == "quadratic":
            return np.full_like(J, self.modulus)
        return self.modulus * (1.0 - np.log(J)) / J**2


class Hyperelastic(ABC):
    """Base class of every continuum law: implement ``energy_C``, ``stress_C``, ``elasticity_C``."""

    #: True when the law's stress is determined only up to a hydrostatic pressure.
    incompressible: bool = False

    # ----------------------------------------------------------------- the law
    @abstractmethod
    def energy_C(self, C: Array) -> Array:
        r"""Strain energy per unit reference volume :math:`\psi(C)`, shape ``batch``."""

    @abstractmethod
    def stress_C(self, C: Array) -> Array:
        r"""Second Piola–Kirchhoff stress :math:`S = 2\partial\psi/\partial C`."""

    @abstractmethod
    def elasticity_C(self, C: Array) -> Array:
        r"""Material elasticity :math:`\mathbb{C} = 2\partial S/\partial C`, shape ``(3, 3, 3, 3, *batch)``."""

    def response_C(self, C: Array) -> tuple[Array, Array]:
        """``(S, elasticity)`` together; laws override this to share intermediate work."""
        return self.stress_C(C), self.elasticity_C(C)

    def split(self) -> tuple[Hyperelastic, VolumetricEnergy | None]:
        r"""Return ``(rest, U)`` with :math:`\psi = \hat\psi + U(J)`; ``(self, None)`` if no split."""
        return self, None

    # --------------------------------------------------- derived, in terms of F
    def psi(self, F: ArrayLike) -> Array:
        """Strain energy per unit reference volume at deformation gradients ``F``."""
        F = as_tensor_field(F)
        return self._checked("psi", self.energy_C(self._C(F)), F.shape[2:])

    def pk2(self, F: ArrayLike) -> Array:
        """Second Piola–Kirchhoff stress, shape ``(3, 3, *batch)``."""
        F = as_tensor_field(F)
        return self._checked("pk2", self.stress_C(self._C(F)), F.shape[2:])

    def pk1(self, F: ArrayLike) -> Array:
        """First Piola–Kirchhoff stress :math:`P = F S`, shape ``(3, 3, *batch)``."""
        F = as_tensor_field(F)
        return np.einsum("iI...,IJ...->iJ...", F, self.pk2(F))

    def cauchy(self, F: ArrayLike) -> Array:
        r"""Cauchy stress :math:`\sigma = J^{-1} F S F^T`, shape ``(3, 3, *batch)``."""
        F = as_tensor_field(F)
        return np.einsum("iI...,IJ...,jJ...->ij...", F, self.pk2(F), F) / determinant(F)

    def tangent(self, F: ArrayLike) -> Array:
        r"""First elasticity tensor :math:`\partial P_{iJ}/\partial F_{kL}`, shape ``(3, 3, 3, 3, *batch)``."""
        return self.pk1_and_tangent(F)[1]

    def pk1_and_tangent(self, F: ArrayLike) -> tuple[Array, Array]:
        """``(P, dP/dF)`` sharing the work of one constitutive evaluation."""
        F = as_tensor_field(F)
        S, CC = self.response_C(self._C(F))
        self._checked("pk2", S, F.shape[2:])
        self._checked("elasticity tensor", CC, F.shape[2:])
        P = np.einsum("iI...,IJ...->iJ...", F, S)
        FCC = np.einsum("iI...,IJKL...->iJKL...", F, CC)
        A = np.einsum("kK...,iJKL...->iJkL...", F, FCC)
        for i in range(3):
            A[i, :, i, :] += S
        return P, A

    # ----------------------------------------------------------------- helpers
    def _C(self, F: ArrayLike) -> Array:
        """C = FᵀF after checking that F is finite with det F > 0 (``ValueError`` naming the point)."""
        F = as_tensor_field(F)
        finite = np.all(np.isfinite(F), axis=(0, 1))
        if not np.all(finite):
            raise ValueError(f"{type(self).__name__}: F must be finite; got NaN or inf{_at(_first_index(~finite))}")
        J = determinant(F)
        if np.any(J <= 0.0):
            idx = _first_index(J <= 0.0)
            raise ValueError(
                f"{type(self).__name__}: det F must be positive; got {float(np.asarray(J)[idx])!r}{_at(idx)}"
            )
        return right_cauchy_green(F)

    def _checked(self, what: str, value: Array, batch_shape: tuple[int, ...]) -> Array:
        """``value`` (tensor axes first, then ``batch_shape``) or ``ValueError`` where it overflowed."""
        bad = ~np.isfinite(value)
        if np.any(bad):
            where = _first_index(bad.reshape((-1,) + batch_shape).any(axis=0))
            raise ValueError(
                f"{type(self).__name__}: {what} overflows (inf or NaN){_at(where)}; "
                "the deformation is outside the range this law can be evaluated in"
            )
        return value

    def parameters(self) -> dict[str, object]:
        """The law's parameters by name (dataclass fields)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}  # type: ignore[arg-type]
