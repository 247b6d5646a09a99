"""The manual's stored plans agree with the pages that state them.

Pages state plans of other parts than the default config's from files kept in
``docs/plans/`` (``docs/_ext/stored_plans.py``; its registry names the
command of each and, per page, the numbers the page takes from it; the
numbers themselves come from ``docs/_ext/plan_numbers.py``). These tests
fail when a page and its file disagree:

(a) every ``{{ stored.NAME.KEY }}`` a page writes names a registered plan
    and a number its stored file has;
(b) every page uses each key the registry lists for it, so a number typed in
    place of its substitution fails; a stored plan's pins are not written
    out in a page's prose (dated measurement records under
    ``docs/performance/`` aside); another command's output on a page that
    names the plan (a layout, a sensor's verdict, an atlas row) shows the
    file's pins and numbers;
(c) each stored file was made by the registry's command: the same
    arguments, the same follow-up commands, the same input files, committed
    code;
(d) a console block that runs a registered command (the tutorials' blocks,
    which ``test_tutorial_commands.py`` also runs) shows only lines the
    stored output holds, and the pages that show a stored command's output
    include the generated file (``docs/_generated/stored/``) instead of a
    pasted copy.
"""
from __future__ import annotations

import hashlib
import re
import shlex
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import plan_numbers  # noqa: E402
import stored_plans  # noqa: E402
from stored_plans import REGISTRY  # noqa: E402

SKIPPED = ("_build", "_generated", "gallery", "_templates", "generated")
#: Folders of dated measurement records (each row names its date and code), which
#: may name a plan that a stored file also holds.
DATED = ("performance",)
SUBSTITUTION = re.compile(r"\{\{\s*stored\.(\w+)\.(\w+)\s*\}\}")
FENCE = re.compile(r"^(`{3,}|~{3,})([^\n]*)\n(.*?)^\1", re.S | re.M)
CONSOLE = re.compile(r"^```(?:console|\{code-block\} console)\n((?::[\w-]+:[^\n]*\n)*)\n?(.*?)^```", re.S | re.M)


def pages() -> list[Path]:
    return sorted(p for p in DOCS.rglob("*.md") if not set(p.relative_to(DOCS).parts[:-1]) & set(SKIPPED))


def numbers(name: str) -> dict:
    return stored_plans.values(stored_plans.load(name))


def uses(text: str) -> set[tuple[str, str]]:
    """The (NAME, KEY) pairs of the ``{{ stored.NAME.KEY }}`` a page writes (not
    in code, where MyST substitutes nothing)."""
    return set(SUBSTITUTION.findall(re.sub(r"`[^`\n]+`", "", prose(text))))


def missing_keys(text: str, name: str, keys) -> list[str]:
    """The registered keys of plan ``name`` that a page's text does not use."""
    used = {key for n, key in uses(text) if n == name}
    return [k for k in keys if k not in used]


def prose(text: str) -> str:
    """A page without its fenced blocks (code, console output, directives' bodies
    are kept: a figure's caption is prose)."""
    return FENCE.sub(lambda m: m.group(0) if m.group(2).startswith("{") and "code-block" not in m.group(2)
                     else "", text)


PIN = r"P\d+(?:v[-+]\d+)?"
PIN_RUN = re.compile(rf"(?<![\w-]){PIN}(?:(?:[ ,]+|,? and |,? then | -> )" + PIN + r")*(?![\w-])")


def pin_runs(text: str) -> list[list[str]]:
    """Every sequence of pin labels a text writes out (``P14 P6``, ``P14 and P6``,
    ``P11 -> P3``), each as long as it goes."""
    return [re.findall(PIN, m.group(0)) for m in PIN_RUN.finditer(text)]


def squeeze(text: str) -> str:
    return " ".join(text.split())


def shown_in(expected: str, output: str) -> bool:
    """Whether a console line (``...`` for any text) appears in the squeezed output."""
    pattern = ".*?".join(re.escape(part) for part in squeeze(expected).split("..."))
    return re.search(pattern, output) is not None


