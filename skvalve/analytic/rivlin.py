r"""Rivlin (1949) pure bending of an incompressible block in plane strain, layered or not.

Used by buchanan2014 (Sect. 2.2, Fig. 3) to fix the Ogden exponent and, here, as the exact
reference for the finite-element strip and for the bimodular bilayer (Eq. 4, Table 3).

Derivation
----------
A block :math:`0 \le X \le L`, :math:`0 \le Y \le H` (unit width, plane strain) is bent into
a circular sector: :math:`r = r(Y)`, :math:`\theta = aX`, :math:`z = Z`, where :math:`a` is
the bending angle per unit reference length. The principal stretches are
:math:`\lambda_\theta = r a =: \lambda`, :math:`\lambda_r = r'(Y)`, :math:`\lambda_z = 1`.
Incompressibility :math:`\lambda_r\lambda_\theta = 1` gives :math:`a\, r\, r' = 1`, so
:math:`a r^2 = 2Y + \text{const}`, i.e.

.. math::  \lambda(Y)^2 = 2aY + c , \qquad \lambda_r = 1/\lambda .

Let :math:`\hat W(\lambda) = W(\operatorname{diag}(\lambda, 1/\lambda, 1))` be the plane-strain
reduced energy. Along that path :math:`dF/d\lambda = \operatorname{diag}(1, -\lambda^{-2}, 0)`,
hence :math:`\hat W'(\lambda) = P_{11} - P_{22}/\lambda^2`; a hydrostatic term
:math:`-p F^{-T}` contributes :math:`-p(1/\lambda - \lambda/\lambda^2) = 0`, so the
pressure-free stress of an incompressible law suffices. The principal Cauchy stress
difference is :math:`\sigma_{\theta\theta} - \sigma_{rr} = \lambda \hat W'(\lambda)`.
Radial equilibrium :math:`d\sigma_{rr}/dr = (\sigma_{\theta\theta} - \sigma_{rr})/r` with
:math:`dr/r = d\lambda/\lambda` becomes :math:`d\sigma_{rr} = \hat W'(\lambda)\,d\lambda`:

.. math::  \sigma_{rr}(Y) = \hat W_L(\lambda(Y)) - \hat W_L(\lambda_L^-) + \sum_{K<L}
           \bigl[\hat W_K(\lambda_K^+) - \hat W_K(\lambda_K^-)\bigr],

with :math:`\lambda_K^\mp` the stretches at the bottom/top of layer :math:`K`, the bottom face
traction free and :math:`\sigma_{rr}` continuous across interfaces. A traction-free top face
fixes :math:`c` through the *equal-energy* condition
:math:`\sum_K [\hat W_K(\lambda_K^+) - \hat W_K(\lambda_K^-)] = 0` (for one layer:
:math:`\hat W(\lambda_\text{top}) = \hat W(\lambda_\text{bottom})`). When each
:math:`\hat W_K` decreases below :math:`\lambda = 1` and increases above it, the root has
:math:`\lambda_\text{bottom} < 1 < \lambda_\text{top}`, bracketed by
:math:`c \in (\max(0, 1 - 2aH), 1)`.

Resultants per unit width, using :math:`dr = dY/\lambda` and :math:`r\,dr = dY/a`:

.. math::  N = \int \sigma_{\theta\theta}\, dr = \int_0^H \frac{\sigma_{\theta\theta}}{\lambda} dY
           = [r\sigma_{rr}] = 0, \qquad
           M = \int \sigma_{\theta\theta}\, r\, dr = \frac1a \int_0^H \sigma_{\theta\theta}\, dY
             = -\frac1a \int_0^H \sigma_{rr}\, dY .

The deformed neutral fibre (:math:`\lambda = 1`) has radius :math:`1/a`, so :math:`a` is the
change of curvature :math:`\Delta\kappa` from the straight reference. :math:`N` is computed by
quadrature and is a check, not an input; :math:`M` is taken from the :math:`\sigma_{rr}`
form, which avoids the cancellation of the :math:`O(a)` fibre stresses at small curvature.
For :math:`a < 0` the block is mirrored (:math:`Y \to H - Y`) and solved with :math:`|a|`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from ..materials.base import check_array, check_scalar

__all__ = ["BendingSolution", "bend", "moment_curvature", "plane_strain_energy"]

Array = NDArray[np.float64]
_GAUSS_POINTS, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(24)


def _stretch_path(lam: Array) -> Array:
    """Deformation gradients diag(λ, 1/λ, 1), shape (3, 3, n)."""
    F = np.zeros((3, 3, lam.size))
    F[0, 0], F[1, 1], F[2, 2] = lam, 1.0 / lam, 1.0
    return F


def plane_strain_energy(material, lam: ArrayLike) -> tuple[Array, Array]:
    r"""Reduced energy :math:`\hat W(\lambda)` and :math:`\hat W'(\lambda) = P_{11} - P_{22}/\lambda^2`."""
    lam = np.atleast_1d(np.asarray(lam, dtype=float))
    F = _stretch_path(lam.ravel())
    W = np.asarray(material.psi(F), dtype=float)
    P = np.asarray(material.pk1(F), dtype=float)
    dW = P[0, 0] - P[1, 1] / lam.ravel() ** 2
    return W.reshape(lam.shape), dW.reshape(lam.shape)


def _check_layers(layers: Sequence) -> tuple[Array, tuple]:
    if len(layers) == 0:
        raise ValueError("bend: layers must hold at least one (thickness, material) pair")
    thicknesses, materials = [], []
    for i, item in enumerate(layers):
        try:
            h, material = item
        except (TypeError, ValueError):
            raise ValueError(f"bend: layers[{i}] must be a (thickness, material) pair; got {item!r}") from None
        try:
            h = check_scalar(f"layers[{i}] thickness", h)
        except TypeError as err:
            raise TypeError(f"bend: {err}") from None
        if not (np.isfinite(h) and h > 0.0):
            raise ValueError(f"bend: layers[{i}] thickness must be positive and finite; got {h!r}")
        if not (hasattr(material, "psi") and hasattr(material, "pk1")):
            raise ValueError(f"bend: layers[{i}] material must provide psi(F) and pk1(F); got {material!r}")
        if not getattr(material, "incompressible", False):
            raise ValueError(f"bend: layers[{i}] material {type(material).__name__} is not incompressible")
        thicknesses.append(h)
        materials.append(material)
    return np.array(thicknesses), tuple(materials)


@dataclass(frozen=True)
class BendingSolution:
    """Rivlin bending state of a layered block; lengths in the units of the thicknesses.

    ``moment`` and ``axial_force`` are per unit width (stress × length² and stress × length).
    """

    a: float
    c: float
    interfaces: Array  # Y of the faces and interfaces, bottom to top (len = n_layers + 1)
    materials: tuple
    neutral_axis: float
    moment: float
    axial_force: float
    lambda_bottom: float
    lambda_top: float
    mirrored: bool = False

    @property
    def thickness(self) -> float:
        return float(self.interfaces[-1])

    @property
    def normalised_neutral_axis(self) -> float:
        """Neutral axis as a fraction of the thickness from the bottom face."""
        return self.neutral_axis / self.thickness

    def profile(self, Y: ArrayLike) -> tuple[Array, Array, Array]:
        r"""``(λ, σ_rr, σ_θθ)`` at reference heights ``Y`` (0 ≤ Y ≤ H), total Cauchy stresses."""
        Y = np.asarray(Y, dtype=float)
        H = self.thickness
        if np.any(~np.isfinite(Y)) or np.any(Y < -1e-12 * H) or np.any(Y > H * (1 + 1e-12)):
            raise ValueError(f"profile: Y must lie in [0, {H}]; got range [{Y.min()}, {Y.max()}]")
        Yr = H - Y if self.mirrored else Y
        abs_a = abs(self.a)
        lam = np.sqrt(2.0 * abs_a * Yr + self.c)
        s_rr = np.empty_like(lam)
        s_tt = np.empty_like(lam)
        ifaces = self._solved_interfaces()
        jump = 0.0
        for k, material in enumerate(self._solved_materials()):
            y0, y1 = ifaces[k], ifaces[k + 1]
            last = k == len(ifaces) - 2
            mask = (Yr >= y0) & ((Yr <= y1) if last else (Yr < y1))
            lam_ends = np.sqrt(2.0 * abs_a * np.array([y0, y1]) + self.c)
            W_ends, _ = plane_strain_energy(material, lam_ends)
            if np.any(mask):
                W, dW = plane_strain_energy(material, lam[mask])
                s_rr[mask] = jump + W - W_ends[0]
                s_tt[mask] = s_rr[mask] + lam[mask] * dW
            jump += W_ends[1] - W_ends[0]
        return lam, s_rr, s_tt

    def _solved_interfaces(self) -> Array:
        return self.interfaces[-1] - self.interfaces[::-1] if self.mirrored else self.interfaces

    def _solved_materials(self) -> tuple:
        return self.materials[::-1] if self.mirrored else self.materials


def _energy_jump_sum(c: float, a: float, interfaces: Array, materials: tuple) -> float:
    """Σ_K [Ŵ_K(λ_K^+) − Ŵ_K(λ_K^-)], i.e. σ_rr at the top face when the bottom is free."""
    lam = np.sqrt(2.0 * a * interfaces + c)
    total = 0.0
    for k, material in enumerate(materials):
        W, _ = plane_strain_energy(material, lam[k : k + 2])
        total += W[1] - W[0]
    return float(total)


def _solve_positive(a: float, interfaces: Array, materials: tuple) -> BendingSolution:
    H = float(interfaces[-1])
    c_low = max(1.0 - 2.0 * a * H, 0.0)
    c_high = 1.0
    g_high = _energy_jump_sum(c_high, a, interfaces, materials)
    # Walk the lower bracket end towards c_low (λ_bottom → 0 may overflow some laws).
    c_try = c_low if c_low > 0.0 else 1e-3
    g_low = _energy_jump_sum(c_try, a, interfaces, materials)
    while c_low == 0.0 and g_low >= 0.0 and c_try > 1e-12:
        c_try *= 1e-2
        g_low = _energy_jump_sum(c_try, a, interfaces, materials)
    if not (g_low <= 0.0 <= g_high):
        raise ValueError(
            f"bend: no traction-free state with λ_bottom < 1 < λ_top for a={a!r} "
            f"(energy jump {g_low:.3g} at c={c_try:.3g}, {g_high:.3g} at c=1); is Ŵ minimal at λ=1?"
        )
    c = brentq(_energy_jump_sum, c_try, c_high, args=(a, interfaces, materials), xtol=1e-16, rtol=1e-15)
    neutral = (1.0 - c) / (2.0 * a)
    trial = BendingSolution(a, c, interfaces, materials, neutral, np.nan, np.nan, np.sqrt(c), np.sqrt(c + 2 * a * H))
    # Gauss–Legendre on every layer, split at the neutral axis where a bimodular Ŵ has a kink.
    cuts = np.unique(np.concatenate([interfaces, [neutral]]))
    segments = list(zip(cuts[:-1], cuts[1:], strict=True))
    Y = np.concatenate([0.5 * (y1 - y0) * _GAUSS_POINTS + 0.5 * (y1 + y0) for y0, y1 in segments])
    w = np.concatenate([0.5 * (y1 - y0) * _GAUSS_WEIGHTS for y0, y1 in segments])
    lam, s_rr, s_tt = trial.profile(Y)
    # −∫σ_rr dY is better conditioned at small a than ∫σ_θθ dY (σ_rr = O(a²), no cancellation).
    moment = -float(w @ s_rr) / a
    axial = float(w @ (s_tt / lam))
    return BendingSolution(a, c, interfaces, materials, neutral, moment, axial, trial.lambda_bottom, trial.lambda_top)


def bend(layers: Sequence[tuple[float, object]], a: float) -> BendingSolution:
    r"""Rivlin pure bending of ``layers`` (``(thickness, material)`` from the bottom face up).

    ``a`` is the bending angle per reference length (= change of curvature Δκ); ``a > 0``
    stretches the top face, ``a < 0`` the bottom face. Returns a :class:`BendingSolution`.
    """
    thicknesses, materials = _check_layers(layers)
    try:
        a = check_scalar("a (the curvature change)", a)
    except TypeError as err:
        raise TypeError(f"bend: {err}") from None
    if not np.isfinite(a) or a == 0.0:
        raise ValueError(f"bend: curvature a must be finite and non-zero; got {a!r}")
    interfaces = np.concatenate([[0.0], np.cumsum(thicknesses)])
    if a > 0.0:
        return _solve_positive(a, interfaces, materials)
    H = interfaces[-1]
    flipped = _solve_positive(-a, H - interfaces[::-1], materials[::-1])
    return BendingSolution(
        a=a,
        c=flipped.c,
        interfaces=interfaces,
        materials=materials,
        neutral_axis=H - flipped.neutral_axis,
        moment=-flipped.moment,
        axial_force=flipped.axial_force,
        lambda_bottom=flipped.lambda_top,
        lambda_top=flipped.lambda_bottom,
        mirrored=True,
    )


def moment_curvature(layers: Sequence[tuple[float, object]], curvatures: ArrayLike) -> Array:
    """Moment per unit width M(Δκ) for each curvature change (M = 0 at Δκ = 0)."""
    try:
        curvatures = check_array("curvatures", curvatures)
    except (TypeError, ValueError) as err:
        raise type(err)(f"moment_curvature: {err}") from None
    _check_layers(layers)
    out = np.zeros(curvatures.shape)
    for idx, kappa in np.ndenumerate(curvatures):
        out[idx] = 0.0 if kappa == 0.0 else bend(layers, kappa).moment
    return out
