r"""Least-squares fit of (G, E_f, β, λc) to biaxial tension–stretch data with the homogeneous RVE model.

The fast path of thomas2019 §2.6: each data point (λ1, λ2) of a protocol is evaluated with
:class:`~skvalve.multiscale.HomogeneousBiaxial` (every network under F = diag(λ1, λ2, λ3), λ3 from
P̄33 = 0), giving model tensions :math:`\hat T`; the parameters minimise
:math:`\sum (\hat T - T)^2` over both axes of all protocols (scipy ``least_squares``, on log-parameters and
log(λc − 1) so that G, E_f, β > 0 and λc > 1 hold). The fit quality is Eq. 12,

.. math::

    R^2 = 1 - \frac{\sum_i (y_i - \hat y_i)^2}{\sum_i (y_i - \bar y)^2},

per protocol and over all protocols, y the measured tensions (both axes).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..materials.exponential_fiber import ExponentialFiber
from ..materials.neo_hookean import NeoHookean
from ..networks.network import Network
from .homogeneous import HomogeneousBiaxial
from .material import RVEMaterial

__all__ = ["BiaxialData", "FiberParameters", "FitResult", "model_tensions", "r_squared", "fit_parameters"]


@dataclass(frozen=True)
class FiberParameters:
    """The four fitted parameters of thomas2019: G (Pa), E_f (Pa), β, λc."""

    G: float
    E_f: float
    beta: float
    lambda_c: float

    def vector(self) -> np.ndarray:
        return np.array([math.log(self.G), math.log(self.E_f), math.log(self.beta), math.log(self.lambda_c - 1.0)])

    @classmethod
    def from_vector(cls, x: np.ndarray) -> FiberParameters:
        return cls(math.exp(x[0]), math.exp(x[1]), math.exp(x[2]), 1.0 + math.exp(x[3]))

    def scaled(self, name: str, factor: float) -> FiberParameters:
        values = dict(G=self.G, E_f=self.E_f, beta=self.beta, lambda_c=self.lambda_c)
        values[name] *= factor
        return FiberParameters(**values)


@dataclass
class BiaxialData:
    """One protocol's tension–stretch path: stretches (n, 2) and tensions (n, 2) in N/m, in loading order."""

    label: str
    stretch: np.ndarray
    tension: np.ndarray

    def __post_init__(self) -> None:
        self.stretch = np.asarray(self.stretch, dtype=float)
        self.tension = np.asarray(self.tension, dtype=float)
        if self.stretch.ndim != 2 or self.stretch.shape[1] != 2 or self.stretch.shape != self.tension.shape:
            raise ValueError(f"BiaxialData {self.label!r}: stretch and tension must both have shape (n, 2)")
        if not (np.all(np.isfinite(self.stretch)) and np.all(np.isfinite(self.tension))):
            raise ValueError(f"BiaxialData {self.label!r}: non-finite values")


@dataclass
class Setting:
    """What stays fixed in a fit: the networks, ν, ψ, fiber diameter and sample thickness."""

    networks: Sequence[Network]
    nu: float
    psi: float
    diameter: float
    thickness: float


def model_tensions(params: FiberParameters, setting: Setting, stretch: np.ndarray) -> np.ndarray:
    """Homogeneous-model tensions (n, 2) along one loading path of stretches (n, 2)."""
    matrix = NeoHookean.from_shear_poisson(params.G, setting.nu)
    fiber = ExponentialFiber.from_diameter(params.E_f, setting.diameter, params.beta, params.lambda_c)
    material = RVEMaterial(setting.networks, matrix, fiber, n_points=1, psi=setting.psi,
                           fiber_diameter=setting.diameter)
    model = HomogeneousBiaxial(material, setting.thickness)
    return np.array([model.tensions_at(l1, l2) for l1, l2 in np.asarray(stretch, dtype=float)])


def r_squared(measured: np.ndarray, predicted: np.ndarray) -> float:
    """Eq. 12 over all entries of ``measured``."""
    y, yhat = np.ravel(measured), np.ravel(predicted)
    return float(1.0 - np.sum((y - yhat) ** 2) / np.sum((y - y.mean()) ** 2))


@dataclass
class FitResult:
    """Fitted parameters, R² per protocol and overall (Eq. 12), SSE, model evaluations."""

    params: FiberParameters
    r2: dict[str, float]
    r2_overall: float
    sse: float
    evaluations: int
    predicted: dict[str, np.ndarray]


def evaluate(params: FiberParameters, setting: Setting, data: Sequence[BiaxialData]) -> tuple[dict, dict, float, float]:
    """(predicted tensions, R² per protocol, overall R², SSE) of ``params`` on ``data``."""
    predicted = {d.label: model_tensions(params, setting, d.stretch) for d in data}
    r2 = {d.label: r_squared(d.tension, predicted[d.label]) for d in data}
    measured = np.concatenate([d.tension.ravel() for d in data])
    model = np.concatenate([predicted[d.label].ravel() for d in data])
    return predicted, r2, r_squared(measured, model), float(np.sum((measured - model) ** 2))


def fit_parameters(data: Sequence[BiaxialData], setting: Setting, start: FiberParameters,
                   xtol: float = 1e-10) -> FitResult:
    """Least-squares fit of (G, E_f, β, λc) starting from ``start`` (module docstring)."""
    if not data:
        raise ValueError("fit_parameters: no data")
    count = [0]

    def residual(x):
        count[0] += 1
        params = FiberParameters.from_vector(x)
        return np.concatenate([(model_tensions(params, setting, d.stretch) - d.tension).ravel() for d in data])

    solution = least_squares(residual, start.vector(), xtol=xtol, ftol=1e-12, gtol=1e-12, diff_step=1e-6)
    params = FiberParameters.from_vector(solution.x)
    predicted, r2, overall, sse = evaluate(params, setting, data)
    return FitResult(params, r2, overall, sse, count[0], predicted)
