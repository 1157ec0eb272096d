r"""buchanan2014 — layered aortic-valve leaflet in flexure (Buchanan & Sacks, BMMB 13:813, 2014).

What is reproduced and how (``skvalve reproduce buchanan2014``):

* **Fig. 3** — normalised M–Δκ of the one-term Ogden model (Eq. 1) from Rivlin's solution
  (:mod:`skvalve.analytic.rivlin`) for several α. The experimental curve (Merryman et al.
  2006) is not published as numbers, so only the model family is shown.
* **Fig. 8 / Table 2** — neutral axis of the bimodular bilayer (Eq. 4, Table 3 moduli,
  fibrosa 60 % / ventricularis 40 %) in WC and AC bending at Δκ = 0.1, 0.2, 0.3 mm⁻¹, from
  Rivlin's exact pure-bending solution, beside the paper's 0.35 / 0.79 and Table 2.
* **Sect. 3.3** — extreme transmural stretches Λ1 in AC bending against the measured ones.
* **Figs. 4 / 9 (bounds)** — Λ1 through the thickness for μS from 1 Pa to 45 kPa in pure bending
  (bonded: Rivlin, layered) and the fully unbonded limit (each layer bent alone). In *pure* bending the
  bonded block is exactly Rivlin's for any μS > 0 (no shear).
* **Figs. 4 / 9 (end loading)** — the paper's pin-ended loading (M = P·y) in plane-strain FE, Λ1 at the
  centre per μS and Δκ, and the μS threshold of measurable sliding (:mod:`.buchanan2014_sliding`).
* **FE (skvalve.fem, mixed Q2/Q1)** — plane-strain strip bent by rotating its end face, checked
  against Rivlin at the FE's own mid-length curvature; 3D quarter strip for the edge-versus-centre
  warping of Fig. 7 (and Fig. 11 with ``full``) (:mod:`.buchanan2014_fe`).
* **Table 3** — the relative moduli and ratios recomputed from the absolute moduli.

Not reproducible without the authors' raw data: the experimental M–Δκ curves (Figs. 3, 5),
the measured transmural profiles (Figs. 6, 10), the silicone validation (Table 1) and the
fit of μ = 45 kPa (Sect. 3.1). Conventions: lengths in mm, moduli in kPa, moments per unit
width in kPa·mm²; normalised thickness 0 = ventricularis face, 1 = fibrosa face; AC bending
stretches the fibrosa face (``a > 0`` in :func:`skvalve.analytic.rivlin.bend`), WC the
ventricularis face (``a < 0``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analytic.rivlin import bend, moment_curvature
from ..materials import BimodularNeoHookean, IncompressibleNeoHookean, Ogden
from .table import Row

__all__ = [
    "Strip", "MODEL_STRIP", "SPECIMEN_STRIP", "CURVATURES", "MU_OUTER", "SPONGIOSA_MODULI", "TABLE2", "TABLE3",
    "FIG8_NEUTRAL_AXIS", "trilayer", "bimodular_bilayer", "neutral_axis", "unbonded_stretch",
    "ogden_normalised_moment", "analytic_rows", "reproduce",
]


@dataclass(frozen=True)
class Strip:
    """Rectangular strip: length (circumferential X1), width (radial X3), thickness (X2), mm."""

    length: float
    width: float
    thickness: float


MODEL_STRIP = Strip(14.0, 3.0, 0.4)  # Sect. 2.2
SPECIMEN_STRIP = Strip(13.7, 2.8, 0.318)  # Sect. 2.4 (mean of 18 specimens)
TRILAYER_FRACTIONS = (("ventricularis", 0.25), ("spongiosa", 0.30), ("fibrosa", 0.45))  # Sect. 2.2, bottom up
BILAYER_FRACTIONS = (("ventricularis", 0.40), ("fibrosa", 0.60))  # Fig. 8
CURVATURES = (0.1, 0.2, 0.3)  # Δκ, mm⁻¹ (Sect. 2.3, Appendix 2)
MU_OUTER = 45.0  # kPa, fibrosa and ventricularis of the initial model (Sect. 3.1)
SPONGIOSA_MODULI = (0.001, 0.1, 1.0, 10.0, 45.0)  # kPa: 1 Pa … 45 kPa (Sect. 2.3)
FIG3_ALPHAS = (2.0, 5.0, 10.0, 20.0, 30.0)
FIG3_MAX_CURVATURE = 0.28  # mm⁻¹
TABLE3 = {"fibrosa": (139.5, 29.55), "ventricularis": (65.00, 16.74)}  # (μ+, μ−) kPa
TABLE3_RELATIVE = {"fibrosa": (100.0, 21.2, 4.72), "ventricularis": (46.6, 12.0, 3.88)}  # %, %, μ+/μ−
# Table 2: Δκ → (AC experiment, AC SD, AC simulation, WC experiment, WC SD, WC simulation)
TABLE2 = {
    0.1: (0.5987, 0.0929, 0.6209, 0.5453, 0.1012, 0.4935),
    0.2: (0.5903, 0.1022, 0.5994, 0.5571, 0.1021, 0.5495),
    0.3: (0.6026, 0.0730, 0.5835, 0.5629, 0.0315, 0.5670),
}
FIG8_NEUTRAL_AXIS = {"WC": 0.35, "AC": 0.79}  # centre of the strip (Sect. 3.4)
AC_STRETCH_EXTREMES = {0.1: (1.016, 0.984), 0.3: (1.026, 0.969)}  # Sect. 3.3: (max Λ1, min Λ1)
LAMBDA_EXPERIMENT_ERROR = 0.0141  # Sect. 3.4, experimental error of Λ1
BIMODULAR_SMOOTHING = 1e-2  # width of the modulus switch in I4 for the FE (not in the paper)

_E1 = (1.0, 0.0, 0.0)
_SIGN = {"AC": 1.0, "WC": -1.0}


def trilayer(mu_spongiosa: float, thickness: float = MODEL_STRIP.thickness, mu_outer: float = MU_OUTER) -> list:
    """Neo-Hookean (Eq. 3) tri-layer, ventricularis/spongiosa/fibrosa 25/30/45 % bottom up."""
    mu = {"ventricularis": mu_outer, "spongiosa": mu_spongiosa, "fibrosa": mu_outer}
    return [(f * thickness, IncompressibleNeoHookean(mu[name])) for name, f in TRILAYER_FRACTIONS]


def bimodular_bilayer(thickness: float = SPECIMEN_STRIP.thickness, smoothed: bool = False) -> list:
    """Bimodular neo-Hookean (Eq. 4) bilayer with the Table 3 moduli, ventricularis 40 % at the bottom
    (``smoothed``: tanh switch over δ = 0.01 in I4 = a·Ca, for Newton in the FE; the Rivlin neutral axis
    moves by < 1e-4)."""
    smoothing = BIMODULAR_SMOOTHING if smoothed else 0.0
    return [(f * thickness, BimodularNeoHookean(*TABLE3[name], _E1, smoothing=smoothing))
            for name, f in BILAYER_FRACTIONS]


def neutral_axis(layers: list, direction: str, curvature: float) -> float:
    """Normalised neutral axis (0 = ventricularis face) of Rivlin bending in ``"AC"`` or ``"WC"``."""
    if direction not in _SIGN:
        raise ValueError(f"direction must be 'AC' or 'WC'; got {direction!r}")
    return bend(layers, _SIGN[direction] * curvature).normalised_neutral_axis


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
    from scipy.optimize import brentq

    layer = {"AC": "fibrosa", "WC": "ventricularis"}[direction]
    H = SPECIMEN_STRIP.thickness

    def mismatch(mu_plus: float) -> float:
        moduli = dict(TABLE3, **{layer: (mu_plus, TABLE3[layer][1])})
        layers = [(f * H, BimodularNeoHookean(*moduli[name], _E1)) for name, f in BILAYER_FRACTIONS]
        return neutral_axis(layers, direction, curvature) - target

    return brentq(mismatch, 1.0, 5000.0, xtol=1e-6)


def ogden_normalised_moment(alpha: float, curvatures: np.ndarray, thickness: float = MODEL_STRIP.thickness,
                            mu: float = MU_OUTER) -> np.ndarray:
    """Fig. 3: M(Δκ)/M(Δκ_max) of a one-term Ogden block (Eq. 1; normalisation removes μ)."""
    M = moment_curvature([(thickness, Ogden(mu=(mu,), alpha=(alpha,)))], curvatures)
    return M / M[-1]


def analytic_rows() -> list[Row]:
    """Rows from the exact solution: Fig. 8, Table 2, Sect. 3.3, Table 3, closed-form checks."""
    rows: list[Row] = []
    H = SPECIMEN_STRIP.thickness
    bilayer = bimodular_bilayer(H)
    centre_vs_edge = ("Rivlin = centre of a long strip in pure bending, no initial curvature; Table 2 "
                      "'simulation' is the paper's 3D FE read at the specimen edge (warping, Sect. 3.4)")
    for direction, paper in FIG8_NEUTRAL_AXIS.items():
        value = neutral_axis(bilayer, direction, 0.2)
        linear = neutral_axis(bilayer, direction, 1e-4)
        layer = {"AC": "fibrosa", "WC": "ventricularis"}[direction]
        needed = tension_modulus_for_neutral_axis(direction, paper)
        rows.append(Row(
            f"Fig. 8 NA {direction} (centre), Δκ=0.2", paper, value, 0.02,
            note=(f"tol 0.02: read from a schematic to 2 digits. Table 3 moduli give {value:.3f} (linear "
                  f"bimodular beam {linear:.3f}); {paper} needs {layer} μ+ = {needed:.0f} kPa (Table 3: "
                  f"{TABLE3[layer][0]}). The paper's value is from its 3D FE (fitted initial curvature, end "
                  "loading), not reproducible from Table 3 in pure bending."),
        ))
    for kappa, (ac_exp, ac_sd, ac_sim, wc_exp, wc_sd, wc_sim) in TABLE2.items():
        for direction, sim, exp, sd in (("AC", ac_sim, ac_exp, ac_sd), ("WC", wc_sim, wc_exp, wc_sd)):
            value = neutral_axis(bilayer, direction, kappa)
            rows.append(Row(f"Table 2 NA {direction} simulation, Δκ={kappa}", sim, value, 0.02,
                            note=f"tol 0.02 as Fig. 8. {centre_vs_edge}."))
            rows.append(Row(f"Table 2 NA {direction} experiment, Δκ={kappa}", exp, value, sd,
                            note="tol = the paper's SD over 18 specimens; measured at the edge."))
    for kappa, (lam_max, lam_min) in AC_STRETCH_EXTREMES.items():
        sol = bend(bilayer, kappa)
        note = (f"tol = experimental Λ1 error ±{LAMBDA_EXPERIMENT_ERROR} (Sect. 3.4); measured at the edge "
                "of specimens 318±46 µm thick")
        rows.append(Row(f"Sect. 3.3 max Λ1 AC, Δκ={kappa}", lam_max, sol.lambda_top, LAMBDA_EXPERIMENT_ERROR,
                        note=note))
        rows.append(Row(f"Sect. 3.3 min Λ1 AC, Δκ={kappa}", lam_min, sol.lambda_bottom, LAMBDA_EXPERIMENT_ERROR,
                        note=note + ("; the soft compressive ventricularis (μ−=16.7 kPa) shortens more in pure "
                                     "bending than measured" if abs(sol.lambda_bottom - lam_min) > 0.0141 else "")))
    for name, (mu_t, mu_c) in TABLE3.items():
        rel_t, rel_c, ratio = TABLE3_RELATIVE[name]
        mu_ref = TABLE3["fibrosa"][0]
        rows.append(Row(f"Table 3 {name} μ+ relative (%)", rel_t, 100 * mu_t / mu_ref, 0.05,
                        note="arithmetic of Table 3; tol = half a unit of the last printed digit"))
        rows.append(Row(f"Table 3 {name} μ− relative (%)", rel_c, 100 * mu_c / mu_ref, 0.05))
        rows.append(Row(f"Table 3 {name} μ+/μ−", ratio, mu_t / mu_c, 0.005))
    rows.extend(_closed_form_checks())
    return rows


def _closed_form_checks() -> list[Row]:
    """Exact values (not from the paper) that the Rivlin solver must meet; 'paper' holds the exact value."""
    H, a, mu = MODEL_STRIP.thickness, 0.2, MU_OUTER
    c = -a * H + np.sqrt((a * H) ** 2 + 1.0)
    exact_M = mu / (4 * a**2) * (0.5 * (c**-2 - c**2) + 2 * np.log(c))
    nh = bend([(H, IncompressibleNeoHookean(mu))], a)
    og = bend([(H, Ogden(mu=(mu,), alpha=(2.0,)))], a)
    layers = trilayer(10.0)
    h = np.array([t for t, _ in layers])
    E = 4 * np.array([m.mu for _, m in layers])  # plane-strain modulus E/(1−ν²) = 4μ
    y = np.concatenate([[0.0], np.cumsum(h)])
    y_na = np.sum(E * (y[1:] ** 2 - y[:-1] ** 2) / 2) / np.sum(E * h)
    EI = np.sum(E * ((y[1:] - y_na) ** 3 - (y[:-1] - y_na) ** 3) / 3)
    small = bend(layers, 1e-4)
    exact = "exact value in the paper column: "
    return [
        Row("[exact] neo-Hookean M, H=0.4, Δκ=0.2", exact_M, nh.moment, 1e-9, relative=True,
            note=exact + "M = μ/4a²[(c⁻²−c²)/2 + 2 ln c]"),
        Row("[exact] neo-Hookean NA/H, Δκ=0.2", (1 - c) / (2 * a * H), nh.normalised_neutral_axis, 1e-10),
        Row("[exact] Ogden α=2 M / neo-Hookean M", 1.0, og.moment / nh.moment, 1e-10),
        Row("[exact] tri-layer μS=10 NA, Δκ→0 (EB)", y_na, small.neutral_axis, 1e-4, relative=True,
            note=exact + "transformed section; Rivlin at Δκ=1e-4, error O(Δκ·H)"),
        Row("[exact] tri-layer μS=10 M/Δκ, Δκ→0 (EB)", EI, small.moment / 1e-4, 1e-4, relative=True,
            note=exact + "EI with E' = 4μ (plane strain; 3μ would be plane stress)"),
        Row("[exact] axial force / fibre stress, Δκ=0.2", 0.0, nh.axial_force / (4 * mu * a * H), 1e-10),
    ]


def figure_3(ax=None):
    """Fig. 3 model family: normalised M–Δκ of one-term Ogden blocks for several α."""
    import matplotlib.pyplot as plt

    ax = ax or plt.figure(figsize=(5, 4)).gca()
    kappa = np.linspace(0.0, FIG3_MAX_CURVATURE, 29)
    for alpha in FIG3_ALPHAS:
        ax.plot(kappa, ogden_normalised_moment(alpha, kappa), label=f"α = {alpha:g}")
    ax.set(xlabel="Δκ (mm⁻¹)", ylabel="M / M(0.28)", title="Fig. 3: one-term Ogden, Rivlin (H = 0.4 mm)")
    ax.legend(title="experiment not published", fontsize=8)
    return ax


def figure_4_bounds(axes=None, direction: str = "WC"):
    """Figs. 4/9 bounds: Λ1 through the thickness, bonded (Rivlin) vs unbonded layers, per μS and Δκ."""
    import matplotlib.pyplot as plt

    axes = axes if axes is not None else plt.subplots(1, 3, figsize=(12, 4), sharey=True)[1]
    H = MODEL_STRIP.thickness
    Y = np.linspace(0.0, H, 241)
    for ax, kappa in zip(axes, CURVATURES, strict=True):
        for k, mu_s in enumerate(SPONGIOSA_MODULI):
            layers = trilayer(mu_s, H)
            colour = f"C{k}"
            ax.plot(Y / H, bend(layers, _SIGN[direction] * kappa).profile(Y)[0], colour, label=f"μS = {mu_s:g} kPa")
        ax.plot(Y / H, unbonded_stretch(trilayer(1e-3, H), _SIGN[direction] * kappa, Y), "k--", label="unbonded")
        for f in (0.25, 0.55):
            ax.axvline(f, color="0.8", lw=0.8)
        ax.set(xlabel="normalised thickness (V → F)", title=f"{direction}, Δκ = {kappa} mm⁻¹")
    axes[0].set_ylabel("Λ1")
    axes[0].legend(fontsize=7)
    return axes


def figure_8(axes=None):
    """Neutral axis of the bimodular bilayer vs Δκ (Rivlin) beside Fig. 8 and Table 2; Λ1 profiles."""
    import matplotlib.pyplot as plt

    axes = axes if axes is not None else plt.subplots(1, 2, figsize=(10, 4))[1]
    H = SPECIMEN_STRIP.thickness
    bilayer = bimodular_bilayer(H)
    kappa = np.linspace(0.02, 0.3, 15)
    for k, direction in enumerate(("WC", "AC")):
        c = f"C{k}"
        axes[0].plot(kappa, [neutral_axis(bilayer, direction, q) for q in kappa], c, label=f"Rivlin {direction}")
        axes[0].axhline(FIG8_NEUTRAL_AXIS[direction], color=c, ls=":", label=f"Fig. 8 {direction} (centre)")
        col = 2 if direction == "AC" else 5
        shift = 0.004 * (1 if direction == "AC" else -1)
        axes[0].plot(np.array(list(TABLE2)) + shift, [v[col] for v in TABLE2.values()], c + "s", mfc="none",
                     label=f"Table 2 sim. {direction} (edge)")
        axes[0].errorbar(np.array(list(TABLE2)) - shift, [v[col - 2] for v in TABLE2.values()],
                         [v[col - 1] for v in TABLE2.values()],
                         fmt=c + "o", capsize=3, label=f"Table 2 exp. {direction}")
        Y = np.linspace(0.0, H, 201)
        axes[1].plot(Y / H, bend(bilayer, _SIGN[direction] * 0.2).profile(Y)[0], c, label=f"{direction}, Δκ = 0.2")
    axes[0].set(xlabel="Δκ (mm⁻¹)", ylabel="neutral axis (0 = V, 1 = F)", title="Bimodular bilayer (Table 3)")
    axes[0].legend(fontsize=7, ncol=2)
    axes[1].axhline(1.0, color="0.6", lw=0.8)
    axes[1].axvline(0.4, color="0.8", lw=0.8)
    axes[1].set(xlabel="normalised thickness (V → F)", ylabel="Λ1", title="Rivlin Λ1, bimodular bilayer")
    axes[1].legend(fontsize=8)
    return axes


def write_figures(out: Path, studies: dict | None = None) -> list[Path]:
    """Write Figs. 3, 4/9 (bounds), 8 and, given the FE studies of :func:`buchanan2014_fe.fe_rows`,
    7 (3D warping) and 4/9 (pin-ended sliding study) as PNG files into ``out``."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from .buchanan2014_fe import figure_7, figure_11
    from .buchanan2014_sliding import figure_4_9_end_loading

    out.mkdir(parents=True, exist_ok=True)
    paths = []
    figures = [("fig3_ogden_moment_curvature", figure_3), ("fig4_9_transmural_bounds", figure_4_bounds),
               ("fig8_bimodular_neutral_axis", figure_8)]
    studies = studies or {}
    if studies.get("warping") is not None:
        figures.append(("fig7_edge_centre_warping", lambda: figure_7(studies["warping"])))
    if studies.get("warping_thickness") is not None:
        figures.append(("fig11_warping_vs_thickness", lambda: figure_11(studies["warping_thickness"])))
    if studies.get("sliding") is not None:
        figures.append(("fig4_9_end_loading_sliding", lambda: figure_4_9_end_loading(studies["sliding"])))
    for name, draw in figures:
        draw()
        path = out / f"buchanan2014_{name}.png"
        plt.gcf().savefig(path, dpi=120, bbox_inches="tight")
        plt.close("all")
        paths.append(path)
    return paths


def reproduce(out: Path | None = None, full: bool = False) -> list[Row]:
    """All rows; figures written to ``out`` when given. ``full`` refines the FE meshes and sweeps."""
    from . import buchanan2014_fe

    rows = analytic_rows()
    fe, studies = buchanan2014_fe.fe_rows(full)
    if out is not None:
        write_figures(Path(out), studies)
    return rows + fe
