"""Every timing in the manual and the README has one source.

A timing (how long a command, a job, a benchmark, a test run or a stage
takes: "took 5.2 min", "about 20 seconds", "42 CPU minutes") is a measured
record with its date and machine, kept in one place: the performance pages
(``docs/performance/``), or, for the gallery examples' run times, the page
sphinx-gallery writes when it builds the manual (``sg_execution_times``).
Every other page links there instead of restating the number, or quotes it
with the link in the same paragraph (or list item). This test scans the
manual's source pages (``docs/**/*.md`` outside ``docs/performance/`` and
the generated folders, the gallery's header, the gallery examples'
docstrings) and ``README.md`` for a number with a time unit and names
page:line and the phrase of each one with no such link beside it.

Not timings, and allowed: the elapsed time in console output a command
prints (a progress line's "(16%, 11 s)", the planner's "46126 new rollouts
in 614 s,"), the progress interval ("every 5 seconds"), a
timeout in an error message ("within 10 s"), a throughput ("parts a
minute"), a signal's own length ("1001 samples over 5.000 s at 200 Hz").
Time steps and inputs written in exponent form ("5e-5 s", "1e12 s") are not
matched at all.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SKIPPED = ("_build", "_generated", "gallery", "performance", "_templates")

_NUMBER = r"(?:\d+(?:[.,]\d+)*(?:\s?(?:-|–|to)\s?\d+(?:[.,]\d+)*)?)"
_WORD = (r"(?:a\s+few|a\s+couple\s+of|half\s+an?|an?|one|two|three|four|five|six|seven|"
         r"eight|nine|ten|twenty|thirty|forty|fifty|sixty|few|several)")
# "a second" is left out on purpose: it is nearly always the ordinal ("a second pin").
TIMING = re.compile(
    rf"(?<![\w.\-+/])(?:~\s?)?{_NUMBER}\s?(?:CPU\s)?"
    r"(?:ms|us|µs|s|secs?|seconds?|min|mins|minutes?|h|hrs?|hours?|days?)\b(?![/-])"
    rf"|\b{_WORD}\s(?:CPU\s)?(?:minutes?|hours?|days?|seconds)\b",
    re.IGNORECASE,
)

# Spans in which a match is not a timing (see the module docstring).
ALLOWED = [re.compile(p, re.IGNORECASE) for p in (
    r"\(\d+%, \d+ s\)",                         # a progress line's elapsed time
    r"new rollouts in \d+ s,",                    # the planner's summary line in console output
    r"every \d+ seconds",                        # the progress interval
    r"within \d+ s \.\.\.\"|within \d+ s \(",    # a timeout in an error message
    r"parts a minute",                           # a throughput
    r"samples over [\d.]+ s at \d+ Hz",          # a force profile's own length
)]

# A link to a source of timings: any performance page, or the gallery's
# computation-times page (Markdown links, MyST {doc}/{ref} roles, rst roles).
SOURCE_LINK = re.compile(
    r"\]\([^)]*(?:performance/|sg_execution_times)[^)]*\)"
    r"|\{(?:doc|ref)\}`[^`]*(?:performance|sg_execution_times)[^`]*`"
    r"|:(?:doc|ref):`[^`]*(?:performance|sg_execution_times)[^`]*`",
    re.IGNORECASE,
)

_BULLET = re.compile(r"^\s*[-*+]\s")
_ITEM = re.compile(r"^\s*(?:[-*+]|\d+\.)\s")


def _starts_item(line: str, unit: list[str]) -> bool:
    """Whether ``line`` starts a new list item after the lines of ``unit``
    (a numbered line only inside a list: "16. Through ..." can be the
    continuation of a sentence)."""
    return bool(unit) and (bool(_BULLET.match(line))
                           or bool(_ITEM.match(line)) and bool(_ITEM.match(unit[0])))


def units(text: str):
    """(first line number, lines) for each paragraph of ``text``: blocks
    between blank lines, a list split into its items."""
    unit: list[str] = []
    start = 1
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or _starts_item(line, unit):
            if unit:
                yield start, unit
            unit = [] if not line.strip() else [line]
            start = number + (0 if line.strip() else 1)
            continue
        if not unit:
            start = number
        unit.append(line)
    if unit:
        yield start, unit


def bare_timings(text: str, first_line: int = 1) -> list[tuple[int, str]]:
    """(line number, phrase) for each timing in ``text`` whose paragraph has
    no link to a source of timings."""
    found = []
    for start, lines in units(text):
        block = "\n".join(lines)
        if SOURCE_LINK.search(block):
            continue
        allowed = [m.span() for pattern in ALLOWED for m in pattern.finditer(block)]
        for match in TIMING.finditer(block):
            if any(a <= match.start() and match.end() <= b for a, b in allowed):
                continue
            line = start + block.count("\n", 0, match.start())
            found.append((first_line - 1 + line, " ".join(match.group(0).split())))
    return found


def sources():
    """(path, text, line number of the text's first line) for every page this
    rule covers."""
    pages = [ROOT / "README.md", DOCS / "examples" / "GALLERY_HEADER.rst"]
    pages += sorted(p for p in DOCS.rglob("*.md")
                    if not set(p.relative_to(DOCS).parts[:-1]) & set(SKIPPED)
                    and "generated" not in p.relative_to(DOCS).parts)
    for page in pages:
        yield page, page.read_text(encoding="utf-8"), 1
    for example in sorted((DOCS / "examples").glob("plot_*.py")):
        module = ast.parse(example.read_text(encoding="utf-8"))
        doc = module.body[0] if module.body else None
        if isinstance(doc, ast.Expr) and isinstance(doc.value, ast.Constant) \
                and isinstance(doc.value.value, str):
            # the docstring's text starts on its opening quotes' line
            yield example, doc.value.value, doc.lineno


def test_the_pattern_flags_a_bare_timing():
    page = ("Intro.\n\n"
            "Planning a new part took 5.2 min wall and\n"
            "42 CPU minutes on 2 cores.\n\n"
            "- a list item: about 20 seconds each\n"
            "- another item, 6.9 s ([measured](../performance/index.md))\n\n"
            "It runs in under a minute, or half an hour cold.\n\n"
            "On 16 cores it took 2.2\nmin. Or on\n"
            "16. Through SLURM: 39 min ([details](../performance/family-atlas.md)).\n")
    assert bare_timings(page) == [(3, "5.2 min"), (4, "42 CPU minutes"),
                                  (6, "20 seconds"),
                                  (9, "a minute"), (9, "half an hour")]
    # "16." continues the sentence before it, so the link covers "2.2 min"


def test_a_linked_or_allowed_number_passes():
    linked = ("A new part is planned in under a minute\n"
              "([performance page](../performance/index.md#planning-time-of-new-parts)).\n")
    gallery = "Run times: :ref:`computation times <sphx_glr_sg_execution_times>`; 20 s.\n"
    not_timings = (
        "Timestep 5e-5 s, a CSV spanning 1e12 s, a belt at 150 mm/s, 7,000 rollouts/s.\n\n"
        "They print, at least every 5 seconds, a line:\n\n"
        "    ... screening and judging: 10/65 sequences done (16%, 11 s)\n"
        "    tight planner, friction 0.15: 46126 new rollouts in 614 s, stored under ...\n\n"
        '"cannot reach the dask scheduler at ADDR within 10 s ..."\n\n'
        "{{ plans.asym_triangle.throughput }} parts a minute; a second pin; 3 mm; 40 deg.\n\n"
        "profile run7.csv: 1001 samples over 5.000 s at 200 Hz\n")
    assert bare_timings(linked) == []
    assert bare_timings(gallery) == []
    assert bare_timings(not_timings) == []


def test_every_timing_links_to_its_source():
    pages = list(sources())
    assert len(pages) > 30   # the walk found the manual
    bare = [f"{path.relative_to(ROOT)}:{line}: {phrase!r}"
            for path, text, first in pages for line, phrase in bare_timings(text, first)]
    assert not bare, (
        "timings with no link to their measured record (move the number to "
        "docs/performance/index.md with its date and machine, and link there):\n"
        + "\n".join(bare))
