"""Exponential collagen-fiber force law of Thomas et al. (2019), Eq. 9 (after Billiar & Sacks).

A fiber of cross-section ``A_f`` and modulus ``E_f`` carries the axial force

    f(λ) = E_f A_f / β · (exp(β e_G) − 1),                       λ < λc
    f(λ) = f(λc) + E_f A_f λc exp(β e_G^c) (λ − λc),              λ ≥ λc

with the fiber Green strain e_G = (λ² − 1)/2 and e_G^c = (λc² − 1)/2.

Derivation of the stiffness k = df/dλ: since de_G/dλ = λ,

    k(λ) = E_f A_f λ exp(β e_G)            (λ < λc),
    k(λ) = E_f A_f λc exp(β e_G^c)         (λ ≥ λc),

so both force and stiffness are continuous at λc (the linear branch is the tangent line of
the exponential one): the law is C¹, but not C² (the curvature jumps to zero).

Compression (λ < 1).  The paper's formula is used for every λ: for λ < 1 it gives a small
compressive force, bounded below by −E_f A_f/β (≈ −2 % of E_f A_f for β = 50.5), with a
positive but exponentially small stiffness.  This keeps the network stiffness matrix
non-singular at the reference state and is what the fitted parameters were obtained with, so
it is the default (``compression="paper"``).  Many network models instead let fibers buckle
(no compressive force); ``compression="buckle"`` gives f = 0 for λ < 1 — regularised by a
residual linear stiffness ``slack_stiffness · E_f A_f`` (default 1e-3) so that slack fibers
never make the network stiffness matrix singular.  1e-3 is three orders below the tensile
stiffness at λ = 1 and about what the paper's own law has at λ ≈ 0.86; much smaller values
(1e-6) make the stiffness jump at λ = 1 so large that Newton iterations of compressed networks
stall at the kink.

Units are those of the inputs: E_f in Pa and A_f in m² give forces in N.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from .base import check_array, check_nonnegative, check_positive

_COMPRESSION_MODES = ("paper", "buckle")


def _positive(name: str, value: float) -> float:
    try:
        return check_positive(name, value)
    except (TypeError, ValueError) as err:
        raise type(err)(f"ExponentialFiber: {err}") from None


class ExponentialFiber:
    """Axial force of a collagen fiber, Thomas et al. (2019) Eq. 9.

    Parameters
    ----------
    E_f : fiber modulus (Pa), > 0.
    A_f : fiber cross-sectional area (m²), > 0.
    beta : exponential nonlinearity β (dimensionless), > 0.
    lambda_c : critical stretch λc beyond which the force grows linearly, > 1.
    compression : "paper" (Eq. 9 for all λ, default) or "buckle" (no compressive force).
    slack_stiffness : residual stiffness of a buckled fiber, relative to E_f A_f ("buckle").
    """

    def __init__(
        self,
        E_f: float,
        A_f: float,
        beta: float,
        lambda_c: float,
        compression: str = "paper",
        slack_stiffness: float = 1e-3,
    ) -> None:
        self.E_f = _positive("E_f", E_f)
        self.A_f = _positive("A_f", A_f)
        self.beta = _positive("beta", beta)
        self.lambda_c = _positive("lambda_c", lambda_c)
        if self.lambda_c <= 1.0:
            raise ValueError(f"ExponentialFiber: lambda_c must be > 1, got {self.lambda_c}")
        if compression not in _COMPRESSION_MODES:
            raise ValueError(f"ExponentialFiber: compression must be one of {_COMPRESSION_MODES}, got {compression!r}")
        self.compression = compression
        try:
            self.slack_stiffness = check_nonnegative("slack_stiffness", slack_stiffness)
        except (TypeError, ValueError) as err:
            raise type(err)(f"ExponentialFiber: {err}") from None
        self.strain_c = 0.5 * (self.lambda_c**2 - 1.0)

    @classmethod
    def from_diameter(cls, E_f: float, diameter: float, beta: float, lambda_c: float, **kwargs) -> ExponentialFiber:
        """Fiber with a circular cross-section A_f = π d²/4 (thomas2019: ``papers.thomas2019.data.FIBER.diameter``)."""
        diameter = _positive("diameter", diameter)
        return cls(E_f, math.pi * diameter**2 / 4.0, beta, lambda_c, **kwargs)

    @property
    def axial_rigidity(self) -> float:
        """E_f A_f, the force scale of Eq. 9."""
        return self.E_f * self.A_f

    def parameters(self) -> np.ndarray:
        """(β, λc, e_G^c, buckle flag, slack stiffness) for the numba kernels (forces / E_f A_f)."""
        return np.array(
            [
                self.beta,
                self.lambda_c,
                self.strain_c,
                1.0 if self.compression == "buckle" else 0.0,
                self.slack_stiffness,
            ]
        )

    def _checked(self, stretch: ArrayLike) -> np.ndarray:
        try:
            lam = check_array("stretch", stretch, finite=False)
        except (TypeError, ValueError) as err:
            raise type(err)(f"ExponentialFiber: {err}") from None
        if not np.all(np.isfinite(lam)) or np.any(lam <= 0.0):
            bad = np.atleast_1d(lam)[~(np.isfinite(np.atleast_1d(lam)) & (np.atleast_1d(lam) > 0.0))][0]
            raise ValueError(f"ExponentialFiber: stretch must be finite and > 0; got {float(bad)!r}")
        return lam

    def _scaled(self, what: str, lam: np.ndarray, normalized: np.ndarray) -> np.ndarray:
        """E_f A_f times the kernel output, or ``ValueError`` where exp(β e_G) overflowed."""
        if not np.all(np.isfinite(normalized)):
            bad = lam.ravel()[~np.isfinite(normalized)][0]
            raise ValueError(
                f"ExponentialFiber: {what} overflows at stretch {float(bad)!r} "
                f"(exp(beta e_G) beyond float range for beta = {self.beta:g})"
            )
        return self.axial_rigidity * normalized.reshape(lam.shape)

    def force(self, stretch: ArrayLike) -> np.ndarray:
        """Axial force f(λ), Eq. 9 (same units as E_f A_f)."""
        lam = self._checked(stretch)
        return self._scaled("force", lam, _evaluate(lam.ravel(), self.parameters())[0])

    def stiffness(self, stretch: ArrayLike) -> np.ndarray:
        """Tangent stiffness df/dλ of Eq. 9."""
        lam = self._checked(stretch)
        return self._scaled("stiffness", lam, _evaluate(lam.ravel(), self.parameters())[1])

    def energy(self, stretch: ArrayLike) -> np.ndarray:
        """Stored energy per unit rest length, W(λ) = ∫₁^λ f dλ' (units of E_f A_f)."""
        lam = self._checked(stretch)
        params = self.parameters()
        flat = np.array([normalized_energy(value, params) for value in lam.ravel()])
        return self._scaled("energy", lam, flat)

    def __repr__(self) -> str:
        return (
            f"ExponentialFiber(E_f={self.E_f:g}, A_f={self.A_f:g}, beta={self.beta:g}, "
            f"lambda_c={self.lambda_c:g}, compression={self.compression!r})"
        )


