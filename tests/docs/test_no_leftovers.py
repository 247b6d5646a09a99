"""Text a user reads holds no leftovers of how pinfeed was made: no
"spec section N" (the manual's own pages say what the mechanics are), no
commit hash as a reference, no "requirement", no "the aim, under ...", no
remark on the sessions that built a feature. Scanned: README, docs sources,
the gallery examples, every --help text, the config schema's descriptions and
the docstrings the API reference renders (docs/reference/api.md).
Tracker numbers have their own test, test_no_tracker_numbers.py."""
from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import pytest
import yaml

from test_no_tracker_numbers import parser_texts

ROOT = Path(__file__).resolve().parents[2]
LEFTOVERS = [
    re.compile(r"spec\s+section", re.IGNORECASE),
    re.compile(r"\b(?:ref|commit)\s+[0-9a-f]{7}\b", re.IGNORECASE),
    re.compile(r"\brequirements?\b", re.IGNORECASE),
    re.compile(r"\bthe aim, under\b", re.IGNORECASE),
    re.compile(r"\bsessions? that (?:built|wrote|made)\b", re.IGNORECASE),
]
# A tutorial opens with what the reader will do; how the test suite runs its
# commands belongs in docs/development/testing.md.
HARNESS = re.compile(r"test suite|tests/docs/", re.IGNORECASE)

# Pages edited elsewhere at the time this test was written; each still holds
# leftovers. Remove an entry once its page is clean (the test then checks it).
PENDING_PAGES = set()
PENDING_TUTORIALS = set()


def leftovers(text: str) -> list[str]:
    """The leftover phrases in ``text``."""
    return [m.group(0) for pattern in LEFTOVERS for m in pattern.finditer(text)]


def test_the_patterns_catch_what_they_should():
    assert leftovers("see spec section 4 and Spec\nsection 9") == ["spec section", "Spec\nsection"]
    assert leftovers("benchmarks (ref 39f0550) at commit d667dff") == ["ref 39f0550", "commit d667dff"]
    assert leftovers("as the requirement asks") == ["requirement"]
    assert leftovers("the aim, under 60 s, is met") == ["the aim, under"]
    assert leftovers("no GPU was lent to the sessions that built it") == ["sessions that built"]
    assert leftovers("the mechanics page, section 4; --ref REV; refs abcdefg1") == []
    assert HARNESS.search("Every command on this page is run by the test suite")


def page_sources() -> list[Path]:
    files = [ROOT / "README.md", *sorted((ROOT / "docs" / "examples").glob("*.py"))]
    # Not the pages the docs build writes (docs/_generated, docs/gallery): a
    # fresh clone has none, and a build running beside the tests replaces them.
    files += sorted(p for p in (ROOT / "docs").rglob("*.md")
                    if not {"_build", "_generated", "gallery"} & set(p.parts))
    return files


def _rel(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _checked(paths, pending):
    mark = pytest.mark.xfail(reason="page edited elsewhere, still has leftovers")
    return [pytest.param(p, id=_rel(p), marks=[mark] if _rel(p) in pending else []) for p in paths]


def test_there_are_pages():
    assert len(page_sources()) > 30


@pytest.mark.parametrize("path", _checked(page_sources(), PENDING_PAGES))
def test_page_has_no_leftovers(path):
    assert leftovers(path.read_text()) == []


def _intro(text: str) -> str:
    """A page's text before its first second-level heading."""
    return re.split(r"^## ", text, maxsplit=1, flags=re.MULTILINE)[0]


@pytest.mark.parametrize("path", _checked(sorted((ROOT / "docs" / "tutorials").glob("*.md")), PENDING_TUTORIALS))
def test_tutorial_opens_without_harness_notes(path):
    assert HARNESS.findall(_intro(path.read_text())) == []


def test_help_texts_have_no_leftovers():
    from pipeline.cli import build_parser
    texts = list(parser_texts(build_parser()))
    assert len(texts) > 50
    assert [(where, leftovers(t)) for where, t in texts if leftovers(t)] == []


def schema_descriptions(node, where="schema"):
    """(where, text) for every ``description`` in the config schema."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "description" and isinstance(value, str):
                yield where, value
            else:
                yield from schema_descriptions(value, f"{where}.{key}")
    elif isinstance(node, list):
        for k, value in enumerate(node):
            yield from schema_descriptions(value, f"{where}[{k}]")


def test_schema_descriptions_have_no_leftovers():
    texts = list(schema_descriptions(yaml.safe_load((ROOT / "config" / "schema.yaml").read_text())))
    assert len(texts) > 50
    assert [(where, leftovers(t)) for where, t in texts if leftovers(t)] == []


AUTODOC = re.compile(r"^\.\. auto(?:class|function):: (\S+)$", re.MULTILINE)
AUTOSUMMARY = re.compile(r"^\.\. autosummary::\n((?:   .*\n|\n)*)", re.MULTILINE)


def rendered_names() -> list[str]:
    """The objects docs/reference/api.md renders (autoclass, autofunction and
    autosummary entries)."""
    text = (ROOT / "docs" / "reference" / "api.md").read_text()
    names = AUTODOC.findall(text)
    for block in AUTOSUMMARY.findall(text):
        names += [line.strip() for line in block.splitlines()
                  if line.strip() and not line.strip().startswith(":")]
    return names


def rendered_docstrings():
    """(name, docstring) for every object the API reference renders and, for
    a class, its public members."""
    for name in rendered_names():
        module, _, attr = name.rpartition(".")
        obj = getattr(importlib.import_module(module), attr)
        yield name, inspect.getdoc(obj) or ""
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if not member.startswith("_"):
                    yield f"{name}.{member}", inspect.getdoc(value) or ""


def test_rendered_docstrings_have_no_leftovers():
    docs = list(rendered_docstrings())
    assert len(docs) >= 8
    assert [(name, leftovers(d)) for name, d in docs if leftovers(d)] == []
