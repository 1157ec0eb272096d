"""Every number Thomas et al. (2019) give, with where they give it.

V. S. Thomas, V. Lai, R. Amini, "A computational multi-scale approach to investigate mechanically-induced
changes in tricuspid valve anterior leaflet microstructure", Acta Biomaterialia 94 (2019) 524–535.

Units: SI (Pa, m) unless the name says otherwise (``_MM``, ``_KPA``, ``_N_PER_M``, percent for α).
This module holds data only; the models built from it are in :mod:`skvalve.papers.thomas2019.models`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# --- fitted model parameters (§3, "The model fit parameters ..."; ν and ψ, d: §2.4–2.5)
G = 2.1e3  # matrix shear modulus (Pa), §3
NU = 0.49  # matrix Poisson's ratio, §2.4 assumption 2
E_F = 10.5e3  # fiber modulus (Pa), §3
BETA = 50.5  # fiber nonlinearity β, §3
LAMBDA_C = 1.12  # fiber critical stretch λc, §3
PSI = 0.43  # fiber volume fraction ψ, §2.5
FIBER_DIAMETER = 450e-9  # collagen fiber diameter (m), §2.5
FIBER_AREA = math.pi * FIBER_DIAMETER**2 / 4.0  # A_f of Eqs. 6-9 for a circular fiber

# --- the sample and its mesh (§2.5)
SAMPLE_SIZE_MM = (7.0, 7.0, 0.406)  # circumferential (x) × radial (y) × thickness (z), §2.5
MESH_DIVISIONS = (28, 28, 3)  # 2352 trilinear hexes in three layers, §2.5 (28 × 28 × 3 = 2352)
GAUSS_POINTS = 8  # RVEs per element, §2.4
FIBERS_PER_RVE = 450  # "an average of 450 fibers", §2.5
DOFS_PER_RVE = 2700  # "nearly 2700 degrees of freedom" per RVE, §2.5
EXCISED_SAMPLE_MM = (10.0, 10.0, 0.406)  # the excised square, §4

# --- Fig. 6: the three networks (α before and after equibiaxial loading), §3 and §4
ALPHA_N1 = 41.0  # belly, Fig. 6d (%)
ALPHA_N2 = 27.0  # near the left boundary, Fig. 6e (%)
ALPHA_N3 = 28.0  # near the top boundary, Fig. 6f (%)
ALPHA_N2_DEFORMED = 36.0  # §4: "increased from 27% to 36%"
ALPHA_N3_DEFORMED = 40.0  # §4: "increased from 28% to 40%"
FIBER_STRAIN_N1 = 0.13  # majority of N1 fibers "approximately 13%", §3 (Fig. 6m)
FIBER_STRAIN_MAX = 0.30  # N2/N3 fibers "up to a maximum strain of ~30%", §3 (Fig. 6n,o)
# Locations read off the schematic Fig. 4 (approximate; as fractions of the sample's width and height):
# N1 in the belly (centre), N2 close to the left boundary, N3 close to the top boundary.
NETWORK_LOCATIONS = {"N1": (0.5, 0.5), "N2": (0.09, 0.5), "N3": (0.5, 0.91)}
# Default α map (not in the paper, which shows its SALS map only as Fig. 2e): edge band in mm, see .sample
DEFAULT_MAP_EDGE_BAND_MM = (1.0, 3.0)

# --- loading (§2.1, §2.5, Fig. 5b)
PROTOCOLS = ((0.5, 1.0), (0.75, 1.0), (1.0, 1.0), (1.0, 0.75), (1.0, 0.5))  # circumferential : radial tension, §2.5
MAX_TENSION_N_PER_M = 40.0  # "loading the sample up to 40 N/m", §2.1
PRECONDITIONING_TENSION_N_PER_M = 100.0  # preconditioning peak, §2.1 (not simulated)

# --- Table 1: [min, max] of E11, E22 (Green strain) and S11, S22 (Cauchy stress, kPa), final state
TABLE1 = {
    (0.5, 1.0): {"E11": (-0.0667, 0.1240), "E22": (0.0024, 0.2433),
                   "S11": (-0.1108, 27.8545), "S22": (-0.0636, 75.3780)},
    (0.75, 1.0): {"E11": (-0.0452, 0.1514), "E22": (0.0022, 0.2505),
                   "S11": (-0.1230, 53.3879), "S22": (-0.0760, 90.0844)},
    (1.0, 1.0): {"E11": (-0.0522, 0.2072), "E22": (0.0022, 0.2594),
                   "S11": (-0.1379, 117.9156), "S22": (-0.0902, 110.0844)},
    (1.0, 0.75): {"E11": (-0.0522, 0.2239), "E22": (0.0023, 0.2616),
                   "S11": (-0.1420, 141.7450), "S22": (-0.0934, 115.3076)},
    (1.0, 0.5): {"E11": (-0.0643, 0.2744), "E22": (-0.0141, 0.2684),
                   "S11": (-0.1539, 221.9012), "S22": (-0.1019, 130.3874)},
}

# --- fit quality (§3) and sensitivity (§4)
R2_OVERALL = 0.93
R2_PER_PROTOCOL = {(0.5, 1.0): 0.82, (0.75, 1.0): 0.99, (1.0, 1.0): 0.98, (1.0, 0.75): 0.93, (1.0, 0.5): 0.85}
R2_NEAR_EQUIBIAXIAL = 0.97  # protocols 0.75:1, 1:1, 1:0.75 together, §3
# % change of the SSE for -5 % / +5 % of each parameter, §4
SENSITIVITY_SSE_PERCENT = {"lambda_c": (160.28, 325.42), "G": (35.66, 39.74), "E_f": (36.94, 42.82),
                           "beta": (143.36, 69.30)}

# --- cost of the paper's simulation (§2.5)
PAPER_CORES = 200
PAPER_WALL_HOURS = 15.0


# --- the same parameters grouped for the library calls (frozen; every value is one of the constants above,
#     with its place in the paper given there and repeated here)
@dataclass(frozen=True)
class MatrixParameters:
    """Eq. 10, compressible neo-Hookean matrix: shear modulus G (Pa, fitted, §3) and ν (§2.4 assumption 2)."""

    G: float
    nu: float


@dataclass(frozen=True)
class FiberParameters:
    """Eq. 9 fiber law: E_f (Pa), β, λc (fitted, §3) and the fiber diameter d (m, §2.5, "assumed to be 450 nm")."""

    E_f: float
    beta: float
    lambda_c: float
    diameter: float

    @property
    def area(self) -> float:
        """A_f = π d²/4 of Eqs. 6–9 (circular fiber)."""
        return math.pi * self.diameter**2 / 4.0


@dataclass(frozen=True)
class NetworkParameters:
    """RVE networks (§2.5): fiber volume fraction ψ (Eqs. 6–8, "43%") and fibers per RVE ("an average of 450")."""

    volume_fraction: float
    fibers_per_rve: int


MATRIX = MatrixParameters(G=G, nu=NU)  # §3, §2.4
FIBER = FiberParameters(E_f=E_F, beta=BETA, lambda_c=LAMBDA_C, diameter=FIBER_DIAMETER)  # §3, §2.5
NETWORK = NetworkParameters(volume_fraction=PSI, fibers_per_rve=FIBERS_PER_RVE)  # §2.5