@njit(cache=True)
def normalized_force_stiffness(lam: float, params: np.ndarray) -> tuple[float, float]:
    """(f, df/dλ) of Eq. 9 divided by E_f A_f; ``params`` from :meth:`ExponentialFiber.parameters`.

    This scalar kernel is the single implementation of the law, shared by the vectorised
    methods above and by the network solver (``skvalve.networks.rve``).
    """
    beta, lambda_c, strain_c, buckle, slack = params[0], params[1], params[2], params[3], params[4]
    if buckle > 0.0 and lam < 1.0:
        return slack * (lam - 1.0), slack
    # expm1: (exp(β e) − 1)/β keeps its precision for small β e (→ e, the linear limit)
    # (one transcendental per call: exp = expm1 + 1, correctly rounded to within an ulp)
    if lam < lambda_c:
        growth = math.expm1(beta * 0.5 * (lam * lam - 1.0))
        return growth / beta, lam * (growth + 1.0)
    growth_c = math.expm1(beta * strain_c)
    return growth_c / beta + lambda_c * (growth_c + 1.0) * (lam - lambda_c), lambda_c * (growth_c + 1.0)


# 12-point Gauss–Legendre rule on [−1, 1] for the strain energy of the exponential branch
# (tuples, not arrays: numba cannot cache parallel functions that reach global arrays)
_GAUSS_X, _GAUSS_W = (tuple(float(v) for v in table) for table in np.polynomial.legendre.leggauss(12))


@njit(cache=True)
def normalized_energy(lam: float, params: np.ndarray) -> float:
    """W(λ) = ∫₁^λ f dλ' / (E_f A_f), the stored energy per unit rest length of the fiber.

    The exponential branch has no elementary antiderivative (it is an erfi); its integrand is
    smooth, so a 12-point Gauss rule is exact to round-off over the stretches that occur.
    """
    beta, lambda_c, buckle, slack = params[0], params[1], params[3], params[4]
    if buckle > 0.0 and lam < 1.0:
        return 0.5 * slack * (lam - 1.0) ** 2
    upper = min(lam, lambda_c)
    half, mid = 0.5 * (upper - 1.0), 0.5 * (upper + 1.0)
    energy = 0.0
    for g in range(len(_GAUSS_X)):
        s = mid + half * _GAUSS_X[g]
        energy += _GAUSS_W[g] * math.expm1(beta * 0.5 * (s * s - 1.0)) / beta
    energy *= half
    if lam > lambda_c:
        f_c, k_c = normalized_force_stiffness(lambda_c, params)
        energy += f_c * (lam - lambda_c) + 0.5 * k_c * (lam - lambda_c) ** 2
    return energy


@njit(cache=True)
def _evaluate(lam: np.ndarray, params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    force = np.empty_like(lam)
    stiffness = np.empty_like(lam)
    for i in range(lam.size):
        force[i], stiffness[i] = normalized_force_stiffness(lam[i], params)
    return force, stiffness
