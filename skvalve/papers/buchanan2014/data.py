"""Every number Buchanan & Sacks (2014) give, with where they give it.

R. M. Buchanan, M. S. Sacks, "Interlayer micromechanics of the aortic heart valve leaflet",
Biomech Model Mechanobiol 13:813–826 (2014), doi:10.1007/s10237-013-0536-6.

Units: lengths in mm, moduli in kPa (Table 1: MPa), curvatures in mm⁻¹, stretches dimensionless.
Layers are listed bottom up: ventricularis (normalised thickness 0) to fibrosa (1).
This module holds data only; the models built from it are in :mod:`skvalve.papers.buchanan2014.models`.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = [
    "Strip", "MODEL_STRIP", "SPECIMEN_STRIP", "SPECIMEN_SD", "SPECIMEN_COUNT", "TRILAYER_FRACTIONS",
    "BILAYER_FRACTIONS", "CURVATURES", "MU_OUTER", "MU_OUTER_R2", "SPONGIOSA_MODULI", "BONDED_SPONGIOSA_FRACTION",
    "SLIDING_SPONGIOSA_LIMIT", "FIG3_ALPHAS", "FIG3_FITTED_ALPHA", "FIG3_R2", "FIG3_MAX_CURVATURE", "LayerModuli",
    "TABLE3", "TABLE3_RELATIVE", "TABLE3_MODULI_UNCERTAINTY", "Table2Row", "TABLE2", "FIG8_NEUTRAL_AXIS",
    "AC_STRETCH_EXTREMES", "LAMBDA_EXPERIMENT_ERROR", "LAMBDA_RESOLUTION", "TRACKING_ACCURACY",
    "FIG7_WARPING", "FIG11_THICKNESSES", "SiliconeModuli", "TABLE1", "TABLE1_AVERAGE", "TABLE1_SEM",
    "SILICONE_THICKNESS",
]


class Strip(NamedTuple):
    """Rectangular strip: length (circumferential X1), width (radial X3), thickness (X2), mm."""

    length: float
    width: float
    thickness: float


MODEL_STRIP = Strip(14.0, 3.0, 0.4)  # Sect. 2.2: FE model 14 mm × 3 mm × 0.4 mm
SPECIMEN_STRIP = Strip(13.7, 2.8, 0.318)  # Sect. 2.4: mean of the specimens (318 µm thick)
SPECIMEN_SD = Strip(2.1, 0.2, 0.046)  # Sect. 2.4: ± of the specimen dimensions
SPECIMEN_COUNT = 18  # Table 3: n = 18
TRILAYER_FRACTIONS = (("ventricularis", 0.25), ("spongiosa", 0.30), ("fibrosa", 0.45))  # Sect. 2.2, bottom up
BILAYER_FRACTIONS = (("ventricularis", 0.40), ("fibrosa", 0.60))  # Sect. 3.4 / Fig. 8: spongiosa absorbed
CURVATURES = (0.1, 0.2, 0.3)  # Δκ, mm⁻¹ (Sect. 2.3, Appendix 2, Fig. 9)
MU_OUTER = 45.0  # kPa, fibrosa and ventricularis of the initial model (Sect. 3.1, Eq. 3)
MU_OUTER_R2 = 0.974  # Sect. 3.1: goodness of that fit
SPONGIOSA_MODULI = (0.001, 0.1, 1.0, 10.0, 45.0)  # kPa: 1 Pa, 0.1–10 kPa, 45 kPa (Sect. 2.3, Fig. 9)
BONDED_SPONGIOSA_FRACTION = 0.25  # Abstract: bonded when μS ≥ 25 % of the outer layers' modulus
SLIDING_SPONGIOSA_LIMIT = 1.0  # kPa, Figs. 4/9: measurable sliding only for μS < 1 kPa
FIG3_ALPHAS = (2.0, 5.0, 10.0, 20.0, 30.0)  # Fig. 3: the α family (the paper shows "various α")
FIG3_FITTED_ALPHA = 2.0  # Sect. 3.1: α ≈ 2.0 captures the shape of M–Δκ
FIG3_R2 = 0.93  # Sect. 3.1 / Fig. 3
FIG3_MAX_CURVATURE = 0.28  # mm⁻¹, Sect. 3.1: normalisation at the largest measured Δκ


class LayerModuli(NamedTuple):
    """Bimodular neo-Hookean moduli of a layer (Eq. 4), kPa."""

    mu_tension: float
    mu_compression: float


TABLE3 = {"fibrosa": LayerModuli(139.5, 29.55), "ventricularis": LayerModuli(65.00, 16.74)}  # Table 3
TABLE3_RELATIVE = {"fibrosa": (100.0, 21.2, 4.72), "ventricularis": (46.6, 12.0, 3.88)}  # Table 3: %, %, μ+/μ−
TABLE3_MODULI_UNCERTAINTY = 0.5  # kPa, Sect. 3.4: "within ±0.5 kPa"


class Table2Row(NamedTuple):
    """Table 2 at one Δκ: neutral axis (normalised thickness), experiment ± SD and simulation, AC and WC."""

    ac_experiment: float
    ac_sd: float
    ac_simulation: float
    wc_experiment: float
    wc_sd: float
    wc_simulation: float


TABLE2 = {
    0.1: Table2Row(0.5987, 0.0929, 0.6209, 0.5453, 0.1012, 0.4935),
    0.2: Table2Row(0.5903, 0.1022, 0.5994, 0.5571, 0.1021, 0.5495),
    0.3: Table2Row(0.6026, 0.0730, 0.5835, 0.5629, 0.0315, 0.5670),
}
FIG8_NEUTRAL_AXIS = {"WC": 0.35, "AC": 0.79}  # Sect. 3.4 / Fig. 8: centre of the strip
AC_STRETCH_EXTREMES = {0.1: (1.016, 0.984), 0.3: (1.026, 0.969)}  # Sect. 3.3: (max Λ1, min Λ1) in AC
LAMBDA_EXPERIMENT_ERROR = 0.0141  # Sect. 3.4: experimental error of Λ1
LAMBDA_RESOLUTION = 0.001  # Sect. 2.4: tracking measures stretches as small as 1.001
TRACKING_ACCURACY = 0.0005  # Sect. 2.4: 0.05 % net accuracy
FIG7_WARPING = 0.02  # Sect. 3.4: edge − centre Λ1 of "~0.02" (3D FE, Fig. 7)
FIG11_THICKNESSES = (0.2, 0.3, 0.4)  # mm: the thickness sweep of Fig. 11 (values not printed; chosen here)
SILICONE_THICKNESS = 1.0  # mm, Sect. 2.5: silicone validation sheets (14 mm × 3 mm)


class SiliconeModuli(NamedTuple):
    """Table 1: Young's modulus of a silicone strip (MPa) by the three methods."""

    model: float
    flexure: float
    tensile: float


TABLE1 = (
    SiliconeModuli(5.973, 5.805, 5.551),
    SiliconeModuli(6.501, 6.558, 6.557),
    SiliconeModuli(6.593, 6.677, 6.333),
    SiliconeModuli(6.749, 7.591, 6.403),
)
TABLE1_AVERAGE = SiliconeModuli(6.454, 6.658, 6.211)
TABLE1_SEM = SiliconeModuli(0.168, 0.366, 0.225)
