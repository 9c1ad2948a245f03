"""Every command's ``--help`` works, and `ballcage.cli`'s docstring lists exactly the commands the parser knows."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys

import pytest

import ballcage.cli
from ballcage import studies


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(actions[0].choices) if actions else {}


def _commands() -> list[str]:
    """The commands of the parser, in its order; a command with its own subcommands as ``scene show``."""
    out = []
    for name, parser in _subcommands(ballcage.cli.build_parser()).items():
        inner = _subcommands(parser)
        out += [f"{name} {sub}" for sub in inner] if inner else [name]
    return out


def _documented() -> list[str]:
    """The command names of the docstring's indented list (``    run          simulate ...``)."""
    doc = ballcage.cli.__doc__ or ""
    block = doc.split("Commands,", 1)[1].split("\n\n", 2)[1]
    return [re.split(r"\s{2,}", line.strip(), maxsplit=1)[0] for line in block.splitlines()]


def _help(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "ballcage", *args, "--help"], capture_output=True, text=True, timeout=120
    )


def test_the_docstring_lists_every_command_in_the_parsers_order():
    assert len(_commands()) >= 11
    assert _documented() == _commands()


def test_the_docstring_names_every_exit_code():
    doc = ballcage.cli.__doc__ or ""
    codes = doc.split("Exit codes:", 1)[1]
    for code in (0, 1, 2, 3, ballcage.cli.EXIT_INTERNAL, 130):
        assert re.search(rf"(^|[\s;:]){code}\s", codes), code


def test_top_level_help_lists_every_command():
    proc = _help()
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("usage: ballcage ")
    listed = proc.stdout.split("commands:", 1)[1]
    for name in _subcommands(ballcage.cli.build_parser()):
        assert re.search(rf"^\s+{re.escape(name)}(\s|$)", listed, re.MULTILINE), name


@pytest.mark.parametrize("command", [*_subcommands(ballcage.cli.build_parser()), *(c for c in _commands() if " " in c)])
def test_each_command_help_exits_0_with_its_usage(command):
    proc = _help(*command.split())
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    assert proc.stdout.startswith(f"usage: ballcage {command} "), proc.stdout[:200]
    assert "options:" in proc.stdout


def test_stability_help_lists_the_studies_parameter_names():
    # The names come from ballcage.studies, imported only when the help is shown.
    proc = _help("stability")
    assert proc.returncode == 0, proc.stderr
    text = " ".join(proc.stdout.split())
    assert f"(default all: {','.join(studies.PARAMETER_NAMES)})" in text
