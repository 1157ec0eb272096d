"""Chapters and exercises: the jupytext percent script (source) and the committed notebook (with outputs) agree.

Edit ``chapters/<name>.py`` or ``exercises/<name>.py``, then ``jupytext --sync <name>.py`` and execute the
notebook (``jupyter nbconvert --to notebook --execute --inplace <name>.ipynb``) so its outputs match the code.
"""

from __future__ import annotations

import base64
import struct
from pathlib import Path

import pytest

jupytext = pytest.importorskip("jupytext", reason="jupytext (extra 'dev') is needed to read the percent scripts")

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("chapters", "exercises")
SCRIPTS = sorted(p for folder in FOLDERS for p in (ROOT / folder).glob("*.py") if not p.name.startswith("_"))
NOTEBOOKS = sorted(p for folder in FOLDERS for p in (ROOT / folder).glob("*.ipynb"))


def _cells(path: Path) -> list[tuple[str, str]]:
    notebook = jupytext.read(path)
    return [(cell.cell_type, cell.source.strip()) for cell in notebook.cells]


def test_every_notebook_has_its_script_and_back():
    assert SCRIPTS, "no percent scripts found in chapters/ or exercises/"
    assert {p.with_suffix("") for p in SCRIPTS} == {p.with_suffix("") for p in NOTEBOOKS}


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_script_and_notebook_have_the_same_cells(script: Path):
    notebook = script.with_suffix(".ipynb")
    assert notebook.exists(), f"{notebook.relative_to(ROOT)} is missing: run jupytext --sync {script.name}"
    from_script, from_notebook = _cells(script), _cells(notebook)
    for index, (a, b) in enumerate(zip(from_script, from_notebook, strict=False)):
        assert a == b, (f"{script.relative_to(ROOT)} and its .ipynb differ at cell {index}: "
                        f"run jupytext --sync {script.name} and re-execute the notebook")
    assert len(from_script) == len(from_notebook), f"{script.name}: the cell counts differ"


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_notebook_is_executed_top_to_bottom(notebook: Path):
    """The committed outputs come from one run of the whole notebook (execution counts 1, 2, 3, ...)."""
    cells = jupytext.read(notebook).cells
    counts = [cell.execution_count for cell in cells if cell.cell_type == "code"]
    assert counts == list(range(1, len(counts) + 1)), (
        f"{notebook.relative_to(ROOT)} was not executed top to bottom in one run (execution counts {counts})")
    errors = [o for cell in cells if cell.cell_type == "code" for o in cell.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors, f"{notebook.relative_to(ROOT)} holds an error output"
    stderr = [o for cell in cells if cell.cell_type == "code" for o in cell.get("outputs", [])
              if o.get("output_type") == "stream" and o.get("name") == "stderr"]
    assert not stderr, (f"{notebook.relative_to(ROOT)} holds warnings (stderr), e.g. {stderr[0]['text'][:200]!r}: fix "
                        "their cause (they also carry machine paths into the repository)")


def _png_width(data: str) -> int:
    """Width in pixels from the IHDR chunk of a base64-encoded PNG."""
    header = base64.b64decode(data[:64])
    assert header[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">I", header[16:20])[0]


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_figures_are_readable(notebook: Path):
    """Figures drawn at >= 150 dpi (issue 12 item 7): every stored PNG is at least 600 pixels wide."""
    outputs = [output for cell in jupytext.read(notebook).cells if cell.cell_type == "code"
               for output in cell.get("outputs", [])]
    widths = [_png_width(output["data"]["image/png"]) for output in outputs if "image/png" in output.get("data", {})]
    assert all(width >= 600 for width in widths), f"{notebook.name}: PNG widths {widths} (draw at figure.dpi >= 150)"
