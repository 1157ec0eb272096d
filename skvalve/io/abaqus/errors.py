"""Where an Abaqus input line came from, and the one exception the reader raises."""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

__all__ = ["Location", "AbaqusParseError"]


class Location(NamedTuple):
    """A line of an input file (1-based), for messages and for tracing data back to the file."""

    file: Path
    line: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


class AbaqusParseError(ValueError):
    """Malformed or unsupported Abaqus input; the message names file, line and keyword.

    A subclass of ``ValueError`` so that callers of the former material-only reader keep working.
    """

    def __init__(self, message: str, location: Location | None = None, keyword: str | None = None):
        self.location = location
        self.keyword = keyword
        where = f"{location}: " if location is not None else ""
        what = f"*{keyword}: " if keyword else ""
        super().__init__(f"{where}{what}{message}")
