"""The reproduction-table row decides pass/fail itself; check its arithmetic."""

import math

import pytest

from skvalve.papers.table import Row, format_table


@pytest.mark.parametrize(
    ("paper", "value", "tol", "relative", "ok"),
    [
        (0.35, 0.36, 0.02, False, True),
        (0.35, 0.38, 0.02, False, False),
        (100.0, 104.0, 0.05, True, True),
        (100.0, 106.0, 0.05, True, False),
        (-2.0, -2.09, 0.05, True, True),
        (1.0, math.nan, 1.0, False, False),
    ],
)
def test_row_ok_follows_tolerance(paper, value, tol, relative, ok):
    assert Row("q", paper, value, tol, relative=relative).ok is ok


def test_format_table_marks_failures():
    text = format_table([Row("good", 1.0, 1.0, 0.1), Row("bad", 1.0, 2.0, 0.1, note="why")], title="t")
    lines = text.splitlines()
    assert lines[0] == "t"
    assert any(line.startswith("good") and line.endswith("yes") for line in lines)
    assert any(line.startswith("bad") and line.endswith("NO") for line in lines)
    assert "    why" in lines
