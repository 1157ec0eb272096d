r"""buchanan2014 — FE studies of the layered strip (skvalve.fem, mixed Q2/Q1, plane strain and 3D).

**Pure bending** (:func:`fe_pure_bending`): half strip with a symmetry plane at mid-length whose end
face is rotated rigidly; the pivot height is found by secant iteration so that the axial force vanishes,
and the FE is compared with Rivlin (:mod:`skvalve.analytic.rivlin`) at its own mid-length curvature.
The 3D quarter strip (:func:`warping_study`) gives the edge-versus-centre warping of Figs. 7 and 11.

The pin-ended end loading of the paper (Figs. 4, 9) is in :mod:`.buchanan2014_sliding`.
"""

from __future__ import annotations

import numpy as np

from ..analytic.rivlin import bend
from .buchanan2014 import (
    _SIGN,
    CURVATURES,
    FIG8_NEUTRAL_AXIS,
    MODEL_STRIP,
    MU_OUTER,
    SPECIMEN_STRIP,
    bimodular_bilayer,
    trilayer,
)
from .table import Row

__all__ = [
    "strip_mesh", "fe_pure_bending", "warping_study", "warping_versus_thickness", "fe_rows", "figure_7", "figure_11",
]


def strip_mesh(layers: list, half_length: float, nx: int, ny_per_layer: int, half_width: float = 0.0, nz: int = 0):
    """Q-mesh of the half strip 0 ≤ X ≤ L/2 (2D) or quarter strip with 0 ≤ Z ≤ W/2 (3D, ``nz > 0``);
    returns ``(mesh, region index per element)`` with layer boundaries on element faces."""
    import skfem as fem

    y = [0.0]
    for h, _ in layers:
        y.extend(np.linspace(y[-1], y[-1] + h, ny_per_layer + 1)[1:])
    x = np.linspace(0.0, half_length, nx + 1)
    if nz:  # graded towards the free edge Z = W/2, where the warping boundary layer sits
        z = half_width * np.sin(0.5 * np.pi * np.linspace(0.0, 1.0, nz + 1))
        mesh = fem.MeshHex.init_tensor(x, np.array(y), z)
    else:
        mesh = fem.MeshQuad.init_tensor(x, np.array(y))
    y_centre = mesh.p[1, mesh.t].mean(axis=0)
    return mesh, np.searchsorted(np.cumsum([h for h, _ in layers]), y_centre)


def _end_rotation(curvature: float, half_length: float, y_pivot: float):
    """Rigid motion of the end face X = L/2 that carries the fibre Y = y_pivot along a circle of curvature a."""

    def value(X, t):
        k = curvature * t
        out = np.zeros_like(X)
        if k == 0.0:
            return out
        phi = k * half_length
        d = X[:2] - np.array([[half_length], [y_pivot]])
        R = np.array([[np.cos(phi), np.sin(phi)], [-np.sin(phi), np.cos(phi)]])  # clockwise for a > 0
        out[:2] = np.array([[np.sin(phi) / k - half_length], [(np.cos(phi) - 1.0) / k]]) + R @ d - d
        return out

    return value


