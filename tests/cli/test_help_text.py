"""What a newcomer meets first: every option of every subcommand says what it
does in --help, and ``pinfeed --version`` names the version."""
import argparse
import tomllib
from pathlib import Path

import pytest

from cli_runs import run_cli
from pipeline import __version__
from pipeline.cli import build_parser


def _options(parser, prog="pinfeed"):
    """``(prog, option action)`` for every option of the parser and its subcommands."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _options(sub, f"{prog} {name}")
        elif action.option_strings:
            yield prog, action


def test_every_option_has_help_text():
    options = list(_options(build_parser()))
    progs = {prog for prog, _ in options}
    assert {"pinfeed plan", "pinfeed speed", "pinfeed catalog query", "pinfeed sense classify"} <= progs
    missing = [f"{prog} {'/'.join(a.option_strings)}" for prog, a in options
               if a.option_strings != ["-h", "--help"] and (not a.help or not a.help.strip())]
    assert not missing, f"options without help text: {missing}"


@pytest.mark.parametrize("prog", ["plan", "speed", "catalog list", "catalog show", "catalog query"])
def test_json_says_what_it_prints(prog, capsys):
    code, out, _ = run_cli(capsys, [*prog.split(), "--help"])
    assert code == 0
    text = " ".join(out.split())
    assert "--json print " in text and "JSON" in text.split("--json", 1)[1]


def test_version(capsys):
    code, out, err = run_cli(capsys, ["--version"])
    assert code == 0 and err == ""
    assert out.strip() == f"pinfeed {__version__}"
    pyproject = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())
    assert __version__ == pyproject["project"]["version"]  # the installed package's metadata
    code, out, _ = run_cli(capsys, ["--help"])
    assert code == 0 and "--version" in out
