"""Command-line interface: argument handling (the commands' numbers are tested elsewhere)."""

import pytest

from skvalve.cli import build_parser, main


def test_unknown_paper_is_rejected_by_argparse():
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reproduce", "nosuchpaper"])


def test_missing_command_is_an_error():
    with pytest.raises(SystemExit):
        main([])


def _fake_paper(monkeypatch, rows):
    """Install a stand-in ``skvalve.papers.mathur2022`` whose reproduce() returns ``rows``."""
    import sys
    import types

    module = types.ModuleType("skvalve.papers.mathur2022")
    calls = []

    def reproduce(out, full):
        calls.append((out, full))
        return rows

    module.reproduce = reproduce
    monkeypatch.setitem(sys.modules, "skvalve.papers.mathur2022", module)
    return calls


def test_reproduce_exit_code_follows_the_rows(monkeypatch, tmp_path, capsys):
    from skvalve.papers.table import Row

    calls = _fake_paper(monkeypatch, [Row("a", 1.0, 1.0, 0.1), Row("b", 2.0, 2.05, 0.1)])
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--full"]) == 0
    assert calls == [(tmp_path, True)]
    assert "skvalve reproduce mathur2022" in capsys.readouterr().out
    _fake_paper(monkeypatch, [Row("a", 1.0, 1.0, 0.1), Row("b", 2.0, 3.0, 0.1)])
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path)]) == 0
    assert "1 of 2 quantities within tolerance" in capsys.readouterr().out
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--strict"]) == 1


def test_reproduce_of_a_paper_without_module_says_so(monkeypatch, capsys):
    import importlib

    real_import = importlib.import_module

    def missing(name, *args):
        if name == "skvalve.papers.mathur2022":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return real_import(name, *args)

    monkeypatch.setattr(importlib, "import_module", missing)
    assert main(["reproduce", "mathur2022"]) == 2
    assert "not reproduced yet" in capsys.readouterr().err
