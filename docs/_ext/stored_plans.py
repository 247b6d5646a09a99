"""Plans of other parts than the default config's, as the manual states them.

The default config's plans are computed by every docs build
(``docs/_ext/default_run.py``). Pages also state plans of other parts and
settings: the tutorial's drawings, a friction range or a support family on
the small test config, the default triangle's support-family answer and
shape tolerance, a long thin rectangle, the parts of the sweep-a-family
page. Planning those again in every build would take many minutes, so each
is run once by hand and kept in ``docs/plans/NAME.json``, and the docs
build renders every number the pages state about it from that file:

* :data:`REGISTRY` names each stored plan: the exact ``pinfeed plan``
  arguments the page documents, the files the command reads, the commands
  the page runs after it (``pinfeed speed``), per page the substitution keys
  (``{{ stored.NAME.KEY }}``) the page must use instead of writing the
  number, and text that another command's output on a page must show (a
  layout naming the plan's pins). The keys' values come from
  ``plan_numbers.py``, the one module that knows the plan file's keys.
* :data:`CONSOLES` names the console outputs pages include: one command of a
  stored plan and the lines of what it printed that the page shows.
* ``python docs/_ext/stored_plans.py refresh [NAME ...]`` runs the commands
  (one after another, in a scratch folder with an empty catalog) and writes
  ``docs/plans/NAME.json`` atomically: the command, the date, the code
  version (commit and a hash of the code), what the commands printed and
  the plan file. ``python docs/_ext/stored_plans.py list`` says which files
  are missing or were made from other code than the checkout's.
* ``docs/conf.py`` loads the files into the MyST substitutions
  ``{{ stored.NAME.KEY }}`` (:func:`write_generated`) and writes the console
  outputs to ``docs/_generated/stored/FILE.txt``.
* ``tests/docs/test_stored_plans.py`` fails when a page and its file
  disagree.

A stored file keeps the plan file as ``pinfeed plan`` wrote it, unless the
stored file would be larger than :data:`KEEP_WHOLE_BYTES`: then the plans
that were not recommended and the :data:`DROPPED` keys (per-step sets,
verification rows, statistics) are left out, and the file's ``trimmed`` key
says so.
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import hashlib
import json
import os
import platform
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PLANS = ROOT / "docs" / "plans"
GENERATED = ROOT / "docs" / "_generated" / "stored"
SMALL = "tests/data/paper_feeder_small.yaml"
FAMILY = "docs/howto/my_family.yaml"
#: The code a stored plan depends on (hashed into ``code.source_hash``).
SOURCES = (("pipeline", "*.py"), ("pipeline", "*.json"), ("kernels", "*.py"), ("config", "*.yaml"))
#: Environment of the runs (recorded in each file): a progress line at most once a
#: minute, so that the stored output is mostly the result.
RUN_ENV = {"PINFEED_PROGRESS_SECONDS": "60"}
#: A stored plan file at most this large keeps the whole plan file.
KEEP_WHOLE_BYTES = 200_000
#: Keys left out of a larger plan file, wherever they occur (see the module's notes).
DROPPED = ("rejected", "sets_after_each_pin", "initial_sets", "rows", "curve", "stats", "steps",
           "jump_steps", "selection_trials", "members_detail", "probe")


@dataclasses.dataclass(frozen=True)
class Stored:
    """One stored plan: how it is made and where the manual states it."""

    #: what it is, in a few words
    what: str
    #: the ``pinfeed plan`` (or ``pinfeed design``) arguments, exactly as the page documents them
    args: tuple[str, ...]
    #: page (relative to ``docs/``) -> the ``{{ stored.NAME.KEY }}`` keys it must use
    pages: dict
    #: files the command reads: name in the run folder -> repository path
    inputs: dict = dataclasses.field(default_factory=dict)
    #: arguments added to the page's when it is run (``--out`` where the page's
    #: command does not keep the plan); recorded apart
    added: tuple[str, ...] = ()
    #: pinfeed commands the page runs after the plan, in the same folder
    then: tuple[tuple[str, ...], ...] = ()
    #: page -> text that a code block of the page shows (another command's output
    #: naming this plan), with ``{KEY}`` for the plan's numbers: it must appear
    #: in the page, whitespace squeezed
    quoted: dict = dataclasses.field(default_factory=dict)
    #: the command: ``plan``, or ``design`` (its file holds the chosen change's plan)
    verb: str = "plan"


@dataclasses.dataclass(frozen=True)
class Console:
    """Console output a page includes (``docs/_generated/stored/NAME.txt``): one
    command of a stored plan and the lines of its output that ``show`` selects."""

    #: the stored plan
    plan: str
    #: regular expressions of the printed lines shown (the rest becomes ``...``)
    show: tuple[str, ...]
    #: the pages that include it
    pages: tuple[str, ...]
    #: regular expressions of lines shown with the lines indented deeper after them
    blocks: tuple[str, ...] = ()
    #: which command: 0 the plan, 1 the first of ``then``, ...
    run: int = 0
    #: whether it starts with the command line (``$ pinfeed ...``)
    command: bool = True


_TUTORIAL_DRAWINGS = {name: f"docs/tutorials/{name}" for name in
                      ("bracket.dxf", "bracket_design.dxf", "wedge.dxf", "holed_bracket.dxf")}

#: The stored plans, by name (``docs/plans/NAME.json``).
REGISTRY: dict[str, Stored] = {
    "bracket_one_pin": Stored(
        what="the tutorial's L bracket with one fixed pin (it ends in four sets)",
        args=("--outline", "bracket.dxf", "--mu-c", "0.2", "--depth", "1", "--speeds", ""),
        inputs={"bracket.dxf": _TUTORIAL_DRAWINGS["bracket.dxf"]},
        pages={"tutorials/own-part.md": ("pins_at", "heights", "sets_of_tolerance", "trials", "pin_spacing"),
               "howto/design-for-feeding.md": ("n_states", "state_thetas"),
               "explanation/complete.md": ("evidence",)}),
    "bracket_chamfered": Stored(
        what="the tutorial's bracket with the 6.5 mm chamfer pinfeed design found, four fixed pins",
        args=("--outline", "bracket_design.dxf", "--layer", "MODIFIED", "--mu-c", "0.2", "--depth", "4",
              "--speeds", ""),
        inputs={"bracket_design.dxf": _TUTORIAL_DRAWINGS["bracket_design.dxf"]},
        pages={"tutorials/own-part.md": ("n_states", "n_pins", "tolerance", "width"),
               "howto/design-for-feeding.md": ("pins",)}),
    "bracket_design": Stored(
        what="pinfeed design on the tutorial's bracket, up to four fixed pins: the chamfer it finds",
        verb="design",
        args=("--outline", "bracket.dxf", "--mu-c", "0.2", "--depth", "4", "--kinds", "chamfer,tab",
              "--chamfer", "0.1,0.2", "--tab", "0.1:0.3", "--positions", "0.3", "--keep-edges", "0,3,4,5"),
        inputs={"bracket.dxf": _TUTORIAL_DRAWINGS["bracket.dxf"]},
        pages={"tutorials/own-part.md": ("change_mm", "change_share"),
               "howto/design-for-feeding.md": ("change_mm", "n_pins", "width", "tolerance", "change_share")}),
    "wedge": Stored(
        what="the tutorial's wedge, the default search (with its speed limit)",
        args=("--outline", "wedge.dxf", "--mu-c", "0.2"),
        inputs={"wedge.dxf": _TUTORIAL_DRAWINGS["wedge.dxf"]},
        pages={"tutorials/own-part.md": ("n_pins", "pins_at", "claim_arc", "in_set", "width", "tolerance",
                                         "speed_limit"),
               "explanation/claims.md": ("claim_arc", "in_set", "share_lower_bound", "width"),
               "reference/glossary.md": ("in_set", "tolerance", "share_lower_bound")},
        quoted={"tutorials/own-part.md": (
            "wedge, plan {pins} (mu_c {friction}, mu_s 0.5): speed limit {speed_limit} mm/s "
            "({speed_trials} trials per state)", "wedge, plan 1: {pins} (mu_c {friction})")}),
    "holed_bracket": Stored(
        what="the tutorial's gusset bracket with holes, the default search",
        args=("--outline", "holed_bracket.dxf", "--mu-c", "0.2"),
        inputs={"holed_bracket.dxf": _TUTORIAL_DRAWINGS["holed_bracket.dxf"]},
        pages={"tutorials/own-part.md": ("pins", "n_carried_sets", "carried_sets", "claim_arc", "in_set", "width",
                                           "tolerance")},
        quoted={"tutorials/own-part.md": ("holed_bracket, plan 1: {pins} (mu_c {friction})",)}),
    "first_plan": Stored(
        what="the paper-feeder tutorial's first plan: the default asymmetric triangle at mu_c 0.2",
        args=("--part", "asym_triangle", "--mu-c", "0.2"),
        added=("--out", "plan.json"),
        pages={"tutorials/paper-feeder.md": ("trials", "n_pins", "heights", "in_set", "width", "tolerance")}),
    "small_friction_range": Stored(
        what="the asymmetric triangle over mu_c 0.1:0.3 on the small test config, and its speed limit",
        args=("--part", "asym_triangle", "--mu-c", "0.1:0.3", "--config", SMALL,
              "--out", "results/config/plans/asym_triangle.json"),
        inputs={SMALL: SMALL},
        then=(("speed", "--part", "asym_triangle", "--mu-c", "0.1:0.3", "--config", SMALL),),
        pages={"howto/friction-range.md": ("trials", "speed_limit", "speed_trials")}),
    "small_warp_family": Stored(
        what="the asymmetric triangle for the support family warp:0.3:3 on the small test config",
        args=("--part", "asym_triangle", "--support-family", "warp:0.3:3", "--depth", "3", "--config", SMALL),
        inputs={SMALL: SMALL},
        added=("--out", "plan.json"),
        pages={"howto/support-family.md": ("n_pins", "family_worst_inside", "fresh_members", "fresh_outside")}),
    "family_answer": Stored(
        what="the default asymmetric triangle for tripods:12 over mu_c 0.1:0.3 (moving pins; the nearest yes)",
        args=("--part", "asym_triangle", "--mu-c", "0.1:0.3", "--support-family", "tripods:12"),
        added=("--out", "plan.json"),
        pages={"explanation/support-family-claims.md": (
            "fixed_4_sequences", "fixed_4_nominal_within", "fixed_4_broken_by_known_member", "fixed_4_judged",
            "fixed_4_orienting", "n_moving", "prefix_pins", "moving_pins_described", "pins",
            "family_worst_inside", "claim", "untruncated_width", "fresh_members", "fresh_outside",
            "epsilon", "beta", "nearest_inset", "nearest_friction", "nearest_tolerance")}),
    "shape_tolerance": Stored(
        what="the default asymmetric triangle's plan certified for a 0.2 mm shape tolerance",
        args=("--part", "asym_triangle", "--mu-c", "0.1:0.3", "--shape-tolerance", "0.2"),
        added=("--out", "plan.json"),
        pages={"explanation/support-family-claims.md": (
            "shape_pins", "heights", "verified_set", "tolerance", "shape_set", "shape_verdict", "shape_worst_inside",
            "shape_fresh_outside", "shape_fresh_members", "shape_epsilon", "shape_beta")}),
    "thin_rectangle": Stored(
        what="a long thin rectangle (80 x 16 mm) at mu_c 0.25: the tails cost more",
        args=("--vertices", "0,0 80,0 80,16 0,16", "--mu-c", "0.25"),
        added=("--out", "plan.json"),
        pages={"explanation/claims.md": (
            "pins", "heights", "in_set", "width", "width_interval", "untruncated_in_set",
            "untruncated_share_lower_bound", "untruncated_width", "untruncated_interval", "tolerance")}),
    "small_asym_triangle": Stored(
        what="the asymmetric triangle on the small test config (its own friction 0.15)",
        args=("--part", "asym_triangle", "--config", SMALL),
        inputs={SMALL: SMALL},
        added=("--out", "plan.json"),
        pages={"howto/build-a-feeder.md": ("n_pins", "pins"),
               "howto/support-family.md": ("n_pins",),
               "howto/force-torque-sensor.md": ("pins",)},
        quoted={"howto/build-a-feeder.md": ("asym_triangle, plan 1: {pins} (mu_c {friction})",),
                "howto/support-family.md": ("the recommended plan {pins} (its final set widens from {width} to",),
                "howto/cad-figures-animations.md": ("of asym_triangle: {pins_path}; 3 initial states",),
                "howto/force-torque-sensor.md": ("(sensor plan {pins_arrow})",)}),
    "l_bracket_four_pins": Stored(
        what="the L bracket of the sweep-a-family page with up to four fixed pins (no plan orients it)",
        args=("--part", "l_bracket", "--config", "my_family.yaml", "--depth", "4"),
        inputs={"my_family.yaml": FAMILY},
        added=("--out", "plan.json"),
        pages={"howto/sweep-family.md": ("n_pins", "share")}),
    "right_triangle": Stored(
        what="the right triangle of the sweep-a-family page (the config's depth 3)",
        args=("--part", "right_triangle", "--config", "my_family.yaml"),
        inputs={"my_family.yaml": FAMILY},
        added=("--out", "plan.json"),
        pages={"howto/sweep-family.md": ("n_pins", "width")},
        quoted={"howto/sweep-family.md": (
            "right_triangle fixed pins {n_fixed} {n_moving} {sets_of_tolerance} {width} {in_set}",)}),
    "scalene_plate": Stored(
        what="the scalene plate of the sweep-a-family page (the config's depth 3)",
        args=("--part", "scalene_plate", "--config", "my_family.yaml"),
        inputs={"my_family.yaml": FAMILY},
        added=("--out", "plan.json"),
        pages={"howto/sweep-family.md": ("n_pins", "width")},
        quoted={"howto/sweep-family.md": (
            "scalene_plate fixed pins {n_fixed} {n_moving} {sets_of_tolerance} {width} {in_set}",)}),
}

_PLAN_SUMMARY = (r"^part ", r"^  state \d+:", r"^tight planner", r"^  for every member", r"orient this part",
                 r"^  family ", r"^stored the plan")
_RECOMMENDED = (r"^  #1\b",)  # the first plan listed: the recommended one

#: Stored plans that must be the same plan (pins and heights): the design's chosen
#: change and the plan of the outline it wrote, as the pages say.
SAME_PLAN = (("bracket_design", "bracket_chamfered"),)

#: The console outputs pages include, by file name (``docs/_generated/stored/NAME.txt``).
CONSOLES: dict[str, Console] = {
    "small_friction_range.plan": Console(
        "small_friction_range", _PLAN_SUMMARY + (r"^next: ",), ("howto/friction-range.md",),
        blocks=_RECOMMENDED),
    "small_friction_range.speed": Console(
        "small_friction_range", (r"speed limit", r"^ +\d+\.\d mm/s:"), ("howto/friction-range.md",), run=1),
    "small_warp_family.plan": Console("small_warp_family", _PLAN_SUMMARY, ("howto/support-family.md",),
                                      blocks=_RECOMMENDED),
    "l_bracket_four_pins.plan": Console(
        "l_bracket_four_pins", (r"^part ", r"^  no fixed-pin sequence", r"^this plan does not orient",
                                r"^  moving pins", r"^  more pins", r"^      pinfeed plan"),
        ("howto/sweep-family.md",), blocks=_RECOMMENDED),
    "bracket_design.design": Console(
        "bracket_design", (r"^  \.\.\. original ", r"changes within the limits", r"^  \.\.\. \[\d+/\d+\]",
                           r"^bracket: ", r"^smallest change", r"^plan: ", r"^held-out verdict"),
        ("howto/design-for-feeding.md",)),
    "wedge.recommended": Console("wedge", (), ("explanation/claims.md",), blocks=_RECOMMENDED, command=False),
}


# --------------------------------------------------------------------------- reading

def path_of(name: str) -> Path:
    return PLANS / f"{name}.json"


def load(name: str) -> dict:
    """A stored plan file (``docs/plans/NAME.json``)."""
    return json.loads(path_of(name).read_text())


def command_line(entry: Stored) -> str:
    """The page's command, as a shell line."""
    return f"pinfeed {entry.verb} " + shlex.join(entry.args)