def console_steps(text: str) -> list[tuple[str, list[str]]]:
    """(command, shown output lines) of every ``$ `` line of every console block."""
    steps = []
    for _options, body in CONSOLE.findall(text):
        for line in body.splitlines():
            if line.startswith("$ "):
                steps.append((line[2:], []))
            elif steps and line.strip() and line.strip() != "...":
                steps[-1][1].append(line)
    return steps


# --------------------------------------------------------------------------- the helpers catch what they must

def test_a_number_written_in_place_of_its_substitution_is_caught():
    page = "The plan {{ stored.wedge.pins }} ends in one set {{ stored.wedge.width }} deg wide.\n"
    assert missing_keys(page, "wedge", ["pins", "width"]) == []
    edited = page.replace("{{ stored.wedge.width }}", "4.8")
    assert missing_keys(edited, "wedge", ["pins", "width"]) == ["width"]


def test_pin_runs_are_read_whole():
    assert pin_runs("the plan P14 P6; then P11 P3 P11 P19; P1 and P2; P11 -> P3v-2; P6") == [
        ["P14", "P6"], ["P11", "P3", "P11", "P19"], ["P1", "P2"], ["P11", "P3v-2"], ["P6"]]


def test_prose_drops_code_but_keeps_captions():
    text = ("Pins P1 P2.\n\n```console\n$ pinfeed plan\nP3 P4\n```\n\n"
            "```{figure} x.png\n:alt: y\n\nThe plan P5 P6.\n```\n")
    assert "P3 P4" not in prose(text) and "P1 P2" in prose(text) and "P5 P6" in prose(text)


def test_console_text_keeps_the_selected_lines_and_marks_the_rest():
    console = stored_plans.Console("x", (r"^part ", r"^  #1"), ())
    stored = {"runs": [{"argv": ["pinfeed", "plan", "--part", "p"],
                        "printed": ["  ... progress", "part p-1: model minpower", "  state 1: ...",
                                    "  #1 (recommended): P1 at 2 mm", "stored the plan at x"]}]}
    assert stored_plans.console_text(console, stored).splitlines() == [
        "$ pinfeed plan --part p", "...", "part p-1: model minpower", "...",
        "  #1 (recommended): P1 at 2 mm", "..."]


# --------------------------------------------------------------------------- the registry and its files

def test_registry_names_are_substitution_names_and_pages_exist():
    for name, entry in REGISTRY.items():
        assert re.fullmatch(r"[a-z][a-z0-9_]*", name), name
        for page in [*entry.pages, *entry.quoted]:
            assert (DOCS / page).is_file(), f"{name}: no page {page}"
        assert entry.pages, f"{name} is stated by no page"
    for file, console in stored_plans.CONSOLES.items():
        assert console.plan in REGISTRY and console.pages, file
        assert console.run <= len(REGISTRY[console.plan].then), file


@pytest.mark.parametrize("name", list(REGISTRY))
def test_stored_file_was_made_by_the_registry_command(name):
    """(c) The arguments, follow-up commands and inputs recorded in the file
    are the registry's."""
    entry = REGISTRY[name]
    assert stored_plans.path_of(name).is_file(), (
        f"docs/plans/{name}.json is missing: python docs/_ext/stored_plans.py refresh {name}")
    stored = stored_plans.load(name)
    assert stored["args"] == list(entry.args)
    assert stored["added_args"] == list(entry.added)
    assert stored["then"] == [list(t) for t in entry.then]
    assert stored["command"] == stored_plans.command_line(entry)
    assert stored["runs"][0]["argv"] == ["pinfeed", entry.verb, *entry.args, *entry.added]
    assert [r["argv"][1:] for r in stored["runs"][1:]] == [list(t) for t in entry.then]
    assert {k: v["from"] for k, v in stored["inputs"].items()} == dict(entry.inputs)
    for local, record in stored["inputs"].items():
        digest = hashlib.sha256((ROOT / record["from"]).read_bytes()).hexdigest()
        assert digest == record["sha256"], (
            f"{record['from']} changed since docs/plans/{name}.json was made: refresh it")
    for key in ("made", "code", "machine"):
        assert stored[key]
    assert not stored["code"]["code_differs_from_commit"], "a stored plan must come from committed code"


