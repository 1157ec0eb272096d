"""buchanan2014 figures: Figs. 3, 4/9 (bounds and end loading), 7, 8 and 11 from the models and FE studies.

Each ``figure_*`` draws into new axes (or the given ones) and returns them; :func:`write_figure` saves one
atomically with the readable style of :mod:`skvalve.papers.plotting`. Symbols: Λ1 axial stretch
√(U11² + U12²) (Sect. 2.3), Δκ curvature change, μS spongiosa shear modulus, NA neutral axis, V/F the
ventricularis/fibrosa faces (normalised thickness 0/1), S the sliding measure of :mod:`.sliding`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ...analytic.rivlin import bend
from ..plotting import readable_style, save_figure
from .data import (
    CURVATURES,
    FIG3_ALPHAS,
    FIG3_MAX_CURVATURE,
    FIG8_NEUTRAL_AXIS,
    FIG11_THICKNESSES,
    MODEL_STRIP,
    SPECIMEN_STRIP,
    SPONGIOSA_MODULI,
    TABLE2,
    TRILAYER_FRACTIONS,
)
from .models import SIGN, bimodular_bilayer, neutral_axis, ogden_normalised_moment, trilayer, unbonded_stretch

__all__ = [
    "figure_3", "figure_4_bounds", "figure_8", "figure_7", "figure_11", "figure_4_9_end_loading", "write_figure",
    "ANALYTIC_FIGURES",
]

THICKNESS_LABEL = "normalised thickness (0 = ventricularis V, 1 = fibrosa F)"
STRETCH_LABEL = "axial stretch Λ1 = √(U11² + U12²)"
_INTERFACES = np.cumsum([f for _, f in TRILAYER_FRACTIONS])[:-1]  # 0.25, 0.55


def _axes(axes, ncols: int, width: float, height: float = 4.2, sharey: bool = False):
    if axes is not None:
        return np.atleast_1d(axes)
    return np.atleast_1d(plt.subplots(1, ncols, figsize=(width, height), sharey=sharey, squeeze=False,
                                      layout="constrained")[1][0])


def _label_thickness(axes) -> None:
    """The thickness axis label: once below a row of panels (the label is long), else on the axes."""
    if len(axes) > 1:
        axes[0].figure.supxlabel(THICKNESS_LABEL, fontsize=10)
    else:
        axes[0].set_xlabel(THICKNESS_LABEL)


def figure_3(ax=None):
    """Fig. 3 model family: normalised M–Δκ of one-term Ogden blocks (Eq. 1) for several α."""
    ax = _axes(ax, 1, 6.4)[0]
    kappa = np.linspace(0.0, FIG3_MAX_CURVATURE, 29)
    for alpha in FIG3_ALPHAS:
        ax.plot(kappa, ogden_normalised_moment(alpha, kappa), label=f"α = {alpha:g}")
    ax.set(xlabel="curvature change Δκ (mm⁻¹)", ylabel=f"moment M / M(Δκ = {FIG3_MAX_CURVATURE} mm⁻¹)",
           title=f"Fig. 3: one-term Ogden (Eq. 1), Rivlin, H = {MODEL_STRIP.thickness} mm")
    ax.legend(title="Ogden exponent (experiment\nnot published)", loc="upper left")
    return ax


def figure_4_bounds(axes=None, direction: str = "WC"):
    """Figs. 4/9 bounds: Λ1 through the thickness in pure bending, bonded (Rivlin) and unbonded, per μS and Δκ."""
    axes = _axes(axes, 3, 14.0, sharey=True)
    H = MODEL_STRIP.thickness
    Y = np.linspace(0.0, H, 241)
    for ax, kappa in zip(axes, CURVATURES, strict=True):
        for k, mu_s in enumerate(SPONGIOSA_MODULI):
            ax.plot(Y / H, bend(trilayer(mu_s, H), SIGN[direction] * kappa).profile(Y)[0], f"C{k}",
                    label=f"bonded, μS = {mu_s:g} kPa")
        ax.plot(Y / H, unbonded_stretch(trilayer(1e-3, H), SIGN[direction] * kappa, Y), "k--",
                label="unbonded (each layer alone)")
        for f in _INTERFACES:
            ax.axvline(f, color="0.8", lw=0.8)
        ax.set(title=f"pure bending, {direction}, Δκ = {kappa} mm⁻¹")
    _label_thickness(axes)
    axes[0].set_ylabel(STRETCH_LABEL)
    axes[0].figure.legend(*axes[0].get_legend_handles_labels(), loc="outside right upper",
                          title="spongiosa shear modulus μS\n(outer layers 45 kPa)")
    return axes


def figure_8(axes=None):
    """Neutral axis of the bimodular bilayer vs Δκ (Rivlin) beside Fig. 8 and Table 2; Λ1 profiles.

    The legend sits below the panels, clear of the data.
    """
    axes = _axes(axes, 2, 11.0, 4.6)
    H = SPECIMEN_STRIP.thickness
    bilayer = bimodular_bilayer(H)
    kappa = np.linspace(0.02, 0.3, 15)
    table_kappa = np.array(list(TABLE2))
    for k, direction in enumerate(("WC", "AC")):
        c = f"C{k}"
        shift = 0.004 * (1 if direction == "AC" else -1)
        sim = [getattr(v, f"{direction.lower()}_simulation") for v in TABLE2.values()]
        exp = [getattr(v, f"{direction.lower()}_experiment") for v in TABLE2.values()]
        sd = [getattr(v, f"{direction.lower()}_sd") for v in TABLE2.values()]
        axes[0].plot(kappa, [neutral_axis(bilayer, direction, q) for q in kappa], c, label=f"Rivlin {direction}")
        axes[0].axhline(FIG8_NEUTRAL_AXIS[direction], color=c, ls=":", label=f"Fig. 8 {direction} (centre)")
        axes[0].plot(table_kappa + shift, sim, c + "s", mfc="none", label=f"Table 2 simulation {direction} (edge)")
        axes[0].errorbar(table_kappa - shift, exp, sd, fmt=c + "o", capsize=3,
                         label=f"Table 2 experiment {direction} (± SD)")
        Y = np.linspace(0.0, H, 201)
        axes[1].plot(Y / H, bend(bilayer, SIGN[direction] * 0.2).profile(Y)[0], c, label=f"{direction}, Δκ = 0.2 mm⁻¹")
    axes[0].set(xlabel="curvature change Δκ (mm⁻¹)", ylabel="neutral axis NA (0 = V, 1 = F)",
                title="Bimodular bilayer (Table 3 moduli)")
    axes[1].axhline(1.0, color="0.6", lw=0.8)
    axes[1].axvline(0.4, color="0.8", lw=0.8)
    axes[1].set(xlabel=THICKNESS_LABEL, ylabel=STRETCH_LABEL, title="Rivlin Λ1, bimodular bilayer")
    axes[1].legend(loc="upper center")
    axes[0].figure.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=4)
    return axes


def figure_7(warp: dict, axes=None):
    """Fig. 7 b, c: Λ1 through the thickness at the centre and at the free edge of the 3D strip."""
    axes = _axes(axes, 2, 11.0, sharey=True)
    Y = warp["Y"] / warp["H"]
    for ax, direction in zip(axes, ("WC", "AC"), strict=True):
        ax.plot(Y, warp[direction]["centre"], "C0", label="centre (Z = 0)")
        ax.plot(Y, warp[direction]["edge"], "C3--", label="free edge (Z = W/2, W the width)")
        ax.axhline(1.0, color="0.6", lw=0.8)
        ax.set(title=f"3D strip, {direction}, Δκ = 0.2 mm⁻¹")
    _label_thickness(axes)
    axes[0].set_ylabel(STRETCH_LABEL)
    axes[-1].legend(loc="upper left")  # AC: the lines start low on the left
    return axes


def figure_11(table: np.ndarray, ax=None):
    """Fig. 11: edge–centre warping max ``|ΔΛ1|`` versus strip thickness, one line per curvature."""
    ax = _axes(ax, 1, 6.4)[0]
    for j, curvature in enumerate(CURVATURES):
        ax.plot(FIG11_THICKNESSES, table[:, j], "o-", label=f"Δκ = {curvature} mm⁻¹")
    ax.set(xlabel="thickness H (mm)", ylabel="max |Λ1 at the edge − Λ1 at the centre|",
           title="3D strip warping (Fig. 11)")
    ax.legend(loc="upper left")
    return ax


def figure_4_9_end_loading(study: dict, axes=None):
    """Figs. 4/9: Λ1 through the thickness at the centre of the pin-ended strip, one line per μS, one panel
    per Δκ. Legend: μS and the sliding measure S = J(μS) − J(45 kPa), J the jump of Λ1 across the spongiosa
    (fibrosa minus ventricularis line, extrapolated to the spongiosa mid-plane)."""
    curvatures = study["curvatures"]
    axes = _axes(axes, len(curvatures), max(8.0, 4.5 * len(curvatures) + 2.5), 5.0, sharey=True)
    Y = study["Y"] / study["H"]
    for ax, kappa in zip(axes, curvatures, strict=True):
        for k, mu in enumerate(sorted(study["moduli"])):
            ax.plot(Y, study["profiles"][(mu, kappa)], f"C{k}",
                    label=f"{1000 * mu:g} Pa: {study['sliding'][(mu, kappa)]:+.3f}")
        for f in _INTERFACES:
            ax.axvline(f, color="0.8", lw=0.8)
        ax.axhline(1.0, color="0.6", lw=0.8)
        ax.set(title=f"pin-ended end loading, {study['direction']}, Δκ = {kappa} mm⁻¹")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                  title="μS: sliding S")
    _label_thickness(axes)
    axes[0].set_ylabel(STRETCH_LABEL + " at the centre")
    axes[0].figure.suptitle("sliding S = J(μS) − J(45 kPa), J = jump of Λ1 across the spongiosa:\nline fitted in the "
                            "fibrosa minus line fitted in the ventricularis, at the spongiosa mid-plane",
                            fontsize=10)
    return axes


def write_figure(out: Path, name: str, draw: Callable[[], object]) -> Path:
    """Draw (``draw()`` makes its own figure) in the readable style and save ``out/buchanan2014_<name>.png``."""
    with readable_style():
        axes = np.atleast_1d(draw())
        fig = axes[0].figure
        try:
            return save_figure(fig, Path(out) / f"buchanan2014_{name}.png")
        finally:
            plt.close(fig)


ANALYTIC_FIGURES = (
    ("fig3_ogden_moment_curvature", figure_3),
    ("fig4_9_transmural_bounds", figure_4_bounds),
    ("fig8_bimodular_neutral_axis", figure_8),
)