def values(stored: dict) -> dict:
    """The numbers of a stored file, as pages quote them (``plan_numbers``)."""
    import plan_numbers
    if stored.get("verb", "plan") == "design":
        return plan_numbers.design_numbers(stored["plan"])
    return plan_numbers.numbers(stored["plan"])


def console_text(console: Console, stored: dict) -> str:
    """What a page shows of a stored command's output: the command as it was run
    and the printed lines ``console.show`` and ``console.blocks`` select,
    ``...`` for the lines left out."""
    patterns = [re.compile(p) for p in console.show]
    blocks = [re.compile(p) for p in console.blocks]
    run = stored["runs"][console.run]
    out = ["$ " + shlex.join(run["argv"])] if console.command else []
    skipped, block = False, None

    def indent(line):
        return len(line) - len(line.lstrip())
    for line in run["printed"]:
        if block is not None and line.strip() and indent(line) <= block:
            block = None
        if any(p.search(line) for p in blocks):
            block = indent(line)
            shown = True
        else:
            shown = block is not None or any(p.search(line) for p in patterns)
        if shown:
            if skipped:
                out.append("...")
            out.append(line)
            skipped = False
        else:
            skipped = True
    if skipped:
        out.append("...")
    return "\n".join(out) + "\n"


def write_generated() -> dict:
    """Every stored file's numbers (for ``{{ stored.NAME.KEY }}``), and the console
    includes written to ``docs/_generated/stored/``; a missing file is an error."""
    missing = [name for name in REGISTRY if not path_of(name).is_file()]
    if missing:
        raise RuntimeError(f"stored plans missing: {', '.join(f'docs/plans/{n}.json' for n in missing)}; "
                           f"run 'python docs/_ext/stored_plans.py refresh {' '.join(missing)}'")
    stored = {name: load(name) for name in REGISTRY}
    shutil.rmtree(GENERATED, ignore_errors=True)
    GENERATED.mkdir(parents=True)
    for file, console in CONSOLES.items():
        (GENERATED / f"{file}.txt").write_text(console_text(console, stored[console.plan]))
    return {name: values(s) for name, s in stored.items()}


