r"""N-term Ogden law in the Abaqus convention (mathur2022 Eq. 2; buchanan2014 Eq. 1).

.. math::

    \psi = \sum_{i=1}^N \frac{2\mu_i}{\alpha_i^2}
           \big(\bar\lambda_1^{\alpha_i} + \bar\lambda_2^{\alpha_i} + \bar\lambda_3^{\alpha_i} - 3\big)
         + \sum_{i} \frac{1}{D_i} (J - 1)^{2i},
    \qquad \bar\lambda_a = J^{-1/3}\lambda_a .

Small-strain shear modulus :math:`\mu_0 = \sum_i \mu_i`, bulk modulus :math:`K_0 = 2/D_1`.
buchanan2014 Eq. 1 writes :math:`\sum_p \tfrac{\mu_p}{\alpha_p}(\dots)`; it is this law with
:math:`\mu_i^\text{Abaqus} = \mu_p\alpha_p/2`, so with :math:`\alpha = 2` the two coincide and
equal the neo-Hookean law of shear modulus :math:`\mu` (:meth:`Ogden.from_buchanan2014`).

Derivation (no principal-stretch bookkeeping): :math:`\sum_a\bar\lambda_a^\alpha =
J^{-\alpha/3}\operatorname{tr}C^{\alpha/2}`, so each term is
:math:`c\,(K(J)\,T(C) - 3)` with :math:`c = 2\mu/\alpha^2`, :math:`K = J^{-\alpha/3}`,
:math:`T = \operatorname{tr}C^{q}`, :math:`q = \alpha/2`. By the product rule

.. math::

    \frac{\partial\psi}{\partial C} = c\,(K' T\,J_{,C} + K\,T_{,C}), \qquad
    \frac{\partial^2\psi}{\partial C^2} = c\,\big(K'' T\,J_{,C}\otimes J_{,C} + K' T\,J_{,CC}
        + K'(J_{,C}\otimes T_{,C} + T_{,C}\otimes J_{,C}) + K\,T_{,CC}\big),

with :math:`J_{,C} = \tfrac J2 C^{-1}`, :math:`J_{,CC}` as in :mod:`.isotropic` and
:math:`T_{,C}, T_{,CC}` from the Daleckii–Krein formula of :mod:`._spectral`, which is exact
at coincident principal stretches (F = I, F = diag(a, a, b), F = aR).
``D = ()`` (or ``None``) means incompressible: only the isochoric part, ``incompressible = True``; the
total stress is then :math:`\sigma_\text{law} - pI` (see :mod:`.base`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..kinematics import Array, determinant, inverse
from ._spectral import symmetric_eigen, trace_power_derivatives
from .base import Hyperelastic, VolumetricEnergy, check_positive, check_scalar
from .derivatives import PrincipalDerivatives
from .isotropic import jacobian_second_derivative, outer

__all__ = ["Ogden"]


def _as_parameter_tuple(name: str, values: float | Sequence[float]) -> tuple[float, ...]:
    if values is None or isinstance(values, (str, bytes)):
        raise TypeError(f"parameter {name} must be a number or a sequence of numbers; got {values!r}")
    for i, value in enumerate(np.atleast_1d(np.asarray(values, dtype=object)).ravel()):
        check_scalar(f"{name}[{i}]", value)
    values = np.atleast_1d(np.asarray(values, dtype=float))
    if values.ndim != 1:
        raise ValueError(f"parameter {name} must be a number or a 1-D sequence; got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"parameter {name} must be finite; got {values.tolist()}")
    return tuple(float(v) for v in values)


@dataclass(frozen=True)
class Ogden(Hyperelastic):
    """N-term Ogden solid: shear moduli ``mu``, exponents ``alpha``, compressibilities ``D``."""

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    D: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        mu = _as_parameter_tuple("mu", self.mu)
        alpha = _as_parameter_tuple("alpha", self.alpha)
        D = () if self.D is None or len(np.atleast_1d(self.D)) == 0 else _as_parameter_tuple("D", self.D)
        if len(mu) == 0:
            raise ValueError("parameter mu must hold at least one Ogden term")
        if len(mu) != len(alpha):
            raise ValueError(f"parameters mu and alpha must have the same length; got {len(mu)} and {len(alpha)}")
        for i, (m, a) in enumerate(zip(mu, alpha, strict=True)):
            check_positive(f"mu[{i}]", m)
            if a == 0.0:
                raise ValueError(f"parameter alpha[{i}] must be non-zero; got 0.0")
        for i, d in enumerate(D):
            check_positive(f"D[{i}]", d)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "D", D)

    @classmethod
    def from_buchanan2014(cls, mu_p: float | Sequence[float], alpha_p: float | Sequence[float]) -> Ogden:
        r"""Incompressible Ogden law from buchanan2014 Eq. 1 :math:`\sum \mu_p/\alpha_p(\dots)`."""
        mu_p = _as_parameter_tuple("mu_p", mu_p)
        alpha_p = _as_parameter_tuple("alpha_p", alpha_p)
        if len(mu_p) != len(alpha_p):
            raise ValueError(
                f"parameters mu_p and alpha_p must have the same length; got {len(mu_p)} and {len(alpha_p)}"
            )
        return cls(mu=tuple(m * a / 2.0 for m, a in zip(mu_p, alpha_p, strict=True)), alpha=alpha_p)

    @property
    def incompressible(self) -> bool:  # type: ignore[override]
        return len(self.D) == 0

    @property
    def shear_modulus(self) -> float:
        """Small-strain shear modulus :math:`\\sum_i \\mu_i`."""
        return float(sum(self.mu))

    @property
    def bulk_modulus(self) -> float:
        """Small-strain bulk modulus :math:`2/D_1` (infinite when incompressible)."""
        return 2.0 / self.D[0] if self.D else float("inf")

    # ------------------------------------------------------------------ volumetric part
    def _volumetric(self, J: Array) -> tuple[Array, Array, Array]:
        """``(U, U', U'')`` of :math:`U = \\sum_i (J-1)^{2i}/D_i`."""
        U = np.zeros_like(J)
        dU = np.zeros_like(J)
        d2U = np.zeros_like(J)
        x = J - 1.0
        for i, d in enumerate(self.D, start=1):
            U += x ** (2 * i) / d
            dU += 2 * i * x ** (2 * i - 1) / d
            d2U += 2 * i * (2 * i - 1) * x ** (2 * i - 2) / d
        return U, dU, d2U

    # ------------------------------------------------------------------------ the law
    def energy_C(self, C: Array) -> Array:
        J = np.sqrt(determinant(C))
        c = np.moveaxis(np.linalg.eigvalsh(np.moveaxis(C, (0, 1), (-2, -1))), -1, 0)
        psi = self._volumetric(J)[0]
        for m, a in zip(self.mu, self.alpha, strict=True):
            psi = psi + 2.0 * m / a**2 * (J ** (-a / 3.0) * np.sum(c ** (a / 2.0), axis=0) - 3.0)
        return psi

    def stress_C(self, C: Array) -> Array:
        return self._response(C, with_tangent=False)[0]

    def elasticity_C(self, C: Array) -> Array:
        return self._response(C, with_tangent=True)[1]

    def response_C(self, C: Array) -> tuple[Array, Array]:
        return self._response(C, with_tangent=True)

    def _response(self, C: Array, with_tangent: bool) -> tuple[Array, Array | None]:
        J = np.sqrt(determinant(C))
        G = inverse(C)
        dJ = 0.5 * J * G
        eigenvalues, vectors = symmetric_eigen(C)
        _, dU, d2U = self._volumetric(J)
        dpsi = dU * dJ
        if with_tangent:
            d2J = jacobian_second_derivative(J, G)[2]
            d2psi = d2U * outer(dJ, dJ) + dU * d2J
        for m, a in zip(self.mu, self.alpha, strict=True):
            c = 2.0 * m / a**2
            K = J ** (-a / 3.0)
            dK = -a / 3.0 * K / J
            d2K = (a / 3.0) * (a / 3.0 + 1.0) * K / J**2
            T, dT, d2T = trace_power_derivatives(eigenvalues, vectors, a / 2.0, with_tangent)
            dpsi = dpsi + c * (dK * T * dJ + K * dT)
            if with_tangent:
                d2psi = d2psi + c * (
                    d2K * T * outer(dJ, dJ) + dK * T * d2J + dK * (outer(dJ, dT) + outer(dT, dJ)) + K * d2T
                )
        return 2.0 * dpsi, (4.0 * d2psi if with_tangent else None)

    def split(self) -> tuple[Hyperelastic, VolumetricEnergy | None]:
        r"""``(isochoric Ogden, VolumetricEnergy(2/D, "quadratic"))`` for exactly one D; else ``(self, None)``."""
        if len(self.D) == 1:
            return Ogden(self.mu, self.alpha), VolumetricEnergy(2.0 / self.D[0], "quadratic")
        return self, None

    def principal_derivatives(self, c: Array) -> PrincipalDerivatives:
        r"""First and second derivatives of :math:`\psi` in the principal values :math:`c_a` of C.

        Each term is :math:`k(K\,T - 3)`, :math:`k = 2\mu/\alpha^2`, :math:`K = (c_1c_2c_3)^{-\alpha/6}`,
        :math:`T = \sum_a c_a^{\alpha/2}`: :math:`K_{,a} = -\tfrac{\alpha}{6}K/c_a`,
        :math:`K_{,ab} = (\tfrac{\alpha}{6})^2 K/(c_ac_b) + \delta_{ab}\tfrac{\alpha}{6}K/c_a^2`,
        :math:`T_{,a} = q c_a^{q-1}`, :math:`T_{,ab} = \delta_{ab} q(q-1)c_a^{q-2}` (:math:`q = \alpha/2`);
        the volumetric :math:`U(J)`, :math:`J_{,a} = J/(2c_a)`, adds :math:`U' J/(2c_a)` and
        :math:`U'' J^2/(4c_ac_b) + U' J/(4c_ac_b) - \delta_{ab} U' J/(2c_a^2)`.
        """
        c = np.asarray(c, dtype=float)
        eye = np.eye(3).reshape((3, 3) + (1,) * (c.ndim - 1))
        inv = 1.0 / c
        inv_ab = inv[:, None] * inv[None, :]
        J = np.sqrt(c[0] * c[1] * c[2])
        _, dU, d2U = self._volumetric(J)
        first = 0.5 * dU * J * inv
        second = 0.25 * (d2U * J**2 + dU * J) * inv_ab - 0.5 * eye * dU * J * inv**2
        for m, a in zip(self.mu, self.alpha, strict=True):
            k, s, q = 2.0 * m / a**2, a / 6.0, a / 2.0
            K = J ** (-a / 3.0)
            T = np.sum(c**q, axis=0)
            dK, dT = -s * K * inv, q * c ** (q - 1.0)
            d2K = s * s * K * inv_ab + eye * s * K * inv**2
            d2T = eye * q * (q - 1.0) * c ** (q - 2.0)
            first = first + k * (dK * T + K * dT)
            second = second + k * (d2K * T + dK[:, None] * dT[None, :] + dT[:, None] * dK[None, :] + K * d2T)
        return PrincipalDerivatives(first, second)
