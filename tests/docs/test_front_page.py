"""The front page, the README and every page quoting the default plans agree
with the plans this code computes.

The docs build computes the default config's plans (docs/_ext/default_run.py:
``pinfeed plan``, the speed and layout stages) and writes their numbers to
``docs/_generated/default_run.json``; pages quote them through substitutions.
These tests read what that build wrote, so they fail when a page, the README
or the README's committed figure shows another plan than the code makes.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
README_IMAGE = re.compile(r"!\[[^\]]*\]\(([^)]+\.png)\)")


def png_text(path: Path) -> dict:
    """The text fields of a PNG (tEXt/iTXt chunks), read with Pillow."""
    from PIL import Image
    with Image.open(path) as image:
        image.load()
        return dict(getattr(image, "text", {}) or image.info)


@pytest.fixture(scope="module")
def default_run(built_docs) -> dict:
    return json.loads((DOCS / "_generated" / "default_run.json").read_text())


def test_readme_figure_shows_the_default_plan(default_run):
    images = README_IMAGE.findall((ROOT / "README.md").read_text())
    assert images, "the README shows no figure"
    stored = png_text(ROOT / images[0]).get("pinfeed-plan")
    computed = default_run["parts"]["asym_triangle"]["pins"]
    assert stored == computed, (
        f"the README's figure {images[0]} shows plan {stored!r}, but this code recommends "
        f"{computed!r} for the default asymmetric triangle: run 'make readme-figure' and commit it")


def test_front_page_shows_the_drawing_the_build_computed(built_docs, default_run):
    page = (built_docs / "index.html").read_text()
    shown = re.findall(r'<img[^>]+src="([^"]+)"', page)
    assert any(re.search(r"feeder_asym_triangle\d*\.png$", src) for src in shown), shown
    src = next(s for s in shown if re.search(r"feeder_asym_triangle\d*\.png$", s))
    built = png_text(built_docs / src)
    assert built.get("pinfeed-plan") == default_run["parts"]["asym_triangle"]["pins"]


def test_pages_quote_the_computed_plans(built_docs, default_run):
    """Each page that quotes a default plan shows the computed one, and no page
    of the source spells a default plan out by hand (it would go stale)."""
    tutorial = (built_docs / "tutorials" / "paper-feeder.html").read_text()
    for name, numbers in default_run["parts"].items():
        assert numbers["pins"] in tutorial, f"the paper-feeder tutorial does not show {name}'s plan"
    index = (built_docs / "index.html").read_text()
    assert default_run["parts"]["asym_triangle"]["pins"] in index
    written = []
    for page in sorted(DOCS.rglob("*.md")):
        # The performance pages are dated records of measured runs (date, machine,
        # the plan that run found), not statements about this code.
        if {"_build", "_generated", "performance"} & set(page.relative_to(DOCS).parts):
            continue
        text = page.read_text()
        for name, numbers in default_run["parts"].items():
            if numbers["pins"] != "-" and numbers["pins"] in text:
                written.append(f"{page.relative_to(ROOT)} spells out {name}'s plan {numbers['pins']}: "
                               f"write {{{{ plans.{name}.pins }}}}")
    assert written == []


def test_default_numbers_are_recorded_with_their_provenance(default_run):
    provenance = default_run["provenance"]
    assert provenance["pinfeed_version"] and provenance["created"]
    assert default_run["machine"]
    for name, numbers in default_run["parts"].items():
        assert re.fullmatch(r"(P\d+ ?)+|-", numbers["pins"]), (name, numbers["pins"])
        assert set(numbers) >= {"width", "in_set", "speed_limit", "belt_speed", "throughput"}