@pytest.mark.parametrize("name", list(REGISTRY))
def test_registered_keys_are_numbers_of_the_stored_plan(name):
    values = numbers(name)
    for page, keys in REGISTRY[name].pages.items():
        assert [k for k in keys if not values.get(k)] == [], (name, page)


# --------------------------------------------------------------------------- pages against their files

@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(DOCS)))
def test_every_stored_substitution_resolves(page):
    """(a)"""
    bad = []
    for name, key in sorted(uses(page.read_text())):
        if name not in REGISTRY:
            bad.append(f"{name}: no such stored plan")
        elif not numbers(name).get(key):
            bad.append(f"{name}.{key}: not a number of docs/plans/{name}.json")
    assert bad == []


@pytest.mark.parametrize("name", list(REGISTRY))
def test_pages_use_the_registered_substitutions(name):
    """(b) Each page takes from the file what the registry says it must."""
    entry = REGISTRY[name]
    for page, keys in entry.pages.items():
        text = (DOCS / page).read_text()
        assert missing_keys(text, name, keys) == [], (
            f"{page} no longer writes {{{{ stored.{name}.KEY }}}} for these keys: a number written by "
            "hand instead? (docs/_ext/stored_plans.py lists what each page takes from its file)")


@pytest.mark.parametrize("name", list(REGISTRY))
def test_no_page_writes_a_stored_plans_pins_out(name):
    """(b) The pins of a plan of two or more pins appear in prose only as a substitution."""
    pins = numbers(name)["pins"].split()
    if len(pins) < 2:
        return
    hits = [str(p.relative_to(DOCS)) for p in pages()
            if p.relative_to(DOCS).parts[0] not in DATED and pins in pin_runs(prose(p.read_text()))]
    assert hits == [], f"the pins {' '.join(pins)} of docs/plans/{name}.json written out by hand"


@pytest.mark.parametrize("name", list(REGISTRY))
def test_console_lines_shown_with_a_stored_command_are_its_output(name):
    """(d) A console block running the registered command (a tutorial's) shows only
    lines the stored run printed; a page showing the stored output includes it."""
    entry, stored = REGISTRY[name], stored_plans.load(name)
    runs = {tuple(r["argv"][1:]): squeeze("\n".join(r["printed"])) for r in stored["runs"]}
    runs[(entry.verb, *entry.args)] = runs.pop((entry.verb, *entry.args, *entry.added))
    # Where the run added --out, the page's command does not keep the plan and says so.
    exempt = ("not stored:", "stored the plan at") if entry.added else ()
    for page in pages():
        for command, lines in console_steps(page.read_text()):
            try:
                argv = shlex.split(command)
            except ValueError:          # not a command line pinfeed could run
                continue
            if argv[:1] != ["pinfeed"] or tuple(argv[1:]) not in runs:
                continue
            wrong = [line for line in lines if not line.startswith(exempt)
                     and not shown_in(line, runs[tuple(argv[1:])])]
            assert wrong == [], f"{page.relative_to(DOCS)}: `{command}` shows lines docs/plans/{name}.json lacks"


@pytest.mark.parametrize("names", stored_plans.SAME_PLAN, ids=" = ".join)
def test_stored_plans_the_pages_call_one_plan_are_one(names):
    """The design's chosen change and the outline it wrote give the same plan."""
    first, *others = [numbers(n) for n in names]
    for other in others:
        assert (other["pins"], other["heights"], other["in_set"]) == (first["pins"], first["heights"], first["in_set"])


@pytest.mark.parametrize("file", list(stored_plans.CONSOLES))
def test_pages_include_the_stored_console_output(file):
    """(d) A stored command's output is included from the generated file, not pasted."""
    for page in stored_plans.CONSOLES[file].pages:
        assert f"_generated/stored/{file}.txt" in (DOCS / page).read_text(), page


@pytest.mark.parametrize("name", [n for n, e in REGISTRY.items() if e.quoted])
def test_code_blocks_quoting_a_stored_plan_show_its_numbers(name):
    """(b) Another command's output that names the plan (a layout, a sensor's
    verdict) shows the plan's own pins and numbers."""
    values = numbers(name)
    for page, templates in REGISTRY[name].quoted.items():
        text = squeeze((DOCS / page).read_text())
        assert [t for t in templates if squeeze(t.format(**values)) not in text] == [], page
