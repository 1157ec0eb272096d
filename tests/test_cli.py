"""Command-line interface: argument handling (the commands' numbers are tested elsewhere)."""

import pytest

from skvalve.cli import build_parser, main


def test_unknown_paper_is_rejected_by_argparse():
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reproduce", "nosuchpaper"])


def test_missing_command_is_an_error():
    with pytest.raises(SystemExit):
        main([])
