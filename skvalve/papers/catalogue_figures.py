"""Figures of the material catalogue: one PNG per group, uniaxial and equibiaxial Cauchy stress (or the
force–stretch curve of a 1-D fibre), in the readable style of :mod:`skvalve.papers.plotting`."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ..analytic.homogeneous import equibiaxial, uniaxial
from ..materials import Hyperelastic
from .catalogue import CatalogueEntry
from .plotting import readable_style, save_figure

__all__ = ["group_figure", "write_catalogue_figures"]


def group_figure(entries: Sequence[CatalogueEntry]):
    """Figure of one group: Cauchy stress σ11 against the stretch λ in uniaxial and equibiaxial tension
    (dashed: a compressible law with free lateral stretch), or a fibre's axial force against its stretch."""
    first = entries[0]
    if not isinstance(first.law, Hyperelastic):  # 1-D fibre: force–stretch
        fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
        for entry in entries:
            lam = np.linspace(*entry.stretch_range, 200)
            ax.plot(lam, entry.law.force(lam) * 1e9, label=entry.name)
        ax.axvline(first.law.lambda_c, color="0.6", ls=":", label="λc (fibre straightens)")
        ax.set(xlabel="fibre stretch λ", ylabel="axial force (nN)", title=first.paper)
        ax.legend(loc="upper left")
        return fig
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.8), layout="constrained")
    for entry in entries:
        lam = np.linspace(*entry.stretch_range, 61)
        for ax, mode in zip(axes, (uniaxial, equibiaxial), strict=True):
            line = ax.plot(lam, mode(entry.law, lam, incompressible=True).cauchy[0], label=entry.name)[0]
            if not entry.law.incompressible:
                ax.plot(lam, mode(entry.law, lam, incompressible=False).cauchy[0], ls="--", color=line.get_color(),
                        lw=1)
    for ax, title in zip(axes, ("uniaxial", "equibiaxial (thin sheet)"), strict=True):
        ax.set(xlabel="stretch λ (loading direction)", ylabel=f"Cauchy stress σ11 ({first.units})",
               title=f"{first.paper}: {title}")
        ax.axhline(0.0, color="0.8", lw=0.5)
    if any(not e.law.incompressible for e in entries):
        axes[0].plot([], [], "k--", lw=1, label="dashed: the compressible law with free lateral stretch; solid: "
                                                "its incompressible limit")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=2)
    return fig


def write_catalogue_figures(entries: Sequence[CatalogueEntry], out: Path) -> list[Path]:
    """One PNG per group, ``out/<group>.png``, written atomically; returns the paths."""
    groups: dict[str, list[CatalogueEntry]] = {}
    for entry in entries:
        groups.setdefault(entry.group, []).append(entry)
    paths = []
    with readable_style():
        for group, members in groups.items():
            fig = group_figure(members)
            try:
                paths.append(save_figure(fig, Path(out) / f"{group}.png"))
            finally:
                plt.close(fig)
    return paths
