r"""Homogeneous principal responses of any continuum law: uniaxial, equibiaxial, planar biaxial.

A homogeneous deformation :math:`F = \operatorname{diag}(\lambda_1, \lambda_2, \lambda_3)` of a law
whose stress is coaxial with :math:`F` (every isotropic law, and the bimodular law within a
branch) has principal Cauchy stresses :math:`\sigma_a` and nominal (first Piola–Kirchhoff)
stresses :math:`P_a = J\sigma_a/\lambda_a`.

The solve is chosen explicitly: an incompressible law (``law.incompressible``) gets the
incompressible one; a compressible law must pass ``incompressible=False`` (its own response) or
``incompressible=True`` (its incompressible limit) — leaving it out raises ``ValueError`` instead of
silently treating a compressible law as incompressible.

**Incompressible** (``incompressible=True``, thin membrane in plane stress): :math:`J = 1` and
:math:`\sigma = \sigma_\text{law} - pI`. Every volumetric term in this package has zero
derivative at :math:`J = 1`, so evaluating the law there and eliminating :math:`p` from the
traction-free condition is exact:

* biaxial :math:`(\lambda_1, \lambda_2)`: :math:`\lambda_3 = 1/(\lambda_1\lambda_2)`,
  :math:`p = \sigma_{\text{law},33}`, so :math:`\sigma_a = \sigma_{\text{law},aa} - \sigma_{\text{law},33}`;
* uniaxial :math:`\lambda`: :math:`\lambda_{2,3} = \lambda^{-1/2} e^{\pm s/2}` with the lateral split
  :math:`s` the root of :math:`\sigma_{\text{law},22} = \sigma_{\text{law},33}`; :math:`s = 0`
  (:math:`\lambda_2 = \lambda_3 = \lambda^{-1/2}`) for an isotropic law, otherwise root-solved.

**Compressible** (``incompressible=False``): the free stretch(es) are solved from the
traction-free conditions :math:`P_{22} = 0` (uniaxial, :math:`\lambda_2 = \lambda_3`) or
:math:`P_{33} = 0` (biaxial) by Brent's method on :math:`\ln\lambda` inside a bracket that is
widened until the sign changes; ``ValueError`` where no root exists in
:math:`10^{-6} < \lambda < 10^{6}`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import brentq

from ..kinematics import Array
from ..materials.base import check_array

__all__ = ["HomogeneousResponse", "uniaxial", "equibiaxial", "biaxial"]

_LOG_BRACKET_LIMIT = np.log(1e6)
_COAXIAL_RTOL = 1e-9


@dataclass(frozen=True)
class HomogeneousResponse:
    """Principal stretches, J, principal Cauchy and nominal stresses; arrays of shape ``(3, *shape)``."""

    stretches: Array
    J: Array
    cauchy: Array
    nominal: Array


def _principal_law_stress(material, stretches: Array) -> Array:
    """Principal Cauchy stresses of the law at diag(stretches); raise if not coaxial."""
    sigma = material.cauchy(np.diag(stretches)[:, :, None])[..., 0]
    scale = np.max(np.abs(sigma)) + 1e-300
    off_diagonal = sigma - np.diag(np.diag(sigma))
    if np.max(np.abs(off_diagonal)) > _COAXIAL_RTOL * scale:
        raise ValueError(
            f"{type(material).__name__}: stress at F = diag{tuple(stretches)} is not coaxial with F; "
            "no homogeneous principal response exists"
        )
    return np.diag(sigma).copy()


def _root_in_log(fun, guess: float, what: str) -> float:
    """Root of ``fun(x)`` (x a log-stretch) by Brent's method, widening a bracket around ``guess``."""

    def safe(x: float) -> float:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            try:
                value = float(fun(x))
            except ValueError:
                return np.nan
        return value

    f0 = safe(guess)
    if f0 == 0.0:
        return guess
    width = 0.05
    while width < 2.0 * _LOG_BRACKET_LIMIT:
        for lo, hi in ((guess - width, guess), (guess, guess + width)):
            f_lo, f_hi = safe(lo), safe(hi)
            if np.isfinite(f_lo) and np.isfinite(f_hi) and f_lo * f_hi <= 0.0:
                return brentq(safe, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
        width *= 2.0
    raise ValueError(f"no solution for {what}: no sign change of the traction within stretches 1e-6 .. 1e6")


def _check_mode(material, incompressible: bool | None) -> bool:
    """The solve to use: the law's own for ``None`` on an incompressible law; an explicit choice otherwise."""
    if not callable(getattr(material, "cauchy", None)):
        raise TypeError(
            "material must be a continuum law with a cauchy(F) method (skvalve.materials); "
            f"got {type(material).__name__}"
        )
    law_incompressible = bool(getattr(material, "incompressible", False))
    if incompressible is None:
        if law_incompressible:
            return True
        raise ValueError(
            f"{type(material).__name__} is compressible: choose incompressible=False for its own response "
            "(lateral faces traction free, J free) or incompressible=True for its incompressible limit "
            "(J = 1, the volumetric part replaced by a pressure)"
        )
    if not isinstance(incompressible, (bool, np.bool_)):
        raise TypeError(f"incompressible must be True, False or None; got {incompressible!r}")
    if not incompressible and law_incompressible:
        raise ValueError(
            f"{type(material).__name__} is incompressible: its stress is defined only up to a pressure, "
            "so use incompressible=True (or leave it out)"
        )
    return bool(incompressible)


def _assemble(stretch_list: list[Array], stress_list: list[Array], shape: tuple[int, ...]) -> HomogeneousResponse:
    stretches = np.stack(stretch_list, axis=-1).reshape((3,) + shape) if stretch_list else np.empty((3,) + shape)
    cauchy = np.stack(stress_list, axis=-1).reshape((3,) + shape) if stress_list else np.empty((3,) + shape)
    J = np.prod(stretches, axis=0)
    return HomogeneousResponse(stretches=stretches, J=J, cauchy=cauchy, nominal=J * cauchy / stretches)


def _positive_stretches(name: str, value: ArrayLike) -> Array:
    value = check_array(name, value, finite=False)  # TypeError naming the parameter for strings, None, ...
    if not np.all(np.isfinite(value)) or np.any(value <= 0.0):
        raise ValueError(f"{name} must be positive and finite; got {value!r}")
    return value


def uniaxial(material, stretch: ArrayLike, incompressible: bool | None = None) -> HomogeneousResponse:
    r"""Uniaxial tension/compression along :math:`e_1`, lateral faces traction free.

    ``incompressible``: ``None`` (default) follows an incompressible law and raises ``ValueError``
    for a compressible one, which must choose: ``False`` solves its own response (free lateral
    stretch from :math:`P_{22} = 0`), ``True`` its incompressible limit (module docstring).
    """
    incompressible = _check_mode(material, incompressible)
    stretch = _positive_stretches("stretch", stretch)
    stretch_list, stress_list = [], []
    for lam in stretch.ravel():
        if incompressible:

            def lateral(s: float, lam: float = lam) -> Array:
                return np.array([lam, lam**-0.5 * np.exp(0.5 * s), lam**-0.5 * np.exp(-0.5 * s)])

            def imbalance(s: float) -> float:
                sigma = _principal_law_stress(material, lateral(s))
                return (sigma[1] - sigma[2]) / (np.max(np.abs(sigma)) + 1e-300)

            sigma0 = _principal_law_stress(material, lateral(0.0))
            if abs(sigma0[1] - sigma0[2]) <= 1e-12 * (np.max(np.abs(sigma0)) + 1e-300):
                split = 0.0
            else:
                split = _root_in_log(imbalance, 0.0, f"the lateral stretch split at stretch {lam}")
            lams = lateral(split)
            sigma = _principal_law_stress(material, lams)
            sigma = sigma - sigma[2]
            sigma[1] = 0.0
        else:

            def lateral_traction(x: float, lam: float = lam) -> float:
                return _principal_law_stress(material, np.array([lam, np.exp(x), np.exp(x)]))[1]

            x = _root_in_log(lateral_traction, -0.5 * np.log(lam), f"the lateral stretch at stretch {lam}")
            lams = np.array([lam, np.exp(x), np.exp(x)])
            sigma = _principal_law_stress(material, lams)
        stretch_list.append(lams)
        stress_list.append(sigma)
    return _assemble(stretch_list, stress_list, stretch.shape)


def biaxial(
    material, stretch1: ArrayLike, stretch2: ArrayLike, incompressible: bool | None = None
) -> HomogeneousResponse:
    r"""Planar biaxial stretch :math:`(\lambda_1, \lambda_2)` of a thin sheet, :math:`\sigma_{33} = 0`.

    ``incompressible`` as in :func:`uniaxial` (a compressible law must choose).
    """
    incompressible = _check_mode(material, incompressible)
    s1, s2 = _positive_stretches("stretch1", stretch1), _positive_stretches("stretch2", stretch2)
    try:
        s1, s2 = np.broadcast_arrays(s1, s2)
    except ValueError:
        raise ValueError(f"stretch1 of shape {s1.shape} and stretch2 of shape {s2.shape} do not broadcast") from None
    stretch_list, stress_list = [], []
    for lam1, lam2 in zip(s1.ravel(), s2.ravel(), strict=True):
        if incompressible:
            lams = np.array([lam1, lam2, 1.0 / (lam1 * lam2)])
            sigma = _principal_law_stress(material, lams)
            sigma = sigma - sigma[2]
        else:

            def thickness_traction(x: float, lam1: float = lam1, lam2: float = lam2) -> float:
                return _principal_law_stress(material, np.array([lam1, lam2, np.exp(x)]))[2]

            x = _root_in_log(thickness_traction, -np.log(lam1 * lam2), f"the thickness stretch at ({lam1}, {lam2})")
            lams = np.array([lam1, lam2, np.exp(x)])
            sigma = _principal_law_stress(material, lams)
        stretch_list.append(lams)
        stress_list.append(sigma)
    return _assemble(stretch_list, stress_list, s1.shape)


def equibiaxial(material, stretch: ArrayLike, incompressible: bool | None = None) -> HomogeneousResponse:
    r"""Equibiaxial stretch :math:`\lambda_1 = \lambda_2 = \lambda` of a thin sheet, :math:`\sigma_{33} = 0`."""
    return biaxial(material, stretch, stretch, incompressible=incompressible)
