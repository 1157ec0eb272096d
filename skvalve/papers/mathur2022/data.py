"""Every number of Mathur et al. (2022) skvalve uses, and the TriValve material parameters read from the file.

M. Mathur, W. D. Meador, M. Malinowski, T. Jazwiec, T. A. Timek, M. K. Rausch, "Texas TriValve 1.0: a
reverse-engineered, open model of the human tricuspid valve", Engineering with Computers (2022),
doi:10.1007/s00366-022-01659-w. The model files are licensed CC BY-NC-SA 4.0 (:data:`CREDIT`); they are
never copied into skvalve: :func:`skvalve.io.abaqus.trivalve_input` finds them (``$SKVALVE_TRIVALVE``, the
.inp file or its folder, else ``../shared/data/texas_trivalve/`` beside the repository or the working directory).

The paper prints the laws (Eq. 1 leaflets, Eq. 2 chordae) but its parameter tables are in the supplement;
the values used are those of the model's Abaqus input, read by :func:`read_trivalve_materials` in the
file's units (MPa). Paper values below are in the paper's units (mm, mm², kPa, mmHg, s).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from ...io.abaqus import read_materials, trivalve_input

__all__ = [
    "CREDIT", "CREDIT_1_1", "LEAFLETS", "ValveStates", "TABLE2_AREAS", "TABLE3_CENTRE_STRESS",
    "PRESSURE_HEALTHY_MMHG", "PRESSURE_DISEASED_MMHG", "LEAFLET_THICKNESS", "CHORDAE_DIAMETER", "POISSON_RATIO",
    "BULK_MODULUS_KPA", "TIME_STEP_HEALTHY", "TIME_STEP_DISEASED", "CLIP_ARM_GAP", "ANNULOPLASTY_RING_SIZE",
    "ECHO_DISTANCES", "ECHO_ERROR_RANGE", "BIAXIAL_SAMPLE_SIZE", "BIAXIAL_FORCE_MN", "LeafletParameters",
    "ChordaeParameters", "TriValveMaterials", "read_trivalve_materials",
]

CREDIT = "Mathur et al. 2022, Texas TriValve 1.0, CC BY-NC-SA 4.0"
#: the Texas TriValve 1.1 inputs (a second donor valve, Soft Tissue Biomechanics Lab, the method of Mathur et al. 2022)
CREDIT_1_1 = "Texas TriValve 1.1 (Soft Tissue Biomechanics Lab; method of Mathur et al. 2022), CC BY 4.0"
LEAFLETS = ("anterior", "posterior", "septal")


class ValveStates(NamedTuple):
    """One quantity of Tables 2/3 in the four valve states at end-systole."""

    healthy: float
    diseased: float
    annuloplasty: float
    clip: float


TABLE2_AREAS = {  # Table 2, mm²
    "orifice": ValveStates(400.0, 870.0, 534.0, 870.0),
    "leaflet": ValveStates(1356.0, 2236.0, 2051.0, 2258.0),
    "coaptation": ValveStates(577.0, 228.0, 607.0, 265.0),
}
TABLE3_CENTRE_STRESS = {  # Table 3: maximum principal Cauchy stress at the leaflet centre, kPa
    "anterior": ValveStates(16.82, 83.61, 38.07, 84.27),
    "posterior": ValveStates(15.12, 63.65, 35.43, 66.44),
    "septal": ValveStates(21.90, 87.97, 57.75, 99.14),
}
PRESSURE_HEALTHY_MMHG = 22.95  # Sect. 2.6: end-systolic transvalvular pressure (ex vivo)
PRESSURE_DISEASED_MMHG = 42.5  # Sect. 2.9: elevated pathological pressure
LEAFLET_THICKNESS = 0.78  # mm, Sect. 2.8
CHORDAE_DIAMETER = {"anterior": 0.65, "posterior": 0.64, "septal": 0.71}  # mm, Sect. 2.8
POISSON_RATIO = 0.495  # Sect. 2.8: leaflet bulk penalty
BULK_MODULUS_KPA = 99.67  # Sect. 2.8
TIME_STEP_HEALTHY = 1e-6  # s, Sect. 2.8: mass-scaled minimum time step, healthy valve
TIME_STEP_DISEASED = 1e-7  # s, Sect. 2.8: diseased valve
CLIP_ARM_GAP = 1.4  # mm, Sect. 2.11
ANNULOPLASTY_RING_SIZE = 30  # Sect. 2.9: Carpentier-Edwards Physio Tricuspid ring size
ECHO_DISTANCES = {"S-A": (22.9, 22.9), "S-C": (10.6, 10.7), "A-C": (13.6, 14.0), "C-T": (4.4, 2.8)}  # Sect. 3.1, mm:
#                 (model, echocardiography) between hinge points A, S, coaptation point C and free-edge tip T
ECHO_ERROR_RANGE = (1.4, 3.0)  # mm, Sect. 3.1: expected error of 2D echocardiographic distances
BIAXIAL_SAMPLE_SIZE = 7.0  # mm, Sect. 2.3: square leaflet samples
BIAXIAL_FORCE_MN = 400.0  # mN, Sect. 2.3: force-controlled equibiaxial tests


@dataclass(frozen=True)
class LeafletParameters:
    """``VUANISO_ISO`` properties (C0, D, C1, C2) of a leaflet as in the file (MPa, 1/MPa, MPa, -)."""

    c0: float
    D: float
    c1: float
    c2: float


@dataclass(frozen=True)
class ChordaeParameters:
    """``*Hyperelastic, OGDEN, N=3``: μ_i (MPa), α_i and D1 (1/MPa) as in the file."""

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    D1: float


@dataclass(frozen=True)
class TriValveMaterials:
    """Leaflet and chordae parameters by leaflet name (:data:`LEAFLETS`), and the file they came from."""

    leaflets: dict[str, LeafletParameters]
    chordae: dict[str, ChordaeParameters]
    source: Path


def read_trivalve_materials(path: str | os.PathLike | None = None) -> TriValveMaterials:
    """Leaflet (``VUANISO_ISO_<Leaflet>``) and chordae (``<Leaflet>_Chordae``) parameters from a TriValve .inp
    (default: :func:`skvalve.io.abaqus.trivalve_input`, the diseased 1.0 input).

    Raises ``FileNotFoundError`` naming ``$SKVALVE_TRIVALVE`` when no file is given or found, and
    ``KeyError``/``ValueError`` naming the material when the file lacks one or its data are incomplete.
    """
    path = trivalve_input() if path is None else Path(path)
    if path is None or not path.is_file():
        where = path or "searched ../shared/data/texas_trivalve"
        raise FileNotFoundError(f"Texas TriValve input not found ({where}): set $SKVALVE_TRIVALVE to the .inp file "
                                "or its folder (the model files of Mathur et al. 2022, CC BY-NC-SA 4.0)")
    materials = read_materials(path)
    leaflets, chordae = {}, {}
    for leaflet in LEAFLETS:
        name = f"VUANISO_ISO_{leaflet.capitalize()}"
        if name not in materials:
            raise KeyError(f"{path}: no *Material, name={name}")
        data = materials[name].option("anisotropic").data
        if len(data) != 4:
            raise ValueError(f"{path}: material {name} has {len(data)} properties; VUANISO_ISO needs 4")
        leaflets[leaflet] = LeafletParameters(*data)
        name = f"{leaflet.capitalize()}_Chordae"
        if name not in materials:
            raise KeyError(f"{path}: no *Material, name={name}")
        data = materials[name].option("hyperelastic").data
        if len(data) < 7:
            raise ValueError(f"{path}: material {name} has {len(data)} Ogden values; N=3 needs 7")
        chordae[leaflet] = ChordaeParameters(tuple(data[0:6:2]), tuple(data[1:6:2]), data[6])
    return TriValveMaterials(leaflets, chordae, path)
