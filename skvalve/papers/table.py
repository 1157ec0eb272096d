"""Rows of a reproduction table: (quantity, paper value, skvalve value, tolerance, ok)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Row:
    """One reproduced quantity.

    ``tolerance`` is absolute unless ``relative`` is true. ``ok`` is computed, never set:
    a row passes when ``|skvalve - paper| <= tolerance`` (times ``|paper|`` if relative).
    """

    quantity: str
    paper: float
    skvalve: float
    tolerance: float
    relative: bool = False
    note: str = ""
    ok: bool = field(init=False)

    def __post_init__(self) -> None:
        scale = abs(self.paper) if self.relative else 1.0
        diff = abs(self.skvalve - self.paper)
        object.__setattr__(self, "ok", bool(math.isfinite(self.skvalve) and diff <= self.tolerance * scale))


def format_table(rows: list[Row], title: str = "") -> str:
    """Plain-text table of rows."""
    head = f"{'quantity':<48} {'paper':>12} {'skvalve':>12} {'tolerance':>12}  ok"
    lines = [title, head, "-" * len(head)] if title else [head, "-" * len(head)]
    for r in rows:
        tol = f"{r.tolerance:.3g}{' rel' if r.relative else ''}"
        lines.append(f"{r.quantity:<48} {r.paper:>12.5g} {r.skvalve:>12.5g} {tol:>12}  {'yes' if r.ok else 'NO'}")
        if r.note:
            lines.append(f"    {r.note}")
    return "\n".join(lines)


def print_table(rows: list[Row], title: str = "") -> None:
    print(format_table(rows, title))
