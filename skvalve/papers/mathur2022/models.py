"""mathur2022 laws in skvalve units (kPa) from the TriValve parameters of
:mod:`skvalve.papers.mathur2022.data` (file units: MPa)."""

from __future__ import annotations

from ...materials import LeeSacks, Ogden
from .data import ChordaeParameters, LeafletParameters

__all__ = ["MPA_TO_KPA", "leaflet_law", "chordae_law"]

MPA_TO_KPA = 1e3


def leaflet_law(p: LeafletParameters) -> LeeSacks:
    """Eq. 1 as shipped (``VUANISO_ISO``: exponent c2 (Ī1 − 3)²), moduli in kPa, D in 1/kPa."""
    return LeeSacks(c0=p.c0 * MPA_TO_KPA, c1=p.c1 * MPA_TO_KPA, c2=p.c2, D=p.D / MPA_TO_KPA)


def chordae_law(p: ChordaeParameters) -> Ogden:
    """Eq. 2, Abaqus ``*Hyperelastic, OGDEN, N=3``, μ_i in kPa, D1 in 1/kPa."""
    return Ogden(mu=tuple(m * MPA_TO_KPA for m in p.mu), alpha=p.alpha, D=(p.D1 / MPA_TO_KPA,))
