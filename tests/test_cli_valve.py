"""``skvalve valve info FILE``: summary text and picture, clear errors for a missing or bad file."""

from pathlib import Path

import pytest

from skvalve.cli import main

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "texas_trivalve" / "Diseased_QuasiStatic.inp"


def test_missing_file_is_a_usage_error(tmp_path, capsys):
    assert main(["valve", "info", str(tmp_path / "nope.inp"), "--out", str(tmp_path)]) == 2
    assert "is not a file" in capsys.readouterr().err


def test_bad_deck_names_file_and_line(tmp_path, capsys):
    deck = tmp_path / "bad.inp"
    deck.write_text("*Node\n1, 0., 0., 0.\n2, 1., x, 0.\n")
    assert main(["valve", "info", str(deck), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "bad.inp" in err and "3" in err


@pytest.mark.skipif(not DATA.is_file(), reason="Texas TriValve 1.0 input not present (../shared/data)")
def test_shipped_diseased_valve(tmp_path, capsys):
    assert main(["valve", "info", str(DATA), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "C3D8R" in out and "T3D2" in out
    assert (tmp_path / "summary.txt").read_text().startswith("Model Diseased_QuasiStatic.inp")
    assert (tmp_path / "undeformed.png").stat().st_size > 20_000
