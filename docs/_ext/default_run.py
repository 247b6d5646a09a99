"""The default plans, as the manual shows them, computed by the docs build.

Every number the manual gives about the default config's plans (the pins,
the final set's width, the trials in it, the belt's speed limit, the belt
speed, the throughput) and the figures of them (the front page's feeder
drawing, a frame of the feeder's animation) come from this module, run at
the start of each docs build by ``docs/conf.py``. Nothing about the default
plans is copied by hand into a page: pages write ``{{ plans.asym_triangle.pins }}``
(a MyST substitution) or include a generated file.

For each part of ``planner.parts`` of the embedded default config it does
what a user does after ``make run``, with the same functions:

1. ``pinfeed plan --part NAME`` (the maps it needs are computed on the
   fly into a scratch catalog: the same grid as the workflow's shards);
2. the speed stage (``pipeline.workflow.speed.speed``: the speed limit);
3. the layout stage (``pipeline.workflow.layout.layout``: stations, belt
   speed, pitch, throughput, the drawing);
4. a still of the laid-out feeder's animation (the parts in mid-stream),
   and the recommended plan's pin-sequence figure (the part's nominal path
   past the pins, as the report draws it);

then the atlas of the parts (``pipeline.workflow.atlas.atlas``) and what
``pinfeed atlas`` prints of it. The parts run side by side, one process each.

The work takes a few minutes, so its results are kept in
``docs/_generated/cache/KEY/``, where KEY hashes everything the results
depend on: the source of ``pipeline/`` and ``kernels/``, ``config/``,
``pyproject.toml``, this file, and the versions of Python, NumPy, Numba and
SciPy. A build with the same key reuses them; any change to the code makes a
new key, so the manual never shows results of other code. The files a page
uses are copied to ``docs/_generated/`` (``default_run.json``,
``feeder_NAME.png``, ``frame_NAME.png``, ``sequence_NAME.png``,
``carried_NAME.png``, ``atlas.txt``, ``plans_by_friction.md``).

The README cannot run code, so it shows a committed copy of the front-page
drawing, ``docs/feeder_asym_triangle.png``, which records its plan in the
PNG's ``pinfeed-plan`` text field; ``tests/docs/test_front_page.py`` fails
when that plan differs from the one this build computed.
``make readme-figure`` copies the fresh drawing there.

Run by hand: ``python docs/_ext/default_run.py`` (all parts, prints the
folder), or ``python docs/_ext/default_run.py part NAME FOLDER`` (one part).
"""
from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GENERATED = ROOT / "docs" / "_generated"
SOURCES = (("pipeline", "*.py"), ("pipeline", "*.json"), ("kernels", "*.py"), ("config", "*.yaml"))
#: The PNG text field holding the drawing's plan (pins, space-separated).
PLAN_FIELD = "pinfeed-plan"


def cache_key() -> str:
    """Hash of everything the default plans depend on (see the module's notes)."""
    import numba
    import numpy
    import scipy
    digest = hashlib.sha256()
    files = [p for folder, pattern in SOURCES for p in (ROOT / folder).rglob(pattern)]
    files += [ROOT / "pyproject.toml", Path(__file__).resolve()]
    for path in sorted(set(files)):
        if "__pycache__" in path.parts:
            continue
        digest.update(str(path.relative_to(ROOT)).encode() + b"\0" + path.read_bytes() + b"\0")
    versions = (platform.python_version(), numpy.__version__, numba.__version__, scipy.__version__)
    digest.update(" ".join(versions).encode())
    return digest.hexdigest()[:16]


def default_run(log=print) -> dict:
    """The default plans' summary (``default_run.json``), computing it unless the
    cache holds it for this code, and the page files copied to ``docs/_generated/``."""
    key = cache_key()
    cached = GENERATED / "cache" / key
    if not (cached / "default_run.json").is_file():
        log(f"pinfeed docs: computing the default plans for the manual (cache key {key}); "
            "this takes a few minutes once per code change")
        start = time.monotonic()
        _compute(cached)
        log(f"pinfeed docs: default plans computed in {time.monotonic() - start:.0f} s")
    summary = json.loads((cached / "default_run.json").read_text())
    for name in ["default_run.json", "atlas.txt", "plans_by_friction.md", *summary["figures"]]:
        shutil.copyfile(cached / name, GENERATED / name)
    return summary


def _compute(target: Path) -> None:
    """Plan, speed, layout and still of every default part (a process each), then
    the atlas; written to a scratch folder and renamed to ``target`` at the end."""
    from pipeline.config import load_config
    names = list(load_config(None)["planner"]["parts"])
    target.parent.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="work-", dir=target.parent))
    env = dict(os.environ, PYTHONPATH=f"{ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
               MPLBACKEND="Agg", NUMBA_NUM_THREADS="1")
    jobs = [(name, subprocess.Popen([sys.executable, __file__, "part", name, str(work)], env=env, cwd=work,
                                    stdout=open(work / f"{name}.log", "w"), stderr=subprocess.STDOUT))
            for name in names]
    for name, job in jobs:
        if job.wait() != 0:
            tail = "".join((work / f"{name}.log").read_text().splitlines(True)[-30:])
            raise RuntimeError(f"computing the default plan of {name} for the manual failed "
                               f"(log {work / f'{name}.log'}):\n{tail}")
    _summarise(names, work)
    shutil.rmtree(target, ignore_errors=True)
    os.replace(work, target)
    # Results of other code are never used again: keep the cache to this key.
    for old in target.parent.iterdir():
        if old != target and not old.name.startswith("work-"):
            shutil.rmtree(old, ignore_errors=True)


