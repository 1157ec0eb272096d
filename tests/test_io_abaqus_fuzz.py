"""Fuzzing the Abaqus reader: generated and mutated inputs raise AbaqusParseError or read, nothing else.

Inputs are built from the hand-written test deck (every keyword family the reader knows) and from
random keyword/data lines, then mutated byte-wise (insert, delete, replace with separators, digits,
non-ASCII and invalid UTF-8, duplicate or drop lines, cut the file). Each read runs under a wall-clock
alarm so that a hang fails the test. Deterministic (hypothesis ``derandomize``).
"""

import logging
import os
import shutil
import signal
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_io_abaqus_model import DECK

from skvalve.io.abaqus import AbaqusParseError, read_model

N_EXAMPLES = 1000  # per test; two tests -> 2000 inputs
SECONDS_PER_READ = 5.0
BASE_LINES = DECK.splitlines()
KEYWORDS = ["*Node", "*Element, type=C3D8R", "*Element, type=T3D2, elset=E", "*Nset, nset=S", "*Elset, elset=E",
            "*Nset, nset=G, generate", "*Surface, name=F", "*Material, name=M", "*Density", "*Hyperelastic, OGDEN, N=2",
            "*Amplitude, name=A, definition=SMOOTH STEP", "*Boundary, amplitude=A", "*Step", "*End Step", "*Static",
            "*Dsload", "*Include, input=x.inp", "*Include, input=fuzz.inp", "*Part, name=P", "*End Part",
            "*Assembly, name=X", "*Instance, name=I, part=P", "*End Instance", "*End Assembly", "*MPC",
            "*Solid Section, elset=E, material=M", "*Contact Pair, interaction=T", "*Friction", "**comment",
            "*Transform, nset=S", "*Rigid Body, ref node=S, elset=E", "*Anisotropic Hyperelastic, user,"]
PIECES = ["1", "2", "-3", "0.5", "1e-9", "1e999", "nan", ",", ", ,", "S1", "SPOS", "I.1", "E", "S", "P", "A", "3, 3",
          "1, 2, 3, 4, 5, 6, 7, 8, 9", "LINK, S, S", "1, 4, 1", "1, 100000000000, 1", "ENCASTRE", "\u0663", "\t", ""]
ALPHABET = [",", "*", "=", ".", "-", "e", "1", "0", " ", "\n", "\r", '"', "\u00e9", "\ufeff", "9"]
INVALID_BYTES = [b"\xff", b"\xe9", b"\xef\xbb\xbf", b"\x00", b"\xc3"]


# a memory-backed folder where there is one: thousands of small writes
_SHM = Path("/dev/shm")
FOLDER = Path(tempfile.mkdtemp(prefix="skvalve_fuzz_", dir=_SHM if os.access(_SHM, os.W_OK) else None))
(FOLDER / "x.inp").write_text("*Node\n1, 0, 0, 0\n")


@pytest.fixture(scope="module", autouse=True)
def _quiet_reader():
    """The reader logs ignored keywords once per file: thousands of files here, so silence it."""
    logger = logging.getLogger("skvalve.io.abaqus.reader")
    level = logger.level
    logger.setLevel(logging.ERROR)
    yield
    logger.setLevel(level)
    shutil.rmtree(FOLDER, ignore_errors=True)


def _hang(*_args):
    raise TimeoutError(f"reader did not return within {SECONDS_PER_READ} s")


def _read_guarded(data: bytes) -> None:
    path = FOLDER / "fuzz.inp"
    path.write_bytes(data)
    previous = signal.signal(signal.SIGALRM, _hang)
    signal.setitimer(signal.ITIMER_REAL, SECONDS_PER_READ)
    try:
        read_model(path)
    except AbaqusParseError as error:
        assert str(error)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@st.composite
def mutated_deck(draw) -> bytes:
    lines = list(BASE_LINES)
    for _ in range(draw(st.integers(0, 6))):
        action = draw(st.sampled_from(["drop", "duplicate", "swap", "insert_line", "edit"]))
        index = draw(st.integers(0, len(lines) - 1))
        if action == "drop" and len(lines) > 1:
            lines.pop(index)
        elif action == "duplicate":
            lines.insert(index, lines[index])
        elif action == "swap":
            other = draw(st.integers(0, len(lines) - 1))
            lines[index], lines[other] = lines[other], lines[index]
        elif action == "insert_line":
            lines.insert(index, draw(st.sampled_from(KEYWORDS + PIECES)))
        else:
            text = lines[index]
            where = draw(st.integers(0, len(text)))
            cut = draw(st.integers(0, 3))
            lines[index] = text[:where] + draw(st.sampled_from(ALPHABET + PIECES)) + text[where + cut:]
    data = "\n".join(lines).encode("utf-8") + b"\n"
    if draw(st.booleans()):
        where = draw(st.integers(0, len(data)))
        data = data[:where] + draw(st.sampled_from(INVALID_BYTES)) + data[where:]
    if draw(st.integers(0, 9)) == 0:
        data = data[: draw(st.integers(0, len(data)))]
    return data


@st.composite
def generated_deck(draw) -> bytes:
    lines = []
    for _ in range(draw(st.integers(1, 14))):
        lines.append(draw(st.sampled_from(KEYWORDS)))
        for _ in range(draw(st.integers(0, 3))):
            lines.append(", ".join(draw(st.lists(st.sampled_from(PIECES), min_size=1, max_size=9))))
    return ("\n".join(lines) + "\n").encode("utf-8")


FUZZ = settings(max_examples=N_EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs POSIX interval timers")
@FUZZ
@given(mutated_deck())
def test_mutated_decks_raise_only_parse_errors(data):
    _read_guarded(data)


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs POSIX interval timers")
@FUZZ
@given(generated_deck())
def test_generated_decks_raise_only_parse_errors(data):
    _read_guarded(data)
