"""Constitutive laws: one law per module, each a strain energy with stress and tangent derived.

Continuum laws share the interface of :class:`~skvalve.materials.base.Hyperelastic`:
``psi(F)``, ``pk1(F)``, ``cauchy(F)``, ``tangent(F)`` with ``F`` of shape ``(3, 3, *batch)``.
"""

from .base import Hyperelastic, VolumetricEnergy
from .bimodular_neo_hookean import BimodularNeoHookean
from .exponential_fiber import ExponentialFiber
from .incompressible_neo_hookean import IncompressibleNeoHookean
from .lee_sacks import LeeSacks
from .neo_hookean import NeoHookean
from .ogden import Ogden

__all__ = [
    "Hyperelastic",
    "VolumetricEnergy",
    "NeoHookean",
    "IncompressibleNeoHookean",
    "Ogden",
    "LeeSacks",
    "BimodularNeoHookean",
    "ExponentialFiber",
]

