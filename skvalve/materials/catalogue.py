"""Catalogue of the material laws with the parameters of the three papers (``skvalve materials``).

Units: kPa for stresses and moduli (D in 1/kPa), stretches dimensionless; fiber forces in nN.
Sources:

* buchanan2014 — Buchanan & Sacks, Biomech Model Mechanobiol 13 (2014): Eq. 3 (μ = 45 kPa),
  Eq. 1 / Fig. 3 (one-term Ogden, fitted α ≈ 2), Eq. 4 / Table 3 (bimodular layer moduli).
* thomas2019 — Thomas et al. (2019): matrix Eq. 10 with G = 2.1 kPa, ν = 0.49; fiber Eq. 9 with
  E_f = 10.5 kPa, β = 50.5, λc = 1.12, d = 450 nm.
* mathur2022 — Texas TriValve 1.0: the paper prints Eq. 1 and Eq. 2 but its parameter tables are in
  the supplement; the values below are those of the model's Abaqus input
  (Mathur et al. 2022, Texas TriValve 1.0, CC BY-NC-SA 4.0), converted from MPa to kPa.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .base import Hyperelastic
from .bimodular_neo_hookean import BimodularNeoHookean
from .incompressible_neo_hookean import IncompressibleNeoHookean
from .lee_sacks import LeeSacks
from .neo_hookean import NeoHookean
from .ogden import Ogden

__all__ = ["CatalogueEntry", "catalogue", "main"]

TEXAS = "Mathur et al. 2022, Texas TriValve 1.0, CC BY-NC-SA 4.0"
MPA_TO_KPA = 1e3


@dataclass(frozen=True)
class CatalogueEntry:
    """One law with one paper's parameters; ``group`` entries share a figure."""

    name: str
    paper: str
    equation: str
    law: object
    units: str
    source: str
    group: str
    stretch_range: tuple[float, float] = (0.8, 1.4)


def _texas_leaflet(c0: float, D: float, c1: float, c2: float) -> LeeSacks:
    """VUANISO_ISO properties (C0, D, C1, C2) in MPa -> LeeSacks in kPa."""
    return LeeSacks(c0=c0 * MPA_TO_KPA, c1=c1 * MPA_TO_KPA, c2=c2, D=D / MPA_TO_KPA)


def _texas_chordae(mu: Sequence[float], alpha: Sequence[float], D1: float) -> Ogden:
    """Abaqus ``*Hyperelastic, OGDEN, N=3`` (mu_i, alpha_i, D1 in MPa) -> Ogden in kPa."""
    return Ogden(mu=tuple(m * MPA_TO_KPA for m in mu), alpha=tuple(alpha), D=(D1 / MPA_TO_KPA,))


def _fiber_entry() -> list[CatalogueEntry]:
    try:
        from .exponential_fiber import ExponentialFiber
    except ImportError:  # pragma: no cover - built by another work stream
        return []
    fiber = ExponentialFiber.from_diameter(E_f=10.5e3, diameter=450e-9, beta=50.5, lambda_c=1.12)
    return [
        CatalogueEntry(
            "thomas2019 collagen fiber",
            "thomas2019",
            "Eq. 9",
            fiber,
            "E_f in Pa, d = 450 nm; force in nN",
            "Results: E_f = 10.5 kPa, beta = 50.5, lambda_c = 1.12; Methods: d = 450 nm",
            "thomas2019_fiber",
            (0.95, 1.2),
        )
    ]


