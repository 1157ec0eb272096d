"""buchanan2014 models built from :mod:`skvalve.papers.buchanan2014.data`:
the layered strips and their exact (Rivlin) responses.

Layers are ``[(thickness, law), ...]`` bottom up (ventricularis first), as
:func:`skvalve.analytic.rivlin.bend` takes them. AC bending stretches the fibrosa face (``a > 0``),
WC the ventricularis face (``a < 0``): :data:`SIGN`.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from ...analytic.rivlin import bend, moment_curvature
from ...materials import BimodularNeoHookean, IncompressibleNeoHookean, Ogden
from .data import BILAYER_FRACTIONS, MODEL_STRIP, MU_OUTER, SPECIMEN_STRIP, TABLE3, TRILAYER_FRACTIONS, LayerModuli

__all__ = [
    "SIGN", "CIRCUMFERENTIAL", "BIMODULAR_SMOOTHING", "trilayer", "bimodular_bilayer", "neutral_axis",
    "unbonded_stretch", "tension_modulus_for_neutral_axis", "ogden_normalised_moment",
]

SIGN = {"AC": 1.0, "WC": -1.0}  # sign of the bending angle a: AC stretches the fibrosa (top) face
CIRCUMFERENTIAL = (1.0, 0.0, 0.0)  # X1, the strip axis: the direction of the bimodular switch (Eq. 4)
BIMODULAR_SMOOTHING = 1e-2  # width of the modulus switch in I4 for the FE (a model choice, not in the paper)


def trilayer(mu_spongiosa: float, thickness: float = MODEL_STRIP.thickness, mu_outer: float = MU_OUTER) -> list:
    """Neo-Hookean (Eq. 3) tri-layer, ventricularis/spongiosa/fibrosa 25/30/45 % bottom up (Sect. 2.2)."""
    mu = {"ventricularis": mu_outer, "spongiosa": mu_spongiosa, "fibrosa": mu_outer}
    return [(f * thickness, IncompressibleNeoHookean(mu[name])) for name, f in TRILAYER_FRACTIONS]


def bimodular_bilayer(thickness: float = SPECIMEN_STRIP.thickness, smoothed: bool = False,
                      moduli: dict[str, LayerModuli] = TABLE3) -> list:
    """Bimodular neo-Hookean (Eq. 4) bilayer, ventricularis 40 % at the bottom, Table 3 moduli by default.

    ``smoothed``: tanh switch over δ = :data:`BIMODULAR_SMOOTHING` in I4 = a·Ca, for Newton in the FE
    (the Rivlin neutral axis moves by < 1e-4).
    """
    smoothing = BIMODULAR_SMOOTHING if smoothed else 0.0
    return [(f * thickness, BimodularNeoHookean(*moduli[name], CIRCUMFERENTIAL, smoothing=smoothing))
            for name, f in BILAYER_FRACTIONS]


def neutral_axis(layers: list, direction: str, curvature: float) -> float:
    """Normalised neutral axis (0 = ventricularis face) of Rivlin bending in ``"AC"`` or ``"WC"``."""
    if direction not in SIGN:
        raise ValueError(f"direction must be 'AC' or 'WC'; got {direction!r}")
    return bend(layers, SIGN[direction] * curvature).normalised_neutral_axis


def unbonded_stretch(layers: list, curvature: float, Y: np.ndarray) -> np.ndarray:
    """Λ1 when every layer bends alone to the same curvature (the no-bond limit of Figs. 4, 9)."""
    Y = np.asarray(Y, dtype=float)
    out = np.empty_like(Y)
    y0 = 0.0
    for k, (h, material) in enumerate(layers):
        last = k == len(layers) - 1
        mask = (Y >= y0) & ((Y <= y0 + h) if last else (Y < y0 + h))
        out[mask] = bend([(h, material)], curvature).profile(Y[mask] - y0)[0]
        y0 += h
    return out


def tension_modulus_for_neutral_axis(direction: str, target: float, curvature: float = 0.2) -> float:
    """μ+ of the layer carrying the tension (AC: fibrosa, WC: ventricularis) that puts the Rivlin
    neutral axis of the Table 3 bilayer at ``target``; the other three moduli stay at Table 3."""
    layer = {"AC": "fibrosa", "WC": "ventricularis"}[direction]

    def mismatch(mu_plus: float) -> float:
        moduli = dict(TABLE3, **{layer: LayerModuli(mu_plus, TABLE3[layer].mu_compression)})
        return neutral_axis(bimodular_bilayer(moduli=moduli), direction, curvature) - target

    return brentq(mismatch, 1.0, 5000.0, xtol=1e-6)


def ogden_normalised_moment(alpha: float, curvatures: np.ndarray, thickness: float = MODEL_STRIP.thickness,
                            mu: float = MU_OUTER) -> np.ndarray:
    """Fig. 3: M(Δκ)/M(Δκ_max) of a one-term Ogden block (Eq. 1; normalisation removes μ)."""
    M = moment_curvature([(thickness, Ogden(mu=(mu,), alpha=(alpha,)))], curvatures)
    return M / M[-1]