# --------------------------------------------------------------------------- making

def source_hash() -> str:
    """Hash of the code a stored plan depends on (as ``default_run.cache_key``,
    without the docs' own files and the library versions)."""
    digest = hashlib.sha256()
    files = [p for folder, pattern in SOURCES for p in (ROOT / folder).rglob(pattern)]
    for path in sorted(set(files + [ROOT / "pyproject.toml"])):
        if "__pycache__" in path.parts:
            continue
        digest.update(str(path.relative_to(ROOT)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()


def code_version() -> dict:
    """The commit, whether the code differs from it, and the code's hash."""
    changed = _git("status", "--porcelain", "--", "pipeline", "kernels", "config", "pyproject.toml")
    from pipeline import __version__
    return {"git_commit": _git("rev-parse", "HEAD"), "code_differs_from_commit": bool(changed),
            "pinfeed_version": __version__, "source_hash": source_hash()}


def _trim(node):
    if isinstance(node, dict):
        return {k: _trim(v) for k, v in node.items() if k not in DROPPED}
    if isinstance(node, list):
        return [_trim(v) for v in node]
    return node


def _not_recommended_dropped(plan: dict) -> dict:
    """The tight entries' ``plans`` cut to the recommended plan."""
    for entry in plan.get("tight") or ():
        rec = entry.get("recommended")
        entry["plans"] = [p for p in entry.get("plans") or () if p == rec]
    return plan


def _run(argv: list[str], folder: Path, env: dict) -> list[str]:
    """Run one pinfeed command in ``folder``; what it printed (stdout and stderr in
    order), or an error with its last lines."""
    proc = subprocess.run([sys.executable, "-m", "pipeline.cli", *argv], cwd=folder, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = proc.stdout.splitlines()
    if proc.returncode != 0:
        raise RuntimeError(f"pinfeed {shlex.join(argv)} failed ({proc.returncode}):\n" + "\n".join(lines[-30:]))
    return lines


def _plan_path(entry: Stored, printed: list[str], folder: Path) -> Path:
    """Where the run's plan file (or design file) is."""
    args = list(entry.args + entry.added)
    if entry.verb == "design":      # RESULTS/designs/NAME.json, or --out DIR/NAME.json
        pattern = f"{args[args.index('--out') + 1]}/*.json" if "--out" in args else "**/designs/*.json"
        found = sorted(folder.glob(pattern))
        if len(found) != 1:
            raise RuntimeError(f"expected one design file, found {found}")
        return found[0]
    if "--out" in args:
        return folder / args[args.index("--out") + 1]
    for line in printed:
        if line.startswith("stored the plan at "):
            return folder / line.removeprefix("stored the plan at ").strip()
    raise RuntimeError("the command did not store its plan: add --out to the entry's 'added'")


def refresh(name: str, log=print) -> Path:
    """Run the entry's commands in a scratch folder (empty catalog) and write
    ``docs/plans/NAME.json`` atomically."""
    entry = REGISTRY[name]
    PLANS.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=f"{ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
               MPLBACKEND="Agg", PYTHONUNBUFFERED="1", **RUN_ENV)
    with tempfile.TemporaryDirectory(prefix=f"stored-{name}-") as tmp:
        folder = Path(tmp)
        inputs = {}
        for local, repo_path in entry.inputs.items():
            (folder / local).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(ROOT / repo_path, folder / local)
            inputs[local] = {"from": repo_path,
                             "sha256": hashlib.sha256((ROOT / repo_path).read_bytes()).hexdigest()}
        version = code_version()
        start = time.monotonic()
        runs = []
        plan_argv = [entry.verb, *entry.args, *entry.added]
        log(f"{name}: pinfeed {shlex.join(plan_argv)}")
        printed = _run(plan_argv, folder, env)
        runs.append({"argv": ["pinfeed", *plan_argv], "shown": command_line(entry), "printed": printed})
        plan_path = _plan_path(entry, printed, folder)
        for then in entry.then:
            log(f"{name}: pinfeed {shlex.join(then)}")
            runs.append({"argv": ["pinfeed", *then], "shown": "pinfeed " + shlex.join(then),
                         "printed": _run(list(then), folder, env)})
        seconds = time.monotonic() - start
        plan = json.loads(plan_path.read_text())
        stored = {"name": name, "what": entry.what, "verb": entry.verb,
                  "args": list(entry.args), "added_args": list(entry.added),
                  "then": [list(t) for t in entry.then], "inputs": inputs, "env": RUN_ENV,
                  "command": command_line(entry),
                  "made": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
                  "code": version, "machine": f"{platform.machine()}, {os.cpu_count()} cores, "
                                              f"Python {platform.python_version()}",
                  "seconds": round(seconds, 1), "runs": runs, "trimmed": [], "plan": plan}
        text = json.dumps(stored, indent=1, sort_keys=False, default=float)
        if len(text) > KEEP_WHOLE_BYTES and entry.verb == "plan":
            stored["plan"] = _trim(_not_recommended_dropped(plan))
            stored["trimmed"] = ["tight[].plans other than the recommended plan", *DROPPED]
            text = json.dumps(stored, indent=1, sort_keys=False, default=float)
        target = path_of(name)
        partial = target.with_suffix(".json.partial")
        partial.write_text(text + "\n")
        os.replace(partial, target)
    log(f"{name}: wrote {target.relative_to(ROOT)} ({len(text) // 1000} kB) in {seconds:.0f} s")
    return target


def status() -> list[str]:
    """One line per registry entry: missing, or made from which code."""
    current = source_hash()
    out = []
    for name in REGISTRY:
        if not path_of(name).is_file():
            out.append(f"{name}: missing")
            continue
        code = load(name)["code"]
        same = code["source_hash"] == current and not code["code_differs_from_commit"]
        out.append(f"{name}: made {load(name)['made']} at {code['git_commit'][:9]}"
                   + ("" if same else " (other code than this checkout's: refresh it)"))
    return out


def main(argv: list[str]) -> int:
    if argv[:1] == ["refresh"]:
        names = argv[1:] or list(REGISTRY)
        unknown = [n for n in names if n not in REGISTRY]
        if unknown:
            print(f"unknown stored plan(s): {', '.join(unknown)}; known: {', '.join(REGISTRY)}")
            return 2
        for name in names:          # one after another: some take minutes
            refresh(name)
        return 0
    if argv[:1] == ["list"]:
        print("\n".join(status()))
        return 0
    print(__doc__.split("\n\n")[0] + "\n\nusage: python docs/_ext/stored_plans.py refresh [NAME ...] | list")
    return 2


if __name__ == "__main__":
    sys.path[:0] = [str(ROOT), str(Path(__file__).resolve().parent)]
    sys.exit(main(sys.argv[1:]))