def fe_pure_bending(layers: list, curvature: float, half_length: float, nx: int, ny_per_layer: int,
                    half_width: float = 0.0, nz: int = 0, steps: int | None = None, tol: float = 1e-5) -> dict:
    """Mixed Q2/Q1 strip bent by rotating its end face (symmetry plane at X = 0).

    The pivot height of the end rotation is found by secant iteration so that the axial force
    (reaction along the deformed axis) vanishes. Returns per-unit-width ``moment``, ``axial_force``,
    the neutral axis where U11 = 1 on the mid-length line at the centre (Z = 0) and, in 3D, at the
    free edge (Z = W/2), plus ``stretch(Y, edge=False)`` giving Λ1 on that line.
    """
    from scipy.optimize import brentq

    from ..fem import Solid

    mesh, regions = strip_mesh(layers, half_length, nx, ny_per_layer, half_width, nz)
    H = float(sum(h for h, _ in layers))
    on_end = lambda X: np.isclose(X[0], half_length)
    width = 2 * half_width if nz else 1.0  # quarter model: per unit width = / (W/2)
    steps = steps or max(2, int(np.ceil(abs(curvature) * half_length / 0.3)))

    def solve(y_pivot: float):
        solid = Solid(mesh, [m for _, m in layers], formulation="up", regions=regions)
        solid.add_dirichlet(lambda X: np.isclose(X[0], 0.0), 0.0, components=[0])
        if nz:
            solid.add_dirichlet(lambda X: np.isclose(X[2], 0.0), 0.0, components=[2])
        solid.add_dirichlet(on_end, _end_rotation(curvature, half_length, y_pivot), components=[0, 1])
        result = solid.solve(steps=steps, rtol=1e-8, progress=False)
        phi = curvature * half_length
        axial = float(result.reaction(on_end)[:2] @ [np.cos(phi), -np.sin(phi)]) / (width / 2 if nz else 1.0)
        return result, axial

    pivots, forces, result = [0.5 * H, 0.45 * H], [], None
    for _ in range(8):
        result, axial = solve(pivots[len(forces)])
        forces.append(axial)
        scale = 4 * max(m.parameters().get("mu_tension", m.parameters().get("mu", 1.0)) for _, m in layers) * abs(
            curvature) * H * H
        if abs(axial) < tol * scale or len(forces) == 8:
            break
        if len(forces) >= 2:
            p0, p1, f0, f1 = pivots[-2], pivots[-1], forces[-2], forces[-1]
            pivots.append(p1 - f1 * (p1 - p0) / (f1 - f0))
    y_pivot = pivots[len(forces) - 1]
    phi = curvature * half_length
    pivot_now = [half_length + np.sin(phi) / curvature - half_length, y_pivot + (np.cos(phi) - 1) / curvature]
    moment = result.reaction_moment(on_end, pivot_now + ([0.0] if nz else []))
    moment = float(moment[2]) / (width / 2) if nz else float(moment)

    def stretch(Y, edge: bool = False) -> np.ndarray:
        Y = np.atleast_1d(np.asarray(Y, dtype=float))
        pts = [np.zeros_like(Y), Y] + ([np.full_like(Y, half_width if edge else 0.0)] if nz else [])
        U = result.evaluate("stretch_tensor", np.array(pts))
        return np.hypot(U[0, 0], U[0, 1])

    def u11_minus_one(y: float, edge: bool) -> float:
        pts = [[0.0], [y]] + ([[half_width if edge else 0.0]] if nz else [])
        return float(result.evaluate("stretch_tensor", np.array(pts))[0, 0, 0]) - 1.0

    # curvature at mid-length from the Rivlin kinematics λ² = 2aY + c fitted through the thickness
    Y = np.linspace(0.0, H, 41)
    local_curvature = 0.5 * np.polyfit(Y, stretch(Y) ** 2, 1)[0]
    out = {"moment": -moment, "axial_force": forces[-1], "pivot": y_pivot, "solves": len(forces),
           "centre_curvature": float(local_curvature),
           "elements": mesh.nelements, "stretch": stretch,
           "neutral_axis": brentq(u11_minus_one, 0.0, H, args=(False,), xtol=1e-12)}
    if nz:
        out["neutral_axis_edge"] = brentq(u11_minus_one, 0.0, H, args=(True,), xtol=1e-12)
    return out


def warping_study(curvature: float = 0.2, half_length: float = 1.2, nx: int = 8, ny: int = 1, nz: int = 6,
                  thickness: float = SPECIMEN_STRIP.thickness, width: float = SPECIMEN_STRIP.width) -> dict:
    """Figs. 7/11: 3D quarter strip in WC and AC; Λ1 at the centre (Z = 0) and the free edge (Z = W/2).

    Unimodular tri-layer (all 45 kPa): the bimodular law of Eq. 4 switches modulus discontinuously
    at λ = 1 and Newton stalls on it, so warping — a geometric effect — is shown without it.
    """
    Y = np.linspace(0.0, thickness, 41)
    layers = trilayer(MU_OUTER, thickness)
    out = {"Y": Y, "layers": layers, "H": thickness}
    for direction in ("WC", "AC"):
        fe = fe_pure_bending(layers, _SIGN[direction] * curvature, half_length, nx, ny,
                             half_width=width / 2, nz=nz, tol=1e-3)
        out[direction] = dict(fe, centre=fe["stretch"](Y), edge=fe["stretch"](Y, edge=True))
    return out


FIG11_THICKNESSES = (0.2, 0.3, 0.4)  # mm


def warping_versus_thickness(thicknesses=FIG11_THICKNESSES, curvatures=CURVATURES, **mesh) -> np.ndarray:
    """Fig. 11: max |Λ1 edge − centre| (AC) for each thickness (rows) and curvature (columns)."""
    out = np.empty((len(thicknesses), len(curvatures)))
    for i, h in enumerate(thicknesses):
        for j, kappa in enumerate(curvatures):
            w = warping_study(kappa, thickness=h, **mesh)["AC"]
            out[i, j] = np.max(np.abs(w["edge"] - w["centre"]))
    return out


def _warping_thickness_rows(table: np.ndarray) -> list[Row]:
    """Fig. 11 trends (paper: warping grows with thickness and with curvature) as pass/fail rows."""
    grows_with_h = float(np.all(np.diff(table, axis=0) > 0))
    grows_with_k = float(np.all(np.diff(table, axis=1) > 0))
    pairs = zip(FIG11_THICKNESSES, table, strict=True)
    note = "; ".join(f"H={h}: " + ", ".join(f"{v:.4f}" for v in row) for h, row in pairs)
    return [Row("Fig. 11 warping grows with thickness (1 = yes)", 1.0, grows_with_h, 0.0, note=note),
            Row("Fig. 11 warping grows with curvature (1 = yes)", 1.0, grows_with_k, 0.0)]


