r"""buchanan2014 FE studies of the layered strip in pure bending (skvalve.fem, mixed Q2/Q1, plane strain and 3D).

**Pure bending** (:func:`fe_pure_bending`): half strip with a symmetry plane at mid-length whose end
face is rotated rigidly; the pivot height is found by secant iteration so that the axial force vanishes,
and the FE is compared with Rivlin (:mod:`skvalve.analytic.rivlin`) at its own mid-length curvature.
The 3D quarter strip (:func:`warping_study`) gives the edge-versus-centre warping of Figs. 7 and 11.

The pin-ended end loading of the paper (Figs. 4, 9) is in :mod:`.sliding`; the rows in :mod:`.rows`.
"""

from __future__ import annotations

import numpy as np
import skfem
from scipy.optimize import brentq

from ...fem import Solid
from .data import CURVATURES, FIG11_THICKNESSES, MU_OUTER, SPECIMEN_STRIP
from .models import SIGN, trilayer

__all__ = ["strip_mesh", "fe_pure_bending", "warping_study", "warping_versus_thickness"]


def strip_mesh(layers: list, half_length: float, nx: int, ny_per_layer: int, half_width: float = 0.0, nz: int = 0):
    """Q-mesh of the half strip 0 ≤ X ≤ L/2 (2D) or quarter strip with 0 ≤ Z ≤ W/2 (3D, ``nz > 0``);
    returns ``(mesh, region index per element)`` with layer boundaries on element faces."""
    y = [0.0]
    for h, _ in layers:
        y.extend(np.linspace(y[-1], y[-1] + h, ny_per_layer + 1)[1:])
    x = np.linspace(0.0, half_length, nx + 1)
    if nz:  # graded towards the free edge Z = W/2, where the warping boundary layer sits
        z = half_width * np.sin(0.5 * np.pi * np.linspace(0.0, 1.0, nz + 1))
        mesh = skfem.MeshHex.init_tensor(x, np.array(y), z)
    else:
        mesh = skfem.MeshQuad.init_tensor(x, np.array(y))
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
        fe = fe_pure_bending(layers, SIGN[direction] * curvature, half_length, nx, ny,
                             half_width=width / 2, nz=nz, tol=1e-3)
        out[direction] = dict(fe, centre=fe["stretch"](Y), edge=fe["stretch"](Y, edge=True))
    return out


def warping_versus_thickness(thicknesses=FIG11_THICKNESSES, curvatures=CURVATURES, **mesh) -> np.ndarray:
    """Fig. 11: max ``|Λ1 edge − centre|`` (AC) for each thickness (rows) and curvature (columns)."""
    out = np.empty((len(thicknesses), len(curvatures)))
    for i, h in enumerate(thicknesses):
        for j, kappa in enumerate(curvatures):
            w = warping_study(kappa, thickness=h, **mesh)["AC"]
            out[i, j] = np.max(np.abs(w["edge"] - w["centre"]))
    return out
