"""Command-line interface: arguments, --out checks, streaming rows, --strict, Ctrl-C, papers not available yet.

The commands' numbers are tested elsewhere; here stand-in ``reproduce`` modules yield chosen items.
"""

import sys
import types
from pathlib import Path

import pytest

import skvalve
from skvalve.cli import build_parser, main
from skvalve.papers.table import InputError, Reason, Row, Source, Stage, Written

FAKE = "skvalve.papers.mathur2022.reproduce"


def test_unknown_paper_is_rejected_by_argparse():
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reproduce", "nosuchpaper"])


def test_missing_command_is_an_error():
    with pytest.raises(SystemExit):
        main([])


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.strip() == f"skvalve {skvalve.__version__}"


def _fake_paper(monkeypatch, items):
    """Install a stand-in ``skvalve.papers.mathur2022.reproduce`` whose reproduce() yields ``items``
    (an exception instance among them is raised there)."""
    module = types.ModuleType(FAKE)
    calls = []

    def reproduce(out, full):
        calls.append((out, full))
        for item in items:
            if isinstance(item, BaseException):
                raise item
            yield item

    module.reproduce = reproduce
    monkeypatch.setitem(sys.modules, FAKE, module)
    return calls


def test_rows_and_stages_are_printed_as_they_come(monkeypatch, tmp_path, capsys):
    calls = _fake_paper(monkeypatch, [Stage("step one"), Row("a", 1.0, 1.0, 0.1), Written(tmp_path / "f.png")])
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--full"]) == 0
    assert calls == [(tmp_path, True)]
    captured = capsys.readouterr()
    assert "step one" in captured.err and "f.png" in captured.err
    assert any(line.startswith("a ") and line.endswith("agrees") for line in captured.out.splitlines())
    assert "1 rows: 1 agree within tolerance" in captured.out


def test_strict_fails_only_on_regressions_and_unexplained_rows(monkeypatch, tmp_path, capsys):
    declared = Row("known", 1.0, 2.0, 0.1, note="model", expected_difference=Reason.MODEL_DIFFERENCE)
    _fake_paper(monkeypatch, [Row("a", 1.0, 1.0, 0.1), declared])
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--strict"]) == 0
    for bad in (Row("b", 2.0, 3.0, 0.1), Row("c", 0.0, 1.0, 0.1, source=Source.EXACT)):
        _fake_paper(monkeypatch, [declared, bad])
        assert main(["reproduce", "mathur2022", "--out", str(tmp_path)]) == 0  # a finding, not a crash
        assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--strict"]) == 1
        assert bad.quantity in capsys.readouterr().err


@pytest.mark.parametrize("kind", ["file", "below a file"])
def test_bad_out_is_refused_before_computing(monkeypatch, tmp_path, capsys, kind):
    calls = _fake_paper(monkeypatch, [Row("a", 1.0, 1.0, 0.1)])
    blocker = tmp_path / "taken"
    blocker.write_text("")
    out = blocker if kind == "file" else blocker / "figures"
    assert main(["reproduce", "mathur2022", "--out", str(out)]) == 2
    assert calls == []
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(out) in err and "Traceback" not in err
    assert main(["materials", "--out", str(out)]) == 2


def test_interrupt_reports_what_was_finished(monkeypatch, tmp_path, capsys):
    _fake_paper(monkeypatch, [Row("a", 1.0, 1.0, 0.1), Written(tmp_path / "one.png"), KeyboardInterrupt()])
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "1 rows" in err and "one.png" in err


@pytest.mark.parametrize("paper", ["thomas2019", "mathur2022"])
def test_a_paper_not_available_yet_says_what_it_will_compute(monkeypatch, tmp_path, capsys, paper):
    monkeypatch.setitem(sys.modules, f"skvalve.papers.{paper}.reproduce", None)  # the module does not exist
    assert main(["reproduce", paper, "--out", str(tmp_path / "out")]) == 2
    assert not (tmp_path / "out").exists()
    err = capsys.readouterr().err
    assert "not available yet" in err and "will compute" in err
    assert ("Table 3" in err) if paper == "mathur2022" else ("RVE" in err)


@pytest.mark.parametrize("layout", ["file", "folder", "folder/Diseased"])
def test_skvalve_trivalve_accepts_the_file_or_its_folder(monkeypatch, tmp_path, layout):
    from skvalve.io.abaqus import trivalve_input

    folder = tmp_path / "Diseased" if layout == "folder/Diseased" else tmp_path
    folder.mkdir(exist_ok=True)
    deck = folder / "Diseased_QuasiStatic.inp"
    deck.write_text("** stand-in\n")
    monkeypatch.setenv("SKVALVE_TRIVALVE", str(deck if layout == "file" else tmp_path))
    assert trivalve_input() == deck
    monkeypatch.setenv("SKVALVE_TRIVALVE", str(tmp_path / "empty"))
    (tmp_path / "empty").mkdir()
    assert trivalve_input() is None  # a folder without the input is not silently replaced by another copy


def test_interrupt_in_materials_exits_130(monkeypatch, tmp_path, capsys):
    import skvalve.papers.catalogue_figures as catalogue_figures

    def interrupt(entries, out):
        raise KeyboardInterrupt

    monkeypatch.setattr(catalogue_figures, "write_catalogue_figures", interrupt)
    assert main(["materials", "--out", str(tmp_path)]) == 130
    assert "interrupted" in capsys.readouterr().err


def test_missing_input_data_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys):
    _fake_paper(monkeypatch, [Stage("reading"), FileNotFoundError("input not found: set $SKVALVE_TRIVALVE")])
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == "skvalve: reproduce mathur2022: input not found: set $SKVALVE_TRIVALVE"


def test_state_goes_only_to_a_reproduce_that_takes_it(monkeypatch, tmp_path, capsys):
    _fake_paper(monkeypatch, [Row("a", 1.0, 1.0, 0.1)])  # reproduce(out, full): no state
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--state", "kept.npz"]) == 2
    assert "does not take --state" in capsys.readouterr().err
    module = types.ModuleType(FAKE)
    seen = []

    def reproduce(out, full, state=None):
        seen.append(state)
        raise InputError(f"kept state {state}: no u in it")
        yield  # a generator, as the papers' are

    module.reproduce = reproduce
    monkeypatch.setitem(sys.modules, FAKE, module)
    assert main(["reproduce", "mathur2022", "--out", str(tmp_path), "--state", "kept.npz"]) == 2
    assert seen == [Path("kept.npz")]
    assert capsys.readouterr().err.strip().splitlines()[-1] == \
        "skvalve: reproduce mathur2022: kept state kept.npz: no u in it"
