"""thomas2019's laws with the fitted parameters, and the FE² material of a sample.

* :func:`matrix_law` — Eq. 10, compressible neo-Hookean (Bonet & Wood) with G = 2.1 kPa, ν = 0.49.
* :func:`fiber_law` — Eq. 9, exponential-linear fiber with E_f = 10.5 kPa, β = 50.5, λc = 1.12, d = 450 nm.
* :func:`fe2_material` — :class:`~skvalve.multiscale.RVEMaterial` over a sample's networks (one RVE per
  Gauss point, ψ = 0.43).
"""

from __future__ import annotations

from ...materials.exponential_fiber import ExponentialFiber
from ...materials.neo_hookean import NeoHookean
from ...multiscale.material import RVEMaterial
from . import data
from .sample import Sample

__all__ = ["matrix_law", "fiber_law", "fe2_material"]


def matrix_law(G: float = data.G, nu: float = data.NU) -> NeoHookean:
    """Eq. 10: σ = G/J (B − I) + 2Gν/(J(1 − 2ν)) ln J I (defaults: the paper's fit, §3)."""
    return NeoHookean.from_shear_poisson(G, nu)


def fiber_law(E_f: float = data.E_F, beta: float = data.BETA, lambda_c: float = data.LAMBDA_C,
              diameter: float = data.FIBER_DIAMETER) -> ExponentialFiber:
    """Eq. 9 with A_f = π d²/4 (defaults: the paper's fit, §3, and d = 450 nm, §2.5)."""
    return ExponentialFiber.from_diameter(E_f, diameter, beta, lambda_c)


def fe2_material(sample: Sample, matrix: NeoHookean | None = None, fiber: ExponentialFiber | None = None,
                 psi: float = data.PSI, tol: float = 1e-10) -> RVEMaterial:
    """One RVE of the element's network at each of the 8 Gauss points of every hex of ``sample``."""
    return RVEMaterial(sample.networks, matrix_law() if matrix is None else matrix,
                       fiber_law() if fiber is None else fiber, n_points=data.GAUSS_POINTS, psi=psi,
                       fiber_diameter=data.FIBER_DIAMETER, tol=tol)