def catalogue() -> list[CatalogueEntry]:
    """All catalogue entries (laws instantiated with the papers' parameters)."""
    e1 = [1.0, 0.0, 0.0]  # circumferential (beam-axis) direction of the flexure specimens
    entries = [
        CatalogueEntry(
            "buchanan2014 leaflet layer, neo-Hookean",
            "buchanan2014",
            "Eq. 3",
            IncompressibleNeoHookean(mu=45.0),
            "kPa",
            "Sect. 3.2: mu_L = 45 kPa (fibrosa, ventricularis)",
            "buchanan2014_neo_hookean",
        ),
    ]
    for alpha in (1.0, 2.0, 4.0, 8.0):
        entries.append(
            CatalogueEntry(
                f"buchanan2014 one-term Ogden, alpha = {alpha:g}",
                "buchanan2014",
                "Eq. 1 (N = 1)",
                Ogden.from_buchanan2014(mu_p=2.0 * 45.0 / alpha, alpha_p=alpha),
                "kPa",
                "Fig. 3 family (alpha swept; fitted alpha ~ 2.0); mu_p = 2 mu / alpha so that mu = 45 kPa",
                "buchanan2014_ogden_family",
            )
        )
    for layer, mu_t, mu_c in (("fibrosa", 139.5, 29.55), ("ventricularis", 65.00, 16.74)):
        entries.append(
            CatalogueEntry(
                f"buchanan2014 {layer}, bimodular",
                "buchanan2014",
                "Eq. 4",
                BimodularNeoHookean(mu_tension=mu_t, mu_compression=mu_c, direction=e1),
                "kPa",
                f"Table 3: mu+ = {mu_t} kPa, mu- = {mu_c} kPa; direction = e1 (circumferential)",
                "buchanan2014_bimodular",
            )
        )
    entries.append(
        CatalogueEntry(
            "thomas2019 non-collagenous matrix",
            "thomas2019",
            "Eq. 10 / Eq. 13",
            NeoHookean.from_shear_poisson(G=2.1, nu=0.49),
            "kPa",
            "Results: G = 2.1 kPa; Methods: nu = 0.49",
            "thomas2019_matrix",
            (0.8, 1.5),
        )
    )
    entries += _fiber_entry()
    for leaflet, props in (
        ("anterior", (1.0e-3, 20.0669, 1.188659e-4, 15.260081)),
        ("posterior", (1.0e-3, 20.0669, 2.204214e-4, 31.90703)),
        ("septal", (1.0e-3, 20.0669, 1.984696e-4, 2.94597)),
    ):
        entries.append(
            CatalogueEntry(
                f"mathur2022 {leaflet} leaflet, Lee-Sacks",
                "mathur2022",
                "Eq. 1 as shipped: exp(c2 (I1bar - 3)^2)",
                _texas_leaflet(*props),
                "kPa",
                f"{TEXAS}: VUANISO_ISO (C0, D, C1, C2) = {props} MPa",
                "mathur2022_leaflets",
                (0.9, 1.2),
            )
        )
    for chord, mu, alpha, D1 in (
        (
            "anterior",
            (4.212040401935249, 7.621400389279001, 15.437445816336888),
            (50.42991853603889, 0.016468374322372, 50.43046978340582),
            7.3584e-04,
        ),
        (
            "posterior",
            (11.769785736240605, 12.403984726216267, 12.399238638580865),
            (49.08073536072372, 49.08069532319126, 49.08069729167792),
            5.4868e-04,
        ),
        (
            "septal",
            (43.040245810758144, 0.000135787756161, 0.000293121663589),
            (0.000113878800484, 0.004100909221214, 0.054406871730778),
            4.6623e-04,
        ),
    ):
        entries.append(
            CatalogueEntry(
                f"mathur2022 {chord} chordae, Ogden N = 3",
                "mathur2022",
                "Eq. 2",
                _texas_chordae(mu, alpha, D1),
                "kPa",
                f"{TEXAS}: *Hyperelastic, OGDEN, N=3 (MPa): mu = {mu}, alpha = {alpha}, D1 = {D1}",
                "mathur2022_chordae",
                (0.98, 1.08),
            )
        )
    return entries


def _describe(law: object) -> str:
    if isinstance(law, BimodularNeoHookean):
        return (
            f"mu_tension={law.mu_tension:g}, mu_compression={law.mu_compression:g}, direction={law.direction.tolist()}"
        )
    if isinstance(law, Hyperelastic):
        parts = []
        for key, value in law.parameters().items():
            if isinstance(value, tuple):
                value = "(" + ", ".join(f"{v:.6g}" for v in value) + ")"
            elif isinstance(value, float):
                value = f"{value:.6g}"
            parts.append(f"{key}={value}")
        return ", ".join(parts)
    return repr(law)


def print_catalogue(entries: Sequence[CatalogueEntry]) -> None:
    for entry in entries:
        print(f"{entry.name}  [{entry.paper} {entry.equation}]")
        law = entry.law
        text = f"{type(law).__name__}({_describe(law)})" if isinstance(law, Hyperelastic) else repr(law)
        print(f"    {text}  units: {entry.units}")
        print(f"    source: {entry.source}")


def _plot_group(entries: Sequence[CatalogueEntry], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..analytic.homogeneous import equibiaxial, uniaxial

    first = entries[0]
    if not isinstance(first.law, Hyperelastic):  # 1-D fiber: force-stretch
        fig, ax = plt.subplots(figsize=(4.5, 3.2))
        for entry in entries:
            lam = np.linspace(*entry.stretch_range, 200)
            ax.plot(lam, entry.law.force(lam) * 1e9, label=entry.name)
        ax.axvline(entries[0].law.lambda_c, color="0.6", ls=":", label="lambda_c")
        ax.set(xlabel="fiber stretch", ylabel="axial force (nN)", title=first.paper)
    else:
        fig, axes = plt.subplots(1, 2, figsize=(8, 3.2))
        for entry in entries:
            lam = np.linspace(*entry.stretch_range, 61)
            for ax, mode in zip(axes, (uniaxial, equibiaxial), strict=True):
                line = ax.plot(lam, mode(entry.law, lam).cauchy[0], label=entry.name)[0]
                if not entry.law.incompressible:
                    ax.plot(
                        lam, mode(entry.law, lam, incompressible=False).cauchy[0], ls="--", color=line.get_color(), lw=1
                    )
        for ax, title in zip(axes, ("uniaxial", "equibiaxial (thin sheet)"), strict=True):
            ax.set(xlabel="stretch", ylabel=f"Cauchy stress ({first.units})", title=f"{first.paper}: {title}")
            ax.axhline(0.0, color="0.8", lw=0.5)
        if any(not e.law.incompressible for e in entries):
            axes[0].plot([], [], "k--", lw=1, label="compressible (free lateral stretch)")
        ax = axes[0]
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(out: Path, show: bool = True) -> int:
    """Print the catalogue; with ``show`` write one PNG per group to ``out``. Returns an exit code."""
    entries = catalogue()
    print_catalogue(entries)
    if not show:
        return 0
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    groups: dict[str, list[CatalogueEntry]] = {}
    for entry in entries:
        groups.setdefault(entry.group, []).append(entry)
    for group, members in groups.items():
        path = out / f"{group}.png"
        _plot_group(members, path)
        print(f"wrote {path}")
    return 0
