"""Figures of the fiber networks (Thomas 2019 Fig. 3 and Fig. 6): 3D fibers coloured by strain,
projected orientation histograms and fiber-strain histograms."""

from __future__ import annotations

import numpy as np
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from skvalve.networks.network import Network
from skvalve.networks.orientation import network_alpha_mu, project


def plot_network(
    ax,
    network: Network,
    positions: np.ndarray | None = None,
    strain: np.ndarray | None = None,
    vmax: float | None = None,
    cmap: str = "viridis",
    show_boundary: bool = True,
):
    """3D line plot of the fibers (``ax`` from ``projection="3d"``), coloured by ``strain``."""
    x = network.nodes if positions is None else positions
    segments = x[network.fibers]
    if strain is None:
        lines = Line3DCollection(segments, colors="0.3", linewidths=0.8)
    else:
        lines = Line3DCollection(segments, cmap=cmap, linewidths=1.0)
        lines.set_array(np.asarray(strain))
        lines.set_clim(0.0, vmax if vmax is not None else max(float(np.max(strain)), 1e-12))
    ax.add_collection3d(lines)
    if show_boundary:
        b = x[network.boundary]
        ax.scatter(b[:, 0], b[:, 1], b[:, 2], s=2, c="tab:red", depthshade=False)
    lo, hi = x.min(axis=0), x.max(axis=0)
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]), xlabel="x", ylabel="y", zlabel="z")
    ax.set_box_aspect(hi - lo)
    return lines


def plot_orientation_histogram(
    ax, network: Network, positions: np.ndarray | None = None, bins: int = 18, label: str | None = None, **kwargs
):
    """Length-weighted histogram of projected fiber angles in [−90°, 90°), with α and μ."""
    angles, weights = project(network, positions=positions)
    degrees = (np.degrees(angles) + 90.0) % 180.0 - 90.0
    alpha, mu = network_alpha_mu(network, positions=positions)
    text = f"α = {alpha:.0f} %, μ = {mu:.0f}°"
    ax.hist(
        degrees,
        bins=bins,
        range=(-90, 90),
        weights=weights / weights.sum(),
        label=f"{label}: {text}" if label else text,
        **kwargs,
    )
    ax.set(xlabel="fiber angle θ (°)", ylabel="length fraction", xlim=(-90, 90))
    return alpha, mu


def plot_strain_histogram(ax, strain: np.ndarray, bins: int = 20, label: str | None = None, **kwargs):
    """Histogram of fiber strains (fraction of fibers)."""
    strain = np.asarray(strain)
    ax.hist(strain, bins=bins, weights=np.full(strain.size, 1.0 / strain.size), label=label, **kwargs)
    ax.set(xlabel="fiber strain ε = λ − 1", ylabel="fraction of fibers")
