"""Every code block of README.md runs (issue 8 item 5).

Python blocks are executed in order in one namespace. Shell blocks are split into commands:
``skvalve ...`` commands run for real (in a temporary folder); the environment set-up commands
(``python3 -m venv``, activating it, ``pip install``) are checked instead of run (the test already
runs inside such an environment: the extras they name must exist in pyproject.toml); ``pytest``
must be the command CI runs (``.ci/run``), which is how it is exercised.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import tomllib

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"^```(\w+)\n(.*?)^```", README, flags=re.S | re.M)
PYTHON = [code for lang, code in BLOCKS if lang == "python"]
SHELL = [code for lang, code in BLOCKS if lang in ("bash", "sh", "shell", "console")]


def _commands(block: str) -> list[str]:
    lines = [line.split("#")[0].strip() for line in block.replace("\\\n", " ").splitlines()]
    return [part.strip() for line in lines if line for part in re.split(r"&&|;", line) if part.strip()]


def test_readme_has_code():
    assert PYTHON and SHELL


def test_python_blocks_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for code in PYTHON:
        exec(compile(code, "README.md", "exec"), namespace)  # noqa: S102 - the README is ours


def test_setup_commands_name_real_extras():
    extras = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"])
    seen = 0
    for block in SHELL:
        for command in _commands(block):
            for spec in re.findall(r'"\.\[([\w,-]+)\]"|\.\[([\w,-]+)\]', command):
                for name in filter(None, ",".join(spec).split(",")):
                    assert name in extras, f"README installs the unknown extra [{name}]"
                    seen += 1
    assert seen


def test_pytest_command_is_what_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text()
    commands = [c for block in SHELL for c in _commands(block) if c.split()[0] == "pytest"]
    assert commands, "the README should say how to run the tests"
    for command in commands:
        assert re.search(rf"^\s*{re.escape(command)}\b", ci, flags=re.M), f"{command!r} is not what .ci/run runs"


SKVALVE = [c for block in SHELL for c in _commands(block) if c.split()[0] == "skvalve"]


@pytest.mark.parametrize("command", SKVALVE)
def test_skvalve_commands_run(command, tmp_path):
    argv = shlex.split(command)
    if "--out" not in argv and argv[1] in ("reproduce", "materials"):
        argv += ["--out", str(tmp_path / "out")]
    done = subprocess.run([sys.executable, "-m", "skvalve.cli", *argv[1:]], cwd=tmp_path, capture_output=True,
                          text=True, timeout=1500)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
