"""``skvalve reproduce buchanan2014``: the rows and figures, stage by stage (see :mod:`skvalve.papers.registry`).

Stages (default run ≈ 1 min on one core; ``full`` refines meshes and sweeps, several minutes):

1. Rivlin (exact pure bending): Fig. 8 / Table 2 neutral axes, Sect. 3.3 stretches, Table 1/3 arithmetic,
   closed-form checks; Figs. 3, 4/9 (bounds), 8.
2. Plane-strain FE of the tri-layer against Rivlin (mesh sequence).
3. Plane-strain FE of the smoothed bimodular bilayer, WC and AC.
4. 3D quarter strip: edge-versus-centre warping (Fig. 7); with ``full`` the thickness sweep (Fig. 11).
5. Pin-ended end loading, μS sweep: sliding threshold (Figs. 4/9, end loading).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ..table import Row, Stage, Written
from .data import CURVATURES
from .fe import warping_study, warping_versus_thickness
from .figures import ANALYTIC_FIGURES, figure_4_9_end_loading, figure_7, figure_11, write_figure
from .rows import (
    analytic_rows,
    bimodular_fe_rows,
    closed_form_rows,
    fe_convergence_rows,
    sliding_rows,
    warping_rows,
    warping_thickness_rows,
)
from .sliding import SLIDING_SPONGIOSA_MODULI, SLIDING_SPONGIOSA_MODULI_DEFAULT, sliding_study

__all__ = ["DESCRIPTION", "reproduce"]

DESCRIPTION = ("neutral axes (Fig. 8, Table 2), transmural stretches (Sect. 3.3), Table 1/3 arithmetic and "
               "closed-form checks from Rivlin's solution; FE strips against Rivlin; 3D warping (Fig. 7); "
               "pin-ended sliding study (Figs. 4/9)")


def reproduce(out: Path | None = None, full: bool = False) -> Iterator[Row | Stage | Written]:
    """Yield the rows as they are computed, :class:`Stage` lines before each long step, and a
    :class:`Written` item per figure saved to ``out`` (no figures when ``out`` is None)."""
    out = None if out is None else Path(out)
    yield Stage("Rivlin pure bending: Fig. 8, Table 2, Sect. 3.3, Tables 1/3, closed forms")
    yield from analytic_rows()
    yield from closed_form_rows()
    if out is not None:
        for name, draw in ANALYTIC_FIGURES:
            yield Written(write_figure(out, name, draw))
    yield Stage("FE tri-layer (plane strain, Q2/Q1) against Rivlin, " + ("4" if full else "3") + " meshes")
    yield from fe_convergence_rows(full)
    yield Stage("FE bimodular bilayer (plane strain), WC and AC")
    yield from bimodular_fe_rows(full)
    yield Stage("FE 3D quarter strip, edge-versus-centre warping (Fig. 7)")
    warp = warping_study(nx=12 if full else 8, ny=2 if full else 1, nz=10 if full else 6)
    yield from warping_rows(warp)
    if out is not None:
        yield Written(write_figure(out, "fig7_edge_centre_warping", lambda: figure_7(warp)))
    if full:
        yield Stage("FE 3D warping versus thickness (Fig. 11): 9 strips")
        table = warping_versus_thickness()
        yield from warping_thickness_rows(table)
        if out is not None:
            yield Written(write_figure(out, "fig11_warping_vs_thickness", lambda: figure_11(table)))
    moduli = SLIDING_SPONGIOSA_MODULI if full else SLIDING_SPONGIOSA_MODULI_DEFAULT
    yield Stage(f"FE pin-ended end loading (Figs. 4/9), μS = {', '.join(f'{m:g}' for m in moduli)} kPa")
    study = sliding_study(moduli, CURVATURES if full else (0.2,))
    yield from sliding_rows(study)
    if out is not None:
        yield Written(write_figure(out, "fig4_9_end_loading_sliding", lambda: figure_4_9_end_loading(study)))
