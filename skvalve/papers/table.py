"""Rows of a reproduction table and the other items a paper's ``reproduce`` yields.

A :class:`Row` compares one quantity with its reference and classifies itself (:attr:`Row.status`):

* ``agrees`` — within tolerance;
* ``differs`` — outside tolerance for a reason stated in advance (:class:`Reason`: the paper's data are
  missing, or skvalve's model differs from the paper's), explained in the row's note;
* ``unexplained`` — a paper value missed without a stated reason;
* ``regression`` — an exact or independent reference (closed form, second formulation) missed: skvalve
  is wrong, whatever the paper says.

``skvalve reproduce --strict`` fails on ``unexplained`` and ``regression`` rows only.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["InputError", "Source", "Reason", "Status", "Row", "Stage", "Written", "format_header", "format_row",
           "format_table"]


class InputError(ValueError):
    """A file given to a paper's ``reproduce`` that it cannot use (the message names the file and what is wrong);
    ``skvalve reproduce`` prints it and exits 2."""


class Source(enum.Enum):
    """What the reference column holds."""

    PAPER = "paper"  #: a value printed in the paper
    EXACT = "exact"  #: an exact or independent value (closed form, a second formulation): a miss is a bug


class Reason(enum.Enum):
    """Why a paper value is expected not to be met."""

    PAPER_DATA_MISSING = "paper data missing"  #: the paper does not give what its value was computed from
    MODEL_DIFFERENCE = "model difference"  #: skvalve's model or loading is not the paper's (note says how)


class Status(enum.Enum):
    AGREES = "agrees"
    DIFFERS = "differs"
    UNEXPLAINED = "UNEXPLAINED"
    REGRESSION = "REGRESSION"

    @property
    def fails_strict(self) -> bool:
        """True for the statuses ``--strict`` turns into a non-zero exit code."""
        return self in (Status.UNEXPLAINED, Status.REGRESSION)


@dataclass(frozen=True)
class Row:
    """One reproduced quantity.

    Parameters
    ----------
    quantity : str
        What is compared (with the paper's table/figure/section).
    paper : float
        The reference value: the paper's, or the exact one when ``source`` is :attr:`Source.EXACT`.
    skvalve : float
        skvalve's value.
    tolerance : float
        Absolute, or relative to ``|paper|`` when ``relative``.
    relative : bool
    note : str
        How the value was obtained and, for ``expected_difference``, why it differs.
    source : Source
        :attr:`Source.PAPER` (default) or :attr:`Source.EXACT`.
    expected_difference : Reason or None
        Declared in advance for a paper row that is known to differ; needs a ``note``.

    ``ok`` is computed, never set: ``|skvalve - paper| <= tolerance`` (times ``|paper|`` if relative), and
    ``skvalve`` finite.
    """

    quantity: str
    paper: float
    skvalve: float
    tolerance: float
    relative: bool = False
    note: str = ""
    source: Source = Source.PAPER
    expected_difference: Reason | None = None
    ok: bool = field(init=False)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tolerance) and self.tolerance >= 0.0):
            raise ValueError(f"row {self.quantity!r}: tolerance must be finite and >= 0; got {self.tolerance}")
        if self.expected_difference is not None:
            if self.source is Source.EXACT:
                raise ValueError(f"row {self.quantity!r}: an exact reference cannot have an expected difference")
            if not self.note:
                raise ValueError(f"row {self.quantity!r}: an expected difference needs a note that states it")
        scale = abs(self.paper) if self.relative else 1.0
        diff = abs(self.skvalve - self.paper)
        object.__setattr__(self, "ok", bool(math.isfinite(self.skvalve) and diff <= self.tolerance * scale))

    @property
    def status(self) -> Status:
        """Agrees / differs for the stated reason / unexplained disagreement / regression."""
        if self.ok:
            return Status.AGREES
        if self.source is Source.EXACT:
            return Status.REGRESSION
        return Status.UNEXPLAINED if self.expected_difference is None else Status.DIFFERS

    @property
    def status_text(self) -> str:
        if self.status is Status.DIFFERS:
            return f"differs: {self.expected_difference.value}"
        return self.status.value


@dataclass(frozen=True)
class Stage:
    """A line announcing the next (long) computation of a ``reproduce`` run."""

    text: str


@dataclass(frozen=True)
class Written:
    """A file a ``reproduce`` run has finished writing (atomically)."""

    path: Path


_WIDTHS = (60, 11, 11, 11)


def format_header() -> str:
    """Column header (two lines: names and a rule)."""
    q, p, s, t = _WIDTHS
    head = f"{'quantity':<{q}} {'reference':>{p}} {'skvalve':>{s}} {'tolerance':>{t}}  status"
    return head + "\n" + "-" * (len(head) + 20)


def format_row(row: Row) -> str:
    """One row (and its note, indented, on the next line)."""
    q, p, s, t = _WIDTHS
    tol = f"{row.tolerance:.3g}{' rel' if row.relative else ''}"
    ref = f"{row.paper:.5g}" + ("*" if row.source is Source.EXACT else "")
    line = f"{row.quantity:<{q}} {ref:>{p}} {row.skvalve:>{s}.5g} {tol:>{t}}  {row.status_text}"
    return line + (f"\n    {row.note}" if row.note else "")


def format_table(rows: list[Row], title: str = "") -> str:
    """Plain-text table of rows; ``*`` marks an exact (not a paper) reference."""
    lines = ([title] if title else []) + [format_header()] + [format_row(r) for r in rows]
    return "\n".join(lines)
