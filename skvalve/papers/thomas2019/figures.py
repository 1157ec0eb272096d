"""Figures 5–7 of thomas2019 from the FE² protocol runs (matplotlib, imported by the caller on demand).

* :func:`figure_5b` — edge tension against edge stretch, both axes, the five protocols (Fig. 5b).
* :func:`figure_5_contours` — E11, E22, S11, S22 on the deformed top surface (Fig. 5c–f), tines as dots.
* :func:`figure_6` — orientation (before/after) and fiber-strain histograms of N1, N2, N3 (Fig. 6).
* :func:`figure_7` — max principal strain E1 of the elements against the fiber strains (Fig. 7).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection

from ...multiscale.fields import gauss_fields
from ...networks.orientation import project
from .analysis import NetworkChange, element_max_principal_strain
from .protocols import ProtocolRun

__all__ = ["figure_5b", "figure_5_contours", "figure_6", "figure_7"]

_MARKERS = {(0.5, 1.0): "x", (0.75, 1.0): "+", (1.0, 1.0): "*", (1.0, 0.75): "^", (1.0, 0.5): "D"}


def figure_5b(runs: list[ProtocolRun]):
    """Tension (N/m) against edge stretch, circumferential (solid) and radial (dashed), per protocol."""
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    for k, run in enumerate(runs):
        colour = f"C{k}"
        marker = _MARKERS.get(tuple(run.ratio), "o")
        label = f"{run.ratio[0]:g}:{run.ratio[1]:g}"
        ax.plot(run.path_stretch[:, 0], run.path_tension[:, 0], "-", marker=marker, color=colour,
                label=f"{label} circ.")
        ax.plot(run.path_stretch[:, 1], run.path_tension[:, 1], "--", marker=marker, color=colour, mfc="none",
                label=f"{label} rad.")
    ax.set_xlabel("edge stretch 1 + δ/L")
    ax.set_ylabel("membrane tension (N/m)")
    ax.set_title("Fig. 5b: FE² sample, five biaxial protocols")
    ax.legend(ncol=2, loc="upper left")
    return fig


def _top_faces(run: ProtocolRun) -> tuple[np.ndarray, np.ndarray]:
    """Deformed (x, y) polygons of the top faces of the top-layer elements and their element ids."""
    mesh = run.solid.mesh
    z_top = mesh.p[2].max()
    disp = run.u[: run.solid.space.n_u].reshape(-1, 3)[: mesh.nvertices].T
    x = mesh.p + disp
    polygons, elements = [], []
    for e in range(mesh.nelements):
        nodes = mesh.t[:, e]
        top = nodes[np.isclose(mesh.p[2, nodes], z_top)]
        if top.size != 4:
            continue
        centre = mesh.p[:2, top].mean(axis=1)
        order = np.argsort(np.arctan2(mesh.p[1, top] - centre[1], mesh.p[0, top] - centre[0]))
        polygons.append(x[:2, top[order]].T * 1e3)
        elements.append(e)
    return np.array(polygons), np.array(elements)


def figure_5_contours(run: ProtocolRun):
    """E11, E22 and S11, S22 (kPa) element averages on the deformed top surface (Fig. 5c–f)."""
    fields = gauss_fields(run.solid, run.material, run.u)
    E = fields.element_average("green_strain")
    S = fields.element_average("cauchy") / 1e3
    polygons, elements = _top_faces(run)
    mesh = run.solid.mesh
    tine_sets = [nodes for name, nodes in run.grips.nodes.items() if run.grips.positions[name].size]
    held = np.unique(np.concatenate(tine_sets)) if tine_sets else np.zeros(0, dtype=int)
    held = held[np.isclose(mesh.p[2, held], mesh.p[2].max())]
    tines = (mesh.p[:2, held] + run.u[: run.solid.space.n_u].reshape(-1, 3)[held, :2].T) * 1e3
    fig, axes = plt.subplots(2, 2, figsize=(8.0, 7.0))
    for ax, (title, values) in zip(axes.ravel(), (("(c) E11", E[:, 0, 0]), ("(d) E22", E[:, 1, 1]),
                                                   ("(e) S11 (kPa)", S[:, 0, 0]), ("(f) S22 (kPa)", S[:, 1, 1])),
                                   strict=True):
        collection = PolyCollection(polygons, array=values[elements], cmap="jet", edgecolors="none")
        ax.add_collection(collection)
        if tines.size:
            ax.plot(tines[0], tines[1], "ko", ms=3)
        ax.autoscale()
        ax.set_aspect("equal")
        ax.set_title(title)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        fig.colorbar(collection, ax=ax)
    fig.suptitle(f"Fig. 5c–f: protocol {run.ratio[0]:g}:{run.ratio[1]:g}, {run.grips.attachment.label}, "
                 "deformed top surface")
    return fig


def figure_6(run: ProtocolRun, changes: dict[str, NetworkChange]):
    """Per network: projected orientation histograms before/after and fiber engineering strains (Fig. 6)."""
    fig, axes = plt.subplots(2, len(changes), figsize=(3.2 * len(changes), 6.0))
    bins = np.linspace(-90, 90, 19)
    for col, (name, change) in enumerate(changes.items()):
        network = run.material.networks[change.element]
        for positions, label, style in ((None, f"before α={change.alpha_before:.0f}%", "step"),
                                        (change.deformed_nodes, f"after α={change.alpha_after:.0f}%", "bar")):
            angles, lengths = project(network, positions=positions)
            folded = (np.degrees(angles) + 90.0) % 180.0 - 90.0
            axes[0, col].hist(folded, bins=bins, weights=lengths, density=True, histtype=style, alpha=0.6,
                              label=label)
        axes[0, col].set_title(f"{name} (element {change.element})")
        axes[0, col].set_xlabel("fiber angle (°)")
        axes[0, col].legend()
        axes[1, col].hist(change.fiber_strain, bins=30, density=True, color="C2")
        axes[1, col].set_xlabel("fiber strain λ − 1")
    axes[0, 0].set_ylabel("length-weighted density")
    axes[1, 0].set_ylabel("density")
    fig.suptitle(f"Fig. 6: networks N1–N3, protocol {run.ratio[0]:g}:{run.ratio[1]:g}")
    return fig


def figure_7(run: ProtocolRun):
    """Histogram of the elements' max principal Green strain E1 and of the fiber strains (one RVE/element)."""
    E1, fiber = element_max_principal_strain(run)
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    bins = np.linspace(min(E1.min(), fiber.min()), max(E1.max(), fiber.max()), 40)
    ax.hist(E1, bins=bins, density=True, alpha=0.4, label="E1 of the elements", ls=":", edgecolor="k")
    ax.hist(fiber, bins=bins, density=True, histtype="step", lw=2, label="fiber strain ε = λ − 1")
    ax.set_xlabel("strain")
    ax.set_ylabel("density")
    ax.set_title(f"Fig. 7: protocol {run.ratio[0]:g}:{run.ratio[1]:g}")
    ax.legend()
    return fig
