"""The manual builds with warnings as errors, and its generated references are complete:
every command and option of the parser, every key of the config schema, every local link."""
from __future__ import annotations

import argparse
import html
import re
from html.parser import HTMLParser
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def page_text(path: Path) -> str:
    """The page's text with tags removed and entities decoded."""
    raw = re.sub(r"<script.*?</script>|<style.*?</style>", " ", path.read_text(), flags=re.S)
    return html.unescape(re.sub(r"<[^>]+>", "", raw))


def parsers(parser: argparse.ArgumentParser, path=("pinfeed",)):
    """(command path, parser) for the parser and every subparser below it."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from parsers(sub, path + (name,))


def test_command_reference_lists_every_verb_and_option_the_help_lists(built_docs):
    from pipeline.cli import build_parser
    text = page_text(built_docs / "reference" / "cli.html")
    walked = list(parsers(build_parser()))
    assert len(walked) > 13            # pinfeed, its verbs and the verbs' subcommands
    missing = []
    for path, parser in walked:
        help_text = parser.format_help()   # what `pinfeed ... --help` prints
        if len(path) > 1 and path[-1] not in text:
            missing.append(" ".join(path))
        for option in set(OPTION.findall(help_text)) - {"--help"}:
            if option not in text:
                missing.append(f"{' '.join(path)} {option}")
    assert missing == []


def test_command_reference_has_a_section_per_verb(built_docs):
    from pipeline.cli import build_parser
    parser = build_parser()
    verbs = [name for path, _ in parsers(parser) if len(path) == 2 for name in path[1:]]
    page = (built_docs / "reference" / "cli.html").read_text()
    headings = html.unescape(" ".join(re.findall(r"<h[2-4][^>]*>(.*?)</h[2-4]>", page, flags=re.S)))
    assert [v for v in verbs if v not in headings] == []


def schema_properties(node, found=None) -> set[str]:
    """Every property name anywhere in the schema (an independent, blunt walk)."""
    found = set() if found is None else found
    if isinstance(node, dict):
        for name, value in (node.get("properties") or {}).items():
            found.add(name)
            schema_properties(value, found)
        for key, value in node.items():
            if key != "properties":
                schema_properties(value, found)
    elif isinstance(node, list):
        for item in node:
            schema_properties(item, found)
    return found


def test_config_reference_lists_every_schema_key_with_its_description(built_docs):
    schema = yaml.safe_load((ROOT / "config" / "schema.yaml").read_text())
    page = built_docs / "reference" / "config.html"
    keys = set(re.findall(r"<code[^>]*><span class=\"pre\">([^<]+)</span></code>", page.read_text()))
    names = schema_properties(schema)
    assert len(names) > 90
    assert [n for n in names if not any(k == n or k.endswith("." + n) for k in keys)] == []
    text = " ".join(page_text(page).split())
    for key in ("sweep.theta_step", "planner.dynamic.speeds", "layout.seed", "families.NAME.parts[].units"):
        assert key in keys
    descriptions = [" ".join(str(schema["properties"][k]["description"]).split())[:60]
                    for k in schema["properties"]]
    assert [d for d in descriptions if d.replace("`", "'") not in text] == []
    assert "default 'catalog'" in text      # catalog_dir's default


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.hrefs, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if attrs.get("id"):
            self.ids.add(attrs["id"])
        for name in ("href", "src"):
            if attrs.get(name) and tag in ("a", "img", "link", "script"):
                self.hrefs.append(attrs[name])


def test_every_local_link_and_image_resolves(built_docs):
    pages = sorted(built_docs.rglob("*.html"))
    parsed = {}
    for page in pages:
        p = _Links()
        p.feed(page.read_text())
        parsed[page] = p
    broken = []
    for page, p in parsed.items():
        for href in p.hrefs:
            if re.match(r"^[a-z]+:", href) or href.startswith("//"):
                continue
            target, _, fragment = href.partition("#")
            target = target.split("?")[0]
            path = (page.parent / target).resolve() if target else page
            if not path.exists():
                broken.append(f"{page.relative_to(built_docs)} -> {href}")
            elif fragment and path.suffix == ".html" and path in parsed and fragment not in parsed[path].ids:
                broken.append(f"{page.relative_to(built_docs)} -> {href} (no such anchor)")
    assert len(pages) > 30
    assert broken == []


def test_the_gallery_ran_every_example(built_docs):
    examples = sorted((ROOT / "docs" / "examples").glob("plot_*.py"))
    assert len(examples) >= 7
    for example in examples:
        page = built_docs / "gallery" / (example.stem + ".html")
        assert page.exists(), example.name
        assert re.search(r"<img[^>]+sphx_glr_" + example.stem, page.read_text()), example.name


def test_readme_is_short_and_its_links_resolve():
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 150
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", readme)
    assert len(targets) > 20
    assert [t for t in targets if not re.match(r"^[a-z]+:", t) and not (ROOT / t).exists()] == []
