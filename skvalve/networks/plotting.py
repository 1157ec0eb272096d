"""Figures of the fiber networks (Thomas 2019 Fig. 3 and Fig. 6): 3D fibers coloured by strain,
projected orientation histograms and fiber-strain histograms.

Readable by default (issue 12 item 7): every function raises its figure to at least
``MIN_DPI`` dots per inch and ``MIN_WIDTH_IN`` inches wide, a coloured 3D network gets a colour bar
with its quantity, and every axis symbol is defined on the axis or in the legend (coordinates in
units of the RVE edge γ, θ the in-plane fiber angle from x, α the anisotropy index of Eq. 2, μ the
mean fiber direction of Eq. 3, ε = λ − 1 the fiber strain).  :func:`network_figure` makes such a
figure from the start.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from skvalve.networks.network import Network
from skvalve.networks.orientation import network_alpha_mu, project

MIN_DPI = 150
MIN_WIDTH_IN = 6.0
STRAIN_LABEL = "fiber strain ε = λ − 1 (λ: fiber stretch)"


def network_figure(width_in: float = 7.0, height_in: float = 4.0, dpi: int = MIN_DPI):
    """An empty figure of readable size (≥ ``MIN_WIDTH_IN`` in wide, ≥ ``MIN_DPI`` dpi)."""
    return plt.figure(figsize=(max(width_in, MIN_WIDTH_IN), height_in), dpi=max(dpi, MIN_DPI), layout="constrained")


def _make_readable(fig) -> None:
    """Raise the figure's resolution and width to the readable minimum (aspect ratio kept)."""
    if fig.get_dpi() < MIN_DPI:
        fig.set_dpi(MIN_DPI)
    width, height = fig.get_size_inches()
    if width < MIN_WIDTH_IN:
        fig.set_size_inches(MIN_WIDTH_IN, height * MIN_WIDTH_IN / width)


def plot_network(
    ax,
    network: Network,
    positions: np.ndarray | None = None,
    strain: np.ndarray | None = None,
    vmax: float | None = None,
    cmap: str = "viridis",
    show_boundary: bool = True,
    colorbar: bool = True,
    strain_label: str = STRAIN_LABEL,
):
    """3D line plot of the fibers (``ax`` from ``projection="3d"``), coloured by ``strain``.

    A coloured network gets a colour bar labelled ``strain_label``; boundary cross-links are red
    dots (``show_boundary``).  Coordinates are in units of the RVE edge γ (the unit cube).
    """
    _make_readable(ax.figure)
    x = network.nodes if positions is None else positions
    segments = x[network.fibers]
    if strain is None:
        lines = Line3DCollection(segments, colors="0.3", linewidths=0.8)
    else:
        lines = Line3DCollection(segments, cmap=cmap, linewidths=1.0)
        lines.set_array(np.asarray(strain))
        lines.set_clim(0.0, vmax if vmax is not None else max(float(np.max(strain)), 1e-12))
    ax.add_collection3d(lines)
    if strain is not None and colorbar:
        ax.figure.colorbar(lines, ax=ax, shrink=0.6, pad=0.1, label=strain_label)
    if show_boundary:
        b = x[network.boundary]
        ax.scatter(b[:, 0], b[:, 1], b[:, 2], s=2, c="tab:red", depthshade=False, label="boundary cross-links")
    lo, hi = x.min(axis=0), x.max(axis=0)
    ax.set(
        xlim=(lo[0], hi[0]),
        ylim=(lo[1], hi[1]),
        zlim=(lo[2], hi[2]),
        xlabel="x / γ (γ: RVE edge)",
        ylabel="y / γ",
        zlabel="z / γ",
    )
    ax.set_box_aspect(hi - lo)
    return lines


def plot_orientation_histogram(
    ax, network: Network, positions: np.ndarray | None = None, bins: int = 18, label: str | None = None, **kwargs
):
    """Length-weighted histogram of projected fiber angles in [−90°, 90°), with α (Eq. 2) and μ (Eq. 3)."""
    _make_readable(ax.figure)
    angles, weights = project(network, positions=positions)
    degrees = (np.degrees(angles) + 90.0) % 180.0 - 90.0
    alpha, mu = network_alpha_mu(network, positions=positions)
    text = f"anisotropy α = {alpha:.0f} %, mean direction μ = {mu:.0f}°"
    ax.hist(
        degrees,
        bins=bins,
        range=(-90, 90),
        weights=weights / weights.sum(),
        label=f"{label}: {text}" if label else text,
        **kwargs,
    )
    ax.set(xlabel="in-plane fiber angle θ from x (°)", ylabel="fraction of fiber length", xlim=(-90, 90))
    return alpha, mu


def plot_strain_histogram(ax, strain: np.ndarray, bins: int = 20, label: str | None = None, **kwargs):
    """Histogram of fiber strains ε = λ − 1 (fraction of fibers)."""
    _make_readable(ax.figure)
    strain = np.asarray(strain)
    ax.hist(strain, bins=bins, weights=np.full(strain.size, 1.0 / strain.size), label=label, **kwargs)
    ax.set(xlabel=STRAIN_LABEL, ylabel="fraction of fibers")