def run_part(name: str, work: Path) -> None:
    """Plan, speed limit, layout, drawing and animation still of one default part."""
    import matplotlib.pyplot as plt

    from pipeline.config import load_config
    from pipeline.maps.io import write_json
    from pipeline.planning import station_scene
    from pipeline.present.animate import station_figure, station_title
    from pipeline.present.figures.feeder import feeder_figure
    from pipeline.workflow.commands import named_part, plan_command, planner_settings
    from pipeline.workflow.layout import layout
    from pipeline.workflow.report import carried_figure
    from pipeline.workflow.speed import speed
    from tutorial_figures import checked
    config = planner_settings(load_config(None), catalog=str(work / "catalog"))
    part = named_part(config, name)
    plan_path = work / "plans" / f"{name}.json"
    plan_path.parent.mkdir(parents=True, exist_ok=True)
    write_json(plan_command(part, config, "tight", progress=print), plan_path)
    result = json.loads(plan_path.read_text())  # as the later stages read it
    tight = result["tight"][0]
    _sequence_png(part, tight, result["model"], config, work / f"sequence_{name}.png")
    # The report's figure reads the resting states at the top of a plan file;
    # a tight-only plan keeps them with its tight plans.
    carried_figure(config, dict(result, initial_states=tight["initial_states"]), work / f"carried_{name}.png")
    speed(plan_path, config, work / "speed" / f"{name}.json", work / "speed" / f"{name}.png")
    drawings = {k: work / f"layout_{name}.{k}" for k in ("dxf", "svg", "png")}
    print(layout(plan_path, config, dict(drawings, json=work / f"layout_{name}.json")))
    feeder = json.loads((work / f"layout_{name}.json").read_text())
    if not feeder.get("stations"):
        return
    fig = checked(feeder_figure(feeder), f"the feeder drawing of {name}")
    fig.savefig(work / f"feeder_{name}.png", dpi=110,
                metadata={PLAN_FIELD: " ".join(feeder["plan"]["pins"]), "Software": "pinfeed"})
    plt.close(fig)
    scene = station_scene(part, feeder, _states(tight), feeder["mu_c"])
    still = station_figure(scene, station_title(name, scene, "the laid-out feeder"))
    still["draw"](0.55 * scene.b_end)   # mid-stream: parts before, at and after the pins
    checked(still["fig"], f"the animation still of {name}").savefig(work / f"frame_{name}.png", dpi=110)
    plt.close(still["fig"])


def _sequence_png(part, tight: dict, model: str, config: dict, out: Path) -> None:
    """The recommended plan as the report's pin-sequence figure: one row per
    resting state, the part's nominal path past the pins (a rollout per pin and
    state) at the middle of the planned friction range."""
    import matplotlib.pyplot as plt

    from pipeline.maps.simulate import nominal_path
    from pipeline.planning import Friction
    from pipeline.present.figures.sequence import sequence_figure
    from pipeline.workflow.report import tight_plan_pins
    from tutorial_figures import checked
    plan = tight.get("recommended")
    if not plan:
        return
    pins, speeds = tight_plan_pins(plan)
    planned = Friction.parse(tight["mu_c"])
    mu_c = planned.nominal
    where = (f"the middle of the planned range {planned.lo:g}-{planned.hi:g}" if planned.is_range
             else "the planned friction")
    paths = {label: nominal_path(part, theta, y_c, plan["pin_heights_mm"], mu_c, config["sweep"]["pin_radius"],
                                 model, [speeds.get(p, 0.0) for p in plan["pins"]])
             for label, (theta, y_c) in _states(tight).items()}
    fig = sequence_figure(part, plan, pins, paths, config["sweep"]["pin_radius"],
                          f"{part.name}: recommended plan; nominal paths at $\\mu_c$ = {mu_c:g}, {where}",
                          speeds=speeds)
    checked(fig, f"the pin sequence of {part.name}")
    fig.savefig(out, dpi=110, metadata={PLAN_FIELD: " ".join(plan["pins"]), "Software": "pinfeed"})
    plt.close(fig)


def _states(tight: dict) -> dict:
    """The tight plans' initial (resting) states: label -> (theta deg, y_c mm)."""
    return {label: (s["theta"], s["y_c"]) for label, s in tight["initial_states"].items()}


