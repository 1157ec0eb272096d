"""Which column of the paper's Tables 2–3 each Texas TriValve input answers, and the rows of one column.

The paper (Mathur et al. 2022) closes one donor valve, Texas TriValve 1.0, diseased and with two virtual repairs, and
reports a healthy column of the same donor. The shared data hold the 1.0 diseased, annuloplasty and clip inputs and
the two inputs of Texas TriValve 1.1, a second donor valve (healthy at the paper's healthy pressure, and diseased).
:data:`COLUMNS` says which paper column each input is compared with, and why a 1.1 input may differ from it.

:func:`column_rows` yields, for a state of one input, the rows of its column: orifice, leaflet and coaptation area
(Table 2) and the leaflet-centre maximum principal Cauchy stresses (Table 3), each with its tolerance and, where the
model is known to differ from the paper's, the reason.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from ...valve.outputs import ClosureMeasures
from ..table import Reason, Row
from .data import CREDIT, CREDIT_1_1, LEAFLETS, PRESSURE_HEALTHY_MMHG, TABLE2_AREAS, TABLE3_CENTRE_STRESS

__all__ = ["COLUMNS", "Column", "SURFACE", "column_rows"]

MPA_TO_KPA = 1e3
SURFACE = "mid"  # which leaflet surface the areas are measured on (the paper does not say)


@dataclass(frozen=True)
class Column:
    """An input's place in Tables 2–3.

    ``state``: the :class:`~skvalve.papers.mathur2022.data.ValveStates` field of the paper column it is compared
    with; ``label``: its name in the rows; ``donor``: why the input is not the paper's valve (None: it is);
    ``credit``: the model files' authors and licence.
    """

    key: str
    state: str
    label: str
    donor: str | None
    credit: str


COLUMNS = {column.key: column for column in (
    Column("1.0-diseased", "diseased", "diseased", None, CREDIT),
    Column("1.0-annuloplasty", "annuloplasty", "annuloplasty", None, CREDIT),
    Column("1.0-clipping", "clip", "clip", None, CREDIT),
    Column("1.1-healthy", "healthy", "healthy, TTV 1.1", f"another donor valve: Texas TriValve 1.1 healthy, "
           f"closed at the paper's healthy pressure ({PRESSURE_HEALTHY_MMHG} mmHg), compared with the paper's "
           "healthy column of the 1.0 donor", CREDIT_1_1),
    Column("1.1-diseased", "diseased", "diseased, TTV 1.1", "another donor valve: Texas TriValve 1.1 diseased, "
           "which the paper does not report, beside the paper's diseased column of the 1.0 donor", CREDIT_1_1),
)}


def _leaflet_of(region: str) -> str:
    """The paper's leaflet name (:data:`LEAFLETS`) in a region name such as ``Anterior``."""
    found = [leaflet for leaflet in LEAFLETS if leaflet in region.lower()]
    if len(found) != 1:
        raise ValueError(f"leaflet region {region!r} names none or several of {LEAFLETS}")
    return found[0]


def column_rows(column: Column, measures: ClosureMeasures, open_measures: ClosureMeasures, dhat: float,
                incomplete: str = "") -> Iterator[Row]:
    """The Table 2–3 rows of ``column`` for the measures of a closed state.

    ``open_measures``: those of the open (reference) configuration; ``dhat``: the IPC barrier's range (mm) the
    state was computed with; ``incomplete``: empty for a converged state, else why it is not (added to each note).
    """
    suffix = f"; {incomplete}" if incomplete else ""
    donor = f"{column.donor}; " if column.donor else ""
    difference = Reason.MODEL_DIFFERENCE
    areas = {name: getattr(values, column.state) for name, values in TABLE2_AREAS.items()}
    orifice_reason = difference if column.donor or column.state == "annuloplasty" else None
    ring = ("; the annulus follows the ring through the input's LINK MPCs, which skvalve models as stiff bars, not "
            "rigid links" if column.state == "annuloplasty" else "")
    yield Row(f"Table 2 orifice area, {column.label} (mm²; closed valve)", areas["orifice"],
              measures.orifice[SURFACE], 0.03, relative=True, expected_difference=orifice_reason,
              note=f"{donor}annulus loop of the mid surface at the state, projected on its best-fit plane (open "
                   f"configuration: {open_measures.orifice[SURFACE]:.0f} mm²){ring}{suffix}")
    open_area, area = open_measures.leaflet_area[SURFACE], measures.leaflet_area[SURFACE]
    yield Row(f"Table 2 leaflet area, {column.label} (mm²)", areas["leaflet"], area, 0.1, relative=True,
              expected_difference=difference,
              note=f"{donor}mid surface of all leaflets; areal stretch from the open configuration ({open_area:.0f} "
                   f"mm²) {area / open_area:.2f} here against {areas['leaflet'] / open_area:.2f} in the paper; the "
                   "implicit equilibrium carries the whole pressure without the explicit run's inertia and bulk "
                   f"viscosity, and the paper does not say which surface it measured{suffix}")
    yield Row(f"Table 2 coaptation area, {column.label} (mm²)", areas["coaptation"], measures.coaptation_area, 0.3,
              relative=True, expected_difference=difference,
              note=f"{donor}current area of the faces of the leaflets' hex boundary all of whose nodes carry IPC "
                   "barrier force (both touching sides count, as Abaqus's CAREA of a self-contact surface does); "
                   f"the barrier acts across gaps below dhat = {dhat:g} mm, so faces that close count without "
                   "touching, and skvalve's contact surface is the whole boundary, not the input's contact "
                   f"pairs{suffix}")
    for region, value in measures.centre_stress.items():
        leaflet = _leaflet_of(region)
        yield Row(f"Table 3 centre max principal Cauchy stress, {leaflet}, {column.label} (kPa)",
                  getattr(TABLE3_CENTRE_STRESS[leaflet], column.state), value * MPA_TO_KPA, 0.25, relative=True,
                  expected_difference=difference,
                  note=f"{donor}mean over the hexes at the leaflet centre region (10 % of the leaflet's mid-surface "
                       "area, the paper's Fig. 4d region is not given in numbers); quasi-static implicit vs "
                       f"explicit dynamics with mass scaling{suffix}")
