"""Catalogue of the material laws with the papers' parameters (``skvalve materials``).

Each entry is a library law built from a paper's data module: buchanan2014 (:mod:`.buchanan2014.data`:
Eq. 3 μ = 45 kPa, the Fig. 3 Ogden family, Eq. 4 with Table 3; kPa), thomas2019 (:mod:`.thomas2019.models`:
matrix Eq. 10 and fiber Eq. 9; Pa) and mathur2022 (the Texas TriValve input read by :mod:`.mathur2022.data`,
present only when the shared data set is found; kPa, D in 1/kPa). Figures: :mod:`.catalogue_figures`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..io.abaqus import trivalve_input
from ..materials import BimodularNeoHookean, Hyperelastic, IncompressibleNeoHookean, Ogden
from .buchanan2014.data import MU_OUTER, TABLE3
from .buchanan2014.models import CIRCUMFERENTIAL
from .mathur2022.data import CREDIT, LEAFLETS, read_trivalve_materials
from .mathur2022.models import chordae_law, leaflet_law
from .thomas2019 import data as thomas2019
from .thomas2019.models import fiber_law, matrix_law

__all__ = ["CatalogueEntry", "catalogue", "describe", "print_catalogue"]

OGDEN_FAMILY = (1.0, 2.0, 4.0, 8.0)  # α of the one-term Ogden curves shown beside Fig. 3's fitted α ≈ 2


@dataclass(frozen=True)
class CatalogueEntry:
    """One law with one paper's parameters; entries of one ``group`` share a figure."""

    name: str
    paper: str
    equation: str
    law: object
    units: str
    source: str
    group: str
    stretch_range: tuple[float, float] = (0.8, 1.4)


def _buchanan2014() -> list[CatalogueEntry]:
    entries = [CatalogueEntry("buchanan2014 leaflet layer, neo-Hookean", "buchanan2014", "Eq. 3",
                              IncompressibleNeoHookean(mu=MU_OUTER), "kPa",
                              f"Sect. 3.1: mu_L = {MU_OUTER:g} kPa (fibrosa, ventricularis)",
                              "buchanan2014_neo_hookean")]
    for alpha in OGDEN_FAMILY:
        entries.append(CatalogueEntry(
            f"buchanan2014 one-term Ogden, alpha = {alpha:g}", "buchanan2014", "Eq. 1 (N = 1)",
            Ogden.from_buchanan2014(mu_p=2.0 * MU_OUTER / alpha, alpha_p=alpha), "kPa",
            f"Fig. 3 family (alpha swept; fitted alpha ~ 2.0); mu_p = 2 mu / alpha so that mu = {MU_OUTER:g} kPa",
            "buchanan2014_ogden_family"))
    for layer, moduli in TABLE3.items():
        entries.append(CatalogueEntry(
            f"buchanan2014 {layer}, bimodular", "buchanan2014", "Eq. 4",
            BimodularNeoHookean(*moduli, direction=CIRCUMFERENTIAL), "kPa",
            f"Table 3: mu+ = {moduli.mu_tension} kPa, mu- = {moduli.mu_compression} kPa; direction = e1 "
            "(circumferential)", "buchanan2014_bimodular"))
    return entries


def _thomas2019() -> list[CatalogueEntry]:
    d = thomas2019
    return [
        CatalogueEntry("thomas2019 non-collagenous matrix", "thomas2019", "Eq. 10 / Eq. 13", matrix_law(), "Pa",
                       f"§3: G = {d.G:g} Pa; §2.4: nu = {d.NU}", "thomas2019_matrix", (0.8, 1.5)),
        CatalogueEntry("thomas2019 collagen fiber", "thomas2019", "Eq. 9", fiber_law(), "E_f in Pa; force in nN",
                       f"§3: E_f = {d.E_F:g} Pa, beta = {d.BETA}, lambda_c = {d.LAMBDA_C}; §2.5: d = "
                       f"{d.FIBER_DIAMETER * 1e9:g} nm", "thomas2019_fiber", (0.95, 1.2)),
    ]


def _mathur2022() -> list[CatalogueEntry]:
    path = trivalve_input()
    if path is None:
        return []
    materials = read_trivalve_materials(path)
    entries = []
    for leaflet in LEAFLETS:
        p = materials.leaflets[leaflet]
        entries.append(CatalogueEntry(
            f"mathur2022 {leaflet} leaflet, Lee-Sacks", "mathur2022", "Eq. 1 as shipped: exp(c2 (I1bar - 3)^2)",
            leaflet_law(p), "kPa", f"{CREDIT}: VUANISO_ISO (C0, D, C1, C2) = {(p.c0, p.D, p.c1, p.c2)} MPa "
            f"({path.name})", "mathur2022_leaflets", (0.9, 1.2)))
    for leaflet in LEAFLETS:
        p = materials.chordae[leaflet]
        entries.append(CatalogueEntry(
            f"mathur2022 {leaflet} chordae, Ogden N = 3", "mathur2022", "Eq. 2", chordae_law(p), "kPa",
            f"{CREDIT}: *Hyperelastic, OGDEN, N=3 (MPa): mu = {p.mu}, alpha = {p.alpha}, D1 = {p.D1} ({path.name})",
            "mathur2022_chordae", (0.98, 1.08)))
    return entries


def catalogue() -> list[CatalogueEntry]:
    """All catalogue entries (laws built with the papers' parameters); mathur2022 only when its data are found."""
    return _buchanan2014() + _thomas2019() + _mathur2022()


def describe(law: object) -> str:
    """``Law(parameter=value, ...)`` with 6 significant digits."""
    if isinstance(law, BimodularNeoHookean):
        return (f"BimodularNeoHookean(mu_tension={law.mu_tension:g}, mu_compression={law.mu_compression:g}, "
                f"direction={law.direction.tolist()})")
    if not isinstance(law, Hyperelastic):
        return repr(law)
    parts = []
    for key, value in law.parameters().items():
        if isinstance(value, tuple):
            value = "(" + ", ".join(f"{v:.6g}" for v in value) + ")"
        elif isinstance(value, float):
            value = f"{value:.6g}"
        parts.append(f"{key}={value}")
    return f"{type(law).__name__}({', '.join(parts)})"


def print_catalogue(entries: Sequence[CatalogueEntry]) -> None:
    """Print each entry: name, paper and equation, the law, its source."""
    for entry in entries:
        print(f"{entry.name}  [{entry.paper} {entry.equation}]")
        print(f"    {describe(entry.law)}  units: {entry.units}")
        print(f"    source: {entry.source}")
    if not any(e.paper == "mathur2022" for e in entries):
        print("mathur2022: Texas TriValve input not found; set $SKVALVE_TRIVALVE to the .inp file or its folder")
