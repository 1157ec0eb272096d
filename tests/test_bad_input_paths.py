"""An explicitly set ``$SKVALVE_TRIVALVE`` that does not exist is an error naming it (issue 35 item 1).

Before the fix a mistyped path fell back silently to ``../shared/data/...`` and the run used another file.
"""

from __future__ import annotations

import pytest

from skvalve.io.abaqus import trivalve_input


@pytest.mark.parametrize("name", ["nonexistent", "Diseased_QuasiStatic.inpx", "texas_trivalve/typo/"])
def test_a_missing_explicit_path_is_an_error_naming_it(monkeypatch, tmp_path, name):
    missing = tmp_path / name
    monkeypatch.setenv("SKVALVE_TRIVALVE", str(missing))
    with pytest.raises(FileNotFoundError, match="SKVALVE_TRIVALVE") as info:
        trivalve_input()
    assert str(missing) in str(info.value)


def test_an_unset_or_empty_variable_still_searches_the_shared_data(monkeypatch):
    monkeypatch.delenv("SKVALVE_TRIVALVE", raising=False)
    unset = trivalve_input()
    monkeypatch.setenv("SKVALVE_TRIVALVE", "")
    assert trivalve_input() == unset  # found under ../shared/data, or None where the data are not there


def test_an_existing_file_or_folder_is_used(monkeypatch, tmp_path):
    deck = tmp_path / "Diseased_QuasiStatic.inp"
    deck.write_text("** stand-in\n")
    monkeypatch.setenv("SKVALVE_TRIVALVE", str(deck))
    assert trivalve_input() == deck
    monkeypatch.setenv("SKVALVE_TRIVALVE", str(tmp_path))
    assert trivalve_input() == deck
