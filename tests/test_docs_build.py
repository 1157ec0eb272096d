"""The documentation site builds with warnings as errors, from the committed notebook outputs (no execution).

Runs in the default test run (marker ``docs``); skipped, with the reason, only when the ``docs`` extra
(sphinx, myst-nb, furo) is not installed. The build happens in a temporary copy of ``docs/`` so that nothing
(autosummary stubs, build output) is written into the working tree.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

for _module in ("sphinx", "myst_nb", "furo"):
    pytest.importorskip(_module, reason=f"{_module} is not installed: the docs build needs the 'docs' extra")

DOCS = Path(__file__).resolve().parents[1] / "docs"
BUILD_SECONDS = 300  # a clean build takes well under a minute on two cores


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("docs")
    source, html = tmp / "source", tmp / "html"
    # symlinks=False: docs/chapters and docs/exercises (links to the repository folders) are copied as folders
    shutil.copytree(DOCS, source, symlinks=False, ignore=shutil.ignore_patterns("_build", "_autosummary", "*.pyc"))
    env = dict(os.environ, PYDEVD_DISABLE_FILE_VALIDATION="1")
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "-d", str(tmp / "doctrees"),
               str(source), str(html)]
    run = subprocess.run(command, capture_output=True, text=True, timeout=BUILD_SECONDS, env=env)
    assert run.returncode == 0, f"sphinx-build failed (warnings are errors):\n{run.stderr[-6000:]}"
    return html


@pytest.mark.docs
def test_pages_exist(site: Path):
    for page in ("index.html", "api.html", "reproduce.html", "buchanan2014.html", "chapters/thomas2019.html",
                 "chapters/buchanan2014.html", "exercises/ogden_truss.html", "exercises/ogden_truss_solution.html"):
        assert (site / page).is_file(), page


@pytest.mark.docs
def test_notebook_figures_come_from_the_committed_outputs(site: Path):
    html = (site / "chapters" / "thomas2019.html").read_text(encoding="utf-8")
    assert len(re.findall(r"<img[^>]+\.png", html)) >= 4  # the chapter's figures, as stored in the notebook
    assert "Newton iterations" in html  # a stored text output


@pytest.mark.docs
def test_api_reference_renders_docstring_maths(site: Path):
    pages = list((site / "_autosummary").glob("skvalve.*.html"))
    assert any(p.name == "skvalve.fem.amplitudes.html" for p in pages), "the API reference lacks skvalve.fem"
    amplitudes = (site / "_autosummary" / "skvalve.fem.amplitudes.html").read_text(encoding="utf-8")
    assert "SmoothStep" in amplitudes and r"\xi^3(10 - 15\xi + 6\xi^2)" in amplitudes.replace("\\,", "")
    assert "mathjax" in amplitudes.lower()