def fe_rows(full: bool = False) -> tuple[list[Row], dict]:
    """FE-vs-Rivlin checks (plane strain), the 3D centre/edge warping and the pin-ended sliding study
    (:func:`.buchanan2014_sliding.sliding_rows`); also returns the 3D and the sliding studies."""
    rows: list[Row] = []
    H = MODEL_STRIP.thickness
    layers = trilayer(10.0, H)
    meshes = [(12, 1), (24, 2), (48, 4)] + ([(96, 8)] if full else [])
    errors = []
    for nx, ny in meshes:
        fe = fe_pure_bending(layers, 0.2, 1.2, nx, ny)
        ref = bend(layers, fe["centre_curvature"])
        errors.append((fe["elements"], fe["moment"] / ref.moment - 1, fe["neutral_axis"] / ref.neutral_axis - 1))
    n_el, err_m, err_na = errors[-1]
    history = "; ".join(f"{n} el: M {m:+.2%}, NA {a:+.2%}" for n, m, a in errors)
    note = (f"tri-layer μS=10 kPa, Δκ=0.2, Q2/Q1 plane strain, Rivlin at the FE centre curvature; {history}. "
            "First order: continuous Q1 pressure cannot jump at layer interfaces")
    rows.append(Row(f"[FE] M / Rivlin − 1, {n_el} elements", 0.0, err_m, 0.01, note=note))
    rows.append(Row(f"[FE] NA / Rivlin − 1, {n_el} elements", 0.0, err_na, 0.01))
    bilayer = bimodular_bilayer(smoothed=True)
    for direction in ("WC", "AC"):
        fe = fe_pure_bending(bilayer, _SIGN[direction] * 0.2, 1.0, 24 if full else 12, 4 if full else 2, tol=1e-3)
        ref = bend(bilayer, fe["centre_curvature"])
        na = fe["neutral_axis"] / SPECIMEN_STRIP.thickness
        rows.append(Row(f"[FE] bimodular NA {direction} / Rivlin − 1", 0.0, fe["neutral_axis"] / ref.neutral_axis - 1,
                        0.01, note=(f"plane strain, {fe['elements']} elements, smoothed Eq. 4; FE NA/H = {na:.3f} "
                                    f"(paper Fig. 8: {FIG8_NEUTRAL_AXIS[direction]}); M/Rivlin − 1 = "
                                    f"{fe['moment'] / ref.moment - 1:+.2%}")))
    warp = warping_study(nx=12 if full else 8, ny=2 if full else 1, nz=10 if full else 6)
    for direction in ("WC", "AC"):
        w = warp[direction]
        ref = bend(warp["layers"], _SIGN[direction] * 0.2)
        rows.append(Row(f"Fig. 7 max |Λ1 edge − centre| {direction}, Δκ=0.2", 0.02,
                        float(np.max(np.abs(w["edge"] - w["centre"]))), 0.01,
                        note=(f"paper: '~0.02' (Sect. 3.4), tol 0.01 for the approximate value; 3D quarter strip "
                              f"{w['elements']} hexes, unimodular tri-layer (45 kPa); NA/H centre "
                              f"{w['neutral_axis'] / warp['H']:.3f}, edge {w['neutral_axis_edge'] / warp['H']:.3f}, "
                              f"plane strain {ref.normalised_neutral_axis:.3f}; 3D/plane-strain moment "
                              f"{w['moment'] / ref.moment:.3f}")))
    thickness_table = warping_versus_thickness() if full else None
    if thickness_table is not None:
        rows.extend(_warping_thickness_rows(thickness_table))
    from .buchanan2014_sliding import sliding_rows  # it imports strip_mesh from here

    sliding, study = sliding_rows(full)
    return rows + sliding, {"warping": warp, "sliding": study, "warping_thickness": thickness_table}


def figure_11(table: np.ndarray, ax=None):
    """Fig. 11: edge–centre warping max |ΔΛ1| versus strip thickness, one line per curvature."""
    import matplotlib.pyplot as plt

    ax = ax if ax is not None else plt.subplots(figsize=(5, 4))[1]
    for j, curvature in enumerate(CURVATURES):
        ax.plot(FIG11_THICKNESSES, table[:, j], "o-", label=f"Δκ = {curvature} mm⁻¹")
    ax.set(xlabel="thickness H (mm)", ylabel="max |Λ1 edge − Λ1 centre|", title="3D strip warping (Fig. 11)")
    ax.legend()
    return ax


def figure_7(warp: dict, axes=None):
    """Fig. 7 b, c: Λ1 through the thickness at the centre and at the free edge of the 3D strip."""
    import matplotlib.pyplot as plt

    axes = axes if axes is not None else plt.subplots(1, 2, figsize=(10, 4), sharey=True)[1]
    Y = warp["Y"] / warp["H"]
    for ax, direction in zip(axes, ("WC", "AC"), strict=True):
        ax.plot(Y, warp[direction]["centre"], "C0", label="centre (Z = 0)")
        ax.plot(Y, warp[direction]["edge"], "C3--", label="edge (Z = W/2)")
        ax.axhline(1.0, color="0.6", lw=0.8)
        ax.set(xlabel="normalised thickness (V → F)", title=f"3D strip, {direction}, Δκ = 0.2 mm⁻¹")
    axes[0].set_ylabel("Λ1")
    axes[0].legend()
    return axes
