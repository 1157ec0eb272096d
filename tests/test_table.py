"""Reproduction-table rows classify themselves: agrees / differs for a stated reason / unexplained / regression."""

import math

import pytest

from skvalve.papers.table import Reason, Row, Source, Status, format_table


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


def test_status_of_each_kind_of_row():
    model = Reason.MODEL_DIFFERENCE
    assert Row("paper, inside", 1.0, 1.05, 0.1).status is Status.AGREES
    assert Row("paper, declared, inside", 1.0, 1.05, 0.1, expected_difference=model, note="why").status is Status.AGREES
    assert Row("paper, outside", 1.0, 2.0, 0.1).status is Status.UNEXPLAINED
    assert Row("paper, declared", 1.0, 2.0, 0.1, expected_difference=model, note="why").status is Status.DIFFERS
    assert Row("exact, outside", 1.0, 2.0, 0.1, source=Source.EXACT).status is Status.REGRESSION
    assert Row("exact, nan", 1.0, math.nan, 0.1, source=Source.EXACT).status is Status.REGRESSION
    assert [s for s in Status if s.fails_strict] == [Status.UNEXPLAINED, Status.REGRESSION]


def test_a_difference_must_be_stated_and_cannot_excuse_an_exact_reference():
    with pytest.raises(ValueError, match="note"):
        Row("q", 1.0, 2.0, 0.1, expected_difference=Reason.PAPER_DATA_MISSING)
    with pytest.raises(ValueError, match="exact"):
        Row("q", 1.0, 2.0, 0.1, source=Source.EXACT, expected_difference=Reason.MODEL_DIFFERENCE, note="x")
    with pytest.raises(ValueError, match="tolerance"):
        Row("q", 1.0, 1.0, math.nan)


def test_format_table_shows_status_and_reason():
    text = format_table([Row("good", 1.0, 1.0, 0.1), Row("bad", 1.0, 2.0, 0.1, note="why"),
                         Row("known", 1.0, 2.0, 0.1, note="model", expected_difference=Reason.MODEL_DIFFERENCE),
                         Row("exact", 1.0, 2.0, 0.1, source=Source.EXACT)], title="t")
    lines = text.splitlines()
    assert lines[0] == "t"
    assert any(line.startswith("good") and line.endswith("agrees") for line in lines)
    assert any(line.startswith("bad") and line.endswith("UNEXPLAINED") for line in lines)
    assert any(line.startswith("known") and line.endswith("differs: model difference") for line in lines)
    assert any(line.startswith("exact") and "1*" in line and line.endswith("REGRESSION") for line in lines)
    assert "    why" in lines
