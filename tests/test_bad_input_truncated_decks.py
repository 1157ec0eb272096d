"""A deck cut at any byte offset is an error naming its line, or the very model of the whole deck (issue 35 item 4).

Before the fix, 26 of 512 cuts of a valid deck were read as a silently shorter model: a last data line cut
mid-number or a data block cut before its last line (the element's second line, an instance's rotation
line), or an input ended by the end of the file where a keyword still had to be closed or continued.
"""

from __future__ import annotations

import dataclasses
import logging
import re
from pathlib import Path

import numpy as np
import pytest
from test_io_abaqus_model import DECK

from skvalve.io.abaqus import AbaqusParseError, read_model

LINE = re.compile(r"\.inp:\d+")


def _canonical(value):
    """Comparable plain data: dataclasses field by field (locations dropped), arrays as lists."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (type(value).__name__,) + tuple((f.name, _canonical(getattr(value, f.name)))
                                               for f in dataclasses.fields(value) if f.name != "location")
    if isinstance(value, np.ndarray):
        return ("array", value.dtype.kind, value.shape, value.tolist())
    if isinstance(value, dict):
        return tuple(sorted((str(k), _canonical(v)) for k, v in value.items()))
    if isinstance(value, list | tuple):
        return tuple(_canonical(v) for v in value)
    if isinstance(value, Path):
        return "path"
    return value


def _fingerprint(model) -> tuple:
    fields = {name: getattr(model, name) for name in vars(model) if not name.startswith("_")}
    fields.pop("path", None)
    return _canonical(fields)


@pytest.fixture(scope="module")
def cuts(tmp_path_factory):
    """(offset, outcome) for every cut of the deck: "error" (with a line), "identical", "warned" (a reader warning
    with its line that the whole deck does not give) or what else was read."""
    folder = tmp_path_factory.mktemp("cuts")
    data = DECK.encode()
    whole = folder / "whole.inp"
    whole.write_bytes(data)
    logger = logging.getLogger("skvalve.io.abaqus.reader")
    level = logger.level
    logger.setLevel(logging.ERROR)
    try:
        full = read_model(whole)
        reference, warned = _fingerprint(full), len(full.warnings)
        outcomes = []
        path = folder / "cut.inp"
        for offset in range(len(data) + 1):
            path.write_bytes(data[:offset])
            try:
                model = read_model(path)
            except AbaqusParseError as error:
                outcomes.append((offset, "error" if LINE.search(str(error)) else f"error without a line: {error}"))
                continue
            if _fingerprint(model) == reference:
                outcomes.append((offset, "identical"))
            elif len(model.warnings) > warned and all(w.location.line > 0 for w in model.warnings):
                outcomes.append((offset, "warned"))
            else:
                outcomes.append((offset, "shorter model"))
    finally:
        logger.setLevel(level)
    return outcomes


def test_every_cut_raises_with_its_line_or_reads_the_whole_model(cuts):
    bad = [(offset, outcome, DECK.encode()[:offset].decode().splitlines()[-1:])
           for offset, outcome in cuts if outcome not in ("error", "identical", "warned")]
    assert not bad, f"{len(bad)} of {len(cuts)} cuts read silently or without a line: {bad[:8]}"


def test_only_cuts_in_the_last_line_read_the_whole_model(cuts):
    """A cut that leaves the model whole may only drop the final newline or blank/comment bytes after it."""
    last = DECK.rstrip("\n").rfind("\n") + 1
    identical = [offset for offset, outcome in cuts if outcome == "identical"]
    assert identical and min(identical) >= last + len("*End Step")