def _summarise(names: list[str], work: Path) -> None:
    """The atlas of the parts, what ``pinfeed atlas`` prints, and default_run.json."""
    from pipeline.config import load_config
    from pipeline.provenance import provenance_attrs
    from pipeline.workflow.atlas import atlas
    config = load_config(None)
    rows = atlas(config, [work / "plans" / f"{n}.json" for n in names],
                 [work / "speed" / f"{n}.json" for n in names],
                 [work / f"layout_{n}.json" for n in names], work / "atlas.json", work / "atlas.csv")
    printed = subprocess.run([sys.executable, "-m", "pipeline.cli", "atlas", "--results", str(work)],
                             capture_output=True, text=True, check=True, cwd=ROOT).stdout
    (work / "atlas.txt").write_text(printed.replace(str(work), "results/config"))
    (work / "plans_by_friction.md").write_text(_friction_table(names, work))
    parts = {row["part"]: _numbers(row, work) for row in rows["rows"]}
    kinds = ("feeder_", "frame_", "sequence_", "carried_")
    figures = sorted(p.name for p in work.glob("*.png") if p.name.startswith(kinds))
    summary = {"what": "the default config's plans, computed by the docs build (docs/_ext/default_run.py)",
               "provenance": provenance_attrs(), "machine": _machine(),
               "parts": parts, "figures": figures}
    (work / "default_run.json").write_text(json.dumps(summary, indent=1, sort_keys=True, default=float))


def _friction_table(names: list[str], work: Path) -> str:
    """A Markdown table of each part's recommended plan at the planner's friction
    range and at each planned friction, with its held-out verdict."""
    from pipeline.present.figures.tables import markdown_table
    rows = []
    for name in names:
        for entry in json.loads((work / "plans" / f"{name}.json").read_text())["tight"]:
            plan = entry.get("recommended")
            if plan is None:
                rows.append([name, entry["friction"], f"none: {entry.get('warning', 'no plan')}", "", ""])
                continue
            verdict = plan["verification"]["orientation"]
            pins = ", ".join(f"{p} {h:g}" for p, h in zip(plan["pins"], plan["pin_heights_mm"]))
            rows.append([name, entry["friction"], pins, f"{verdict['width_deg']:.1f} deg",
                         f"{verdict['in_tolerance']}/{verdict['trials']}"])
    return markdown_table(rows, ["part", "mu_c", "recommended plan (pin heights, mm)", "verified width",
                                 "trials in one set within the tolerance"])


def _numbers(row: dict, work: Path) -> dict:
    """The numbers a page may quote of one part, formatted as pages show them."""
    feeder = json.loads((work / f"layout_{row['part']}.json").read_text())
    stations = feeder.get("stations") or []

    def fmt(value, spec):
        return "-" if value is None else format(value, spec)
    return {
        "outcome": row["outcome"], "pins": row["plan"] or "-",
        "n_pins": (row["fixed_pins"] or 0) + (row["moving_pins"] or 0),
        "heights": ", ".join(f"{s['y_mm']:g}" for s in stations),
        "friction": row["mu_c"], "width": fmt(row["verified_width_deg"], ".1f"),
        "in_set": f"{row['in_set']}/{row['trials']}" if row.get("in_set") is not None else "-",
        "share_lower_bound": fmt(100 * row["share_lower_bound"] if row.get("share_lower_bound") is not None
                                 else None, ".2f"),
        "speed_limit": fmt(row["speed_limit_mm_s"], ".0f"), "belt_speed": fmt(row["belt_speed_mm_s"], ".0f"),
        "throughput": fmt(row["throughput_per_min"], ".0f"), "pitch": fmt(feeder.get("pitch_mm"), ".0f"),
        "belt_width": fmt(feeder.get("belt_width_mm"), ".0f"),
        "planning_seconds": fmt(row["planning_seconds"], ".0f"),
        **_untruncated_numbers(work / "plans" / f"{row['part']}.json", fmt),
    }


def _untruncated_numbers(plan_path: Path, fmt) -> dict:
    """The recommended plan's replay on untruncated normals, formatted as pages show it."""
    stored = json.loads(plan_path.read_text()) if plan_path.exists() else {}
    tight = stored.get("tight") or [{}]
    u = ((tight[0].get("recommended") or {}).get("verification") or {}).get("untruncated") or {}
    iv = u.get("width_interval_deg") or [None, None]
    return {"untruncated_in_set": f"{u['in_one_set']}/{u['trials']}" if u else "-",
            "untruncated_width": fmt(u.get("width_deg"), ".1f"),
            "untruncated_interval": "-" if None in iv else f"{iv[0]:.1f}-{iv[1]:.1f}",
            "untruncated_orients": "-" if not u else ("orients" if u["orients"] else "does not orient")}


def _machine() -> str:
    """The machine in words: processor, cores, Python."""
    return (f"{platform.machine()}, {os.cpu_count()} cores, {platform.system()}, "
            f"Python {platform.python_version()}")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    if len(sys.argv) == 4 and sys.argv[1] == "part":
        run_part(sys.argv[2], Path(sys.argv[3]))
    else:
        GENERATED.mkdir(parents=True, exist_ok=True)
        default_run()
        print(GENERATED)
