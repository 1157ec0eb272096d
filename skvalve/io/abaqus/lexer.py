"""Split an Abaqus input file into keyword cards with their data lines, and read data fields strictly.

Rules followed (Abaqus Analysis User's Guide, "Input syntax rules"):

* a line starting with ``**`` is a comment; a line starting with ``*`` is a keyword line; any other
  non-blank line is data belonging to the last keyword;
* keywords and parameter names are case-insensitive (lower-cased here, inner blanks collapsed);
  a keyword line ending with a comma continues on the next line;
* ``*Include, input=FILE`` is replaced by FILE's cards (FILE relative to the including file;
  a file that includes itself, directly or not, is an error);
* a data field left blank means "default"; a trailing comma does not open a further field;
* a file whose last data line has no final newline is an error (a cut file: the number may be cut); a
  last keyword line without one is marked ``Card.unterminated`` (:func:`~skvalve.io.abaqus.read_model` warns).

Bytes: a UTF-8 byte-order mark is dropped, lines that are not UTF-8 are read as latin-1 (so a stray
byte in a comment does no harm) and carriage returns are removed.

Numbers: only ASCII decimal literals (``1``, ``-2.5``, ``.5e-3``) that are finite; ``nan``, ``inf``,
``1e999``, ``1_000`` and non-ASCII digits are rejected with file and line.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .errors import AbaqusParseError, Location

__all__ = ["DataLine", "Card", "read_cards", "split_fields", "parse_float", "parse_int", "data_values", "fast_table"]

_FLOAT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_INT = re.compile(r"[+-]?\d+", re.ASCII)
_SPACES = re.compile(r"\s+")
_NOT_FLOAT_CHARS = re.compile(r"[^0-9eE+\-.,\s]", re.ASCII)
_NOT_INT_CHARS = re.compile(r"[^0-9+\-,\s]", re.ASCII)
#: Nesting depth of ``*Include`` beyond which the input is rejected (besides the cycle check).
MAX_INCLUDE_DEPTH = 32


class DataLine(NamedTuple):
    """One data line: its text (stripped) and where it is."""

    text: str
    location: Location


@dataclass
class Card:
    """A keyword line with its parameters and the data lines that follow it.

    ``keyword`` is lower case with single blanks (``"solid section"``); ``parameters`` maps lower-case
    names to values as written (quotes removed); ``flags`` are the lower-case words without ``=``
    (``"ogden"`` in ``*Hyperelastic, OGDEN, N=3``).
    """

    keyword: str
    parameters: dict[str, str]
    flags: list[str]
    location: Location
    texts: list[str] = field(default_factory=list)
    numbers: list[int] = field(default_factory=list)
    #: the keyword line is the file's last line and has no final newline (the file may have been cut there)
    unterminated: bool = False

    @cached_property
    def data(self) -> list[DataLine]:
        """The data lines with their locations (built on first use; large blocks read ``texts``)."""
        file = self.location.file
        return [DataLine(text, Location(file, number)) for text, number in zip(self.texts, self.numbers, strict=True)]

    def error(self, message: str, location: Location | None = None) -> AbaqusParseError:
        """An :class:`AbaqusParseError` for this card (at ``location``, default the keyword line)."""
        return AbaqusParseError(message, location or self.location, self.title)

    @property
    def title(self) -> str:
        """The keyword as Abaqus users write it, e.g. ``Solid Section``."""
        return " ".join(w.capitalize() for w in self.keyword.split())

    def require(self, name: str) -> str:
        """The value of a required parameter (raises naming the card when absent or empty)."""
        value = self.parameters.get(name)
        if not value:
            raise self.error(f"missing required parameter {name.upper()}=")
        return value


def _split_keyword_fields(text: str, location: Location) -> list[str]:
    """Comma-separated fields of a keyword line, honouring double quotes."""
    if '"' not in text:
        return [f.strip() for f in text.split(",")]
    fields, current, quoted = [], [], False
    for char in text:
        if char == '"':
            quoted = not quoted
            current.append(char)
        elif char == "," and not quoted:
            fields.append("".join(current))
            current = []
        else:
            current.append(char)
    if quoted:
        raise AbaqusParseError("unbalanced double quote in keyword line", location)
    fields.append("".join(current))
    return [f.strip() for f in fields]


def _unquote(value: str) -> str:
    return value[1:-1] if len(value) >= 2 and value[0] == value[-1] == '"' else value


def _parse_keyword_line(text: str, location: Location) -> Card:
    fields = _split_keyword_fields(text[1:], location)
    keyword = _SPACES.sub(" ", fields[0]).lower()
    if not keyword or not keyword[0].isalpha():
        raise AbaqusParseError(f"not a keyword: {text[:40]!r}", location)
    parameters: dict[str, str] = {}
    flags: list[str] = []
    for item in fields[1:]:
        if "=" in item:
            name, value = item.split("=", 1)
            name = _SPACES.sub(" ", name.strip()).lower()
            if not name:
                raise AbaqusParseError(f"parameter without a name: {item!r}", location, keyword)
            parameters[name] = _unquote(value.strip())
        elif item:
            flags.append(_SPACES.sub(" ", item).lower())
    return Card(keyword, parameters, flags, location)


def _decode_lines(raw: bytes) -> list[str]:
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    try:
        text = raw.decode("utf-8")
        return text.split("\n")
    except UnicodeDecodeError:
        pass
    lines = []
    for chunk in raw.split(b"\n"):
        try:
            lines.append(chunk.decode("utf-8"))
        except UnicodeDecodeError:
            lines.append(chunk.decode("latin-1"))
    return lines


def read_cards(path: Path, _stack: tuple[Path, ...] = ()) -> list[Card]:
    """All keyword cards of ``path`` in order, with ``*Include`` files expanded in place."""
    path = Path(path)
    resolved = path.resolve()
    if resolved in _stack:
        chain = " -> ".join(str(p) for p in (*_stack, resolved))
        raise AbaqusParseError(f"*Include cycle: {chain}")
    if len(_stack) >= MAX_INCLUDE_DEPTH:
        raise AbaqusParseError(f"*Include nested deeper than {MAX_INCLUDE_DEPTH} files at {path}")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise AbaqusParseError(f"cannot read {path}: {exc.strerror or exc}") from None
    if b"\x00" in raw:
        line = raw[: raw.index(b"\x00")].count(b"\n") + 1
        raise AbaqusParseError("NUL byte: not a text file", Location(path, line))
    lines = _decode_lines(raw)
    unterminated = not raw.endswith(b"\n") and bool(lines[-1].strip())
    cards: list[Card] = []
    current: Card | None = None
    continued: tuple[str, Location] | None = None
    last = len(lines)
    for number, line in enumerate(lines, start=1):
        text = line.strip()
        if continued is not None:
            if not text or text.startswith("*"):
                raise AbaqusParseError("keyword line ends with a comma but is not continued", continued[1])
            text, location = continued[0] + text, continued[1]
            continued = None
        elif not text or text.startswith("**"):
            continue
        elif text[0] != "*":
            if current is None:
                raise AbaqusParseError(f"data line before any keyword: {text[:40]!r}", Location(path, number))
            if unterminated and number == last:
                raise current.error("the file ends inside this data line (no final newline): truncated?",
                                    Location(path, number))
            current.texts.append(text)
            current.numbers.append(number)
            continue
        else:
            location = Location(path, number)
        if text.endswith(","):
            continued = (text, location)
            continue
        current = _parse_keyword_line(text, location)
        current.unterminated = unterminated and number == last
        if current.keyword == "include":
            target = current.require("input")
            if current.texts:
                raise current.error("*Include takes no data lines")
            cards.extend(read_cards(path.parent / target, (*_stack, resolved)))
            current = None
        else:
            cards.append(current)
    if continued is not None:
        raise AbaqusParseError("keyword line ends with a comma at the end of the file", continued[1])
    return cards


def split_fields(text: str) -> list[str]:
    """Stripped comma-separated fields of a data line; one trailing empty field is dropped."""
    fields = [f.strip() for f in text.split(",")]
    if len(fields) > 1 and fields[-1] == "":
        fields.pop()
    return fields


def parse_float(token: str, card: Card, location: Location, what: str = "value") -> float:
    """A strictly read, finite ASCII decimal number."""
    if not _FLOAT.fullmatch(token):
        raise card.error(f"{what} is not a number: {token[:40]!r}", location)
    value = float(token)
    if not math.isfinite(value):
        raise card.error(f"{what} is out of range: {token[:40]!r}", location)
    return value


#: Largest magnitude accepted for an integer field (labels are at most 9 digits in Abaqus).
MAX_INT = 2**53


def parse_int(token: str, card: Card, location: Location, what: str = "integer") -> int:
    """A strictly read ASCII integer of magnitude at most :data:`MAX_INT`."""
    if not _INT.fullmatch(token):
        raise card.error(f"{what} is not an integer: {token[:40]!r}", location)
    value = int(token)
    if abs(value) > MAX_INT:
        raise card.error(f"{what} is out of range: {token[:40]!r}", location)
    return value


def data_values(card: Card, blank: float | None = 0.0) -> list[float]:
    """All fields of all data lines as numbers, in order; a blank field is ``blank`` (error if None)."""
    values: list[float] = []
    for line in card.data:
        for token in split_fields(line.text):
            if token == "":
                if blank is None:
                    raise card.error("blank field where a value is required", line.location)
                values.append(blank)
            else:
                values.append(parse_float(token, card, line.location))
    return values


def fast_table(card: Card, columns: int, integer: bool) -> np.ndarray | None:
    """The data of ``card`` as an (n, columns) array when every line is a plain row of ``columns`` numbers.

    A quick path for large node and element blocks: None whenever anything is irregular (blank or
    missing fields, a continuation, a character outside ASCII digits, signs, ``.``, ``e``, or a value that
    is not finite), and the caller then reads line by line with exact error messages.
    """
    texts = card.texts
    if not texts:
        return None
    pattern = _NOT_INT_CHARS if integer else _NOT_FLOAT_CHARS
    if pattern.search("\n".join(texts)):
        return None
    rows = [text.split(",") for text in texts]
    for row in rows:
        if len(row) == columns + 1 and not row[-1].strip():
            row.pop()
        if len(row) != columns:
            return None
    try:
        table = np.array(rows, dtype=np.int64 if integer else float)
    except (ValueError, OverflowError):
        return None
    if integer and np.any(np.abs(table) > MAX_INT):
        return None
    if not integer and not np.all(np.isfinite(table)):
        return None
    return table
