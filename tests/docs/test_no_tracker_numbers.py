"""Text a user reads never names a tracker number ("issue 25"): README, docs
sources, every --help text and every docstring in kernels/ and pipeline/."""
from __future__ import annotations

import argparse
import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TRACKER = re.compile(r"\bissues?\s*#?\s*\d+", re.IGNORECASE)
DOC_SUFFIXES = {".md", ".rst", ".txt", ".py"}


def tracker_mentions(text: str) -> list[str]:
    """The tracker-number mentions in ``text``."""
    return [m.group(0) for m in TRACKER.finditer(text)]


def test_the_pattern_catches_what_it_should():
    assert tracker_mentions("supports (issue 25) and Issues 11, 12") == ["issue 25", "Issues 11"]
    assert tracker_mentions("see issue #7") == ["issue #7"]
    assert tracker_mentions("an issue with 3 pins; issued 4 plans") == []


def doc_sources():
    files = [ROOT / "README.md", *sorted((ROOT / "config").glob("*.yaml"))]  # the schema's text is the config reference
    files += [p for p in (ROOT / "docs").rglob("*") if p.suffix in DOC_SUFFIXES
              and "_build" not in p.parts and "gallery" not in p.parts]
    return files


def test_readme_docs_and_configs_name_no_tracker_number():
    found = {str(p.relative_to(ROOT)): tracker_mentions(p.read_text()) for p in doc_sources()}
    assert {k: v for k, v in found.items() if v} == {}


def parser_texts(parser: argparse.ArgumentParser, path: str = "pinfeed"):
    """(where, text) for a parser's description, epilog, every option's help and
    every subparser's, recursively."""
    yield path, parser.description or ""
    yield path, parser.epilog or ""
    for action in parser._actions:
        yield f"{path} {'/'.join(action.option_strings) or action.dest}", action.help or ""
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                yield f"{path} {choice.dest}", choice.help or ""
            for name, sub in action.choices.items():
                yield from parser_texts(sub, f"{path} {name}")


def test_help_texts_name_no_tracker_number():
    from pipeline.cli import build_parser
    texts = list(parser_texts(build_parser()))
    assert len(texts) > 50   # the walk reached the subcommands
    assert [(where, tracker_mentions(t)) for where, t in texts if tracker_mentions(t)] == []


def docstrings(path: Path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                yield getattr(node, "name", "<module>"), doc


@pytest.mark.parametrize("package", ["kernels", "pipeline"])
def test_docstrings_name_no_tracker_number(package):
    found = [f"{p.relative_to(ROOT)}:{name}: {m}" for p in sorted((ROOT / package).rglob("*.py"))
             for name, doc in docstrings(p) for m in tracker_mentions(doc)]
    assert found == []
