"""Plan real-looking CAD parts and measure their rollout rates: the corpus of ``benchmarks/corpus``.

For each drawing (``benchmarks/corpus/*.dxf`` and ``*.svg``, or the files or
``--parts`` glob given) it records the outline's vertex count after
flattening (outline and holes), its size, and:

* the rollout rate: rollouts per second of ``pipeline.maps.simulate.compute_map``
  on one thread over a fixed grid (90 theta_i every 4 deg x 6 d values,
  mu_c 0.2, pin radius 3 mm, the minpower model), after a warm-up call, best
  of ``--repeat``; the default triangle (0,0) (60,0) (15,35) is timed in the
  same run, so each part's rate is also given as a ratio to the triangle's;
* unless ``--only-speed``: the answer of ``pinfeed plan --outline F --mu-c 0.2
  --json``, each part in its own subprocess (``python -m pipeline.cli`` of this
  checkout) with an empty catalog of its own, so maps are computed afresh:
  orients with N fixed pins, with moving pins, a sensor must finish, or no
  plan; and the nearest "yes" the planner gives when the answer is no. With
  ``--time-limit S`` the planner gets ``--time-limit S`` when ``pinfeed plan
  --help`` lists that option (and is killed 60 s after S if it overruns);
  otherwise it runs without it and is killed after S seconds of wall time,
  recorded as "timeout". A plan cut short by its time limit (``"complete":
  false`` in the JSON) is recorded as "not complete", with what was left
  unsearched. Each subprocess's wall time and CPU time (user +
  system, its own and its children's, from ``os.wait4``: the per-child form
  of the ``getrusage(RUSAGE_CHILDREN)`` delta) are recorded.

It prints a Markdown table (for the docs' performance page) and a summary
line (median and worst wall time), and writes a JSON record (date, machine:
platform, CPU count, load average before and after; git commit and whether
the tree had changes; settings; the rows) to ``--record`` (default
``benchmarks/records/real_parts_DATE.json``)::

    .venv/bin/python benchmarks/real_parts.py --only-speed              # rates only, whole corpus (minutes)
    .venv/bin/python benchmarks/real_parts.py --time-limit 600          # plan every part (hours)
    .venv/bin/python benchmarks/real_parts.py --time-limit 120 --parts 'benchmarks/corpus/l_bracket*'
    .venv/bin/python benchmarks/real_parts.py --time-limit 120 FILE.dxf FILE.svg --record OUT.json

``--jobs N`` plans N parts at a time (the default, 1, keeps the wall times
comparable; rates are always measured alone, before any planning).
"""
from __future__ import annotations

import argparse
import datetime
import glob
import json
import os
import platform
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

# The checkout this script lives in, not whichever pinfeed the environment
# has installed (an editable install of another worktree would win otherwise).
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pipeline.maps import simulate  # noqa: E402
from pipeline.parts.outlines import read_outline  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402

CORPUS = ROOT / "benchmarks" / "corpus"
RECORDS = ROOT / "benchmarks" / "records"
TRIANGLE = [(0, 0), (60, 0), (15, 35)]
THETA = np.arange(0.0, 360.0, 4.0)  # 90 theta_i
D = [-0.75, -0.45, -0.15, 0.15, 0.45, 0.75]  # 6 d values (fractions, as the paper's d grid)
MU_C = 0.2
PIN_RADIUS = 3.0
MODEL = "minpower"
GRACE_S = 60.0  # how long past --time-limit a planner that honours it may run before it is killed


def pinfeed_cmd() -> list[str]:
    """The ``pinfeed`` command of this checkout."""
    return [sys.executable, "-m", "pipeline.cli"]


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def planner_has_time_limit() -> bool:
    """Whether ``pinfeed plan --help`` lists ``--time-limit``."""
    out = subprocess.run(pinfeed_cmd() + ["plan", "--help"], capture_output=True, text=True, env=_env(),
                         cwd=ROOT, timeout=120)
    return "--time-limit" in out.stdout


def describe(path: Path) -> dict:
    """Vertex counts after flattening (default tolerance), holes and size of a drawing."""
    out = read_outline(path)
    w, h, a = out.size_mm
    return {"file": _rel(path), "outline_vertices": out.n_vertices, "holes": len(out.holes),
            "hole_vertices": [int(len(x)) for x in out.holes], "width_mm": round(w, 2), "height_mm": round(h, 2),
            "a_mm": round(a, 2), "flatten_tol_mm": round(out.flatten_tol, 4),
            "part": Part.from_vertices(out.vertices, name=path.stem, holes=out.holes)}


def _rel(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


def rollout_rate(part: Part, repeat: int) -> float:
    """Rollouts per second (wall time, one thread) over the fixed grid, best of ``repeat``."""
    simulate.compute_map(part, THETA[:2], D[:1], MU_C, PIN_RADIUS, model=MODEL, threads=1)  # warm-up
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        simulate.compute_map(part, THETA, D, MU_C, PIN_RADIUS, model=MODEL, threads=1)
        best = min(best, time.perf_counter() - t0)
    return THETA.size * len(D) / best


def answer(doc: dict) -> tuple[str, str | None]:
    """The planner's answer from ``plan --json``, and its nearest "yes" in a few words (or None)."""
    rec = doc.get("recommended")
    if doc.get("orients"):
        pins = rec["pins"] if rec else []
        if any("v" in p for p in pins):  # moving pins are labelled like P23v-2
            text = f"orients with {len(pins)} pins, moving ones among them"
        else:
            text = f"orients with {len(pins)} fixed pin{'s' if len(pins) != 1 else ''}"
    elif rec:
        sets = rec["carried_sets"]["n_sets"] if "carried_sets" in rec else rec["n_final_sets"]  # older JSON
        text = f"sensor: {len(rec['pins'])} pins end in {sets} sets"
    else:
        text = "no plan"
    near = doc.get("nearest_yes")
    nearest = None
    if near:
        found = [a for a in near.get("axes", []) if a.get("found")]
        nearest = "; ".join(f"{a['axis']}: {a['statement']}" for a in found) or "none found"
    return text, nearest


def plan(path: Path, time_limit: float | None, has_limit: bool) -> dict:
    """Plan one part in its own subprocess; answer, wall and CPU time."""
    with tempfile.TemporaryDirectory(prefix="real_parts_") as tmp:
        cmd = pinfeed_cmd() + ["plan", "--outline", str(path), "--mu-c", str(MU_C), "--json",
                               "--catalog", str(Path(tmp) / "catalog"), "--out", str(Path(tmp) / "plan.json")]
        budget = None
        if time_limit is not None:
            if has_limit:
                cmd += ["--time-limit", f"{time_limit:g}"]
                budget = time_limit + GRACE_S
            else:
                budget = time_limit
        out_path, err_path = Path(tmp) / "stdout", Path(tmp) / "stderr"
        with open(out_path, "w") as out, open(err_path, "w") as err:
            t0 = time.perf_counter()
            proc = subprocess.Popen(cmd, stdout=out, stderr=err, env=_env(), cwd=tmp, start_new_session=True)
            killed = False
            try:
                while True:
                    pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
                    if pid:
                        break
                    if budget is not None and time.perf_counter() - t0 > budget and not killed:
                        os.killpg(proc.pid, signal.SIGKILL)  # the planner and any workers it started
                        killed = True
                    time.sleep(0.2)
            except BaseException:  # interrupted: leave no planner running in its own session
                os.killpg(proc.pid, signal.SIGKILL)
                raise
            wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here: keep Popen from waiting again
        row = {"wall_s": round(wall, 2), "cpu_s": round(usage.ru_utime + usage.ru_stime, 2),
               "max_rss_mb": round(usage.ru_maxrss / 1024, 1), "returncode": proc.returncode,
               "command": f"pinfeed plan --outline {path.name} --mu-c {MU_C:g} --json"
                          + (f" --time-limit {time_limit:g}" if has_limit and time_limit else "")}
        if killed:
            row.update(status="timeout", answer=f"timeout (killed after {budget:g} s)", nearest_yes=None)
            return row
        text = out_path.read_text()
        try:
            doc = json.loads(text)
        except json.JSONDecodeError:
            last = (err_path.read_text().strip().splitlines() or ["no output"])[-1]
            row.update(status="error", answer=f"error: {last[:200]}", nearest_yes=None)
            return row
        row["status"] = "ok" if doc.get("complete", True) else "not complete"
        row["answer"], row["nearest_yes"] = answer(doc)
        if not doc.get("complete", True):
            row["answer"] += " (search not complete within the time limit)"
        row["plan_json"] = {k: doc.get(k) for k in ("orients", "pins_used", "warning", "nearest_yes",
                                                    "time_limit_s", "complete", "unsearched")
                            if k in doc}
        if doc.get("recommended"):
            row["plan_json"]["recommended_pins"] = doc["recommended"]["pins"]
        return row


def git_state() -> dict:
    def git(*args):
        r = subprocess.run(["git", *args], capture_output=True, text=True, cwd=ROOT)
        return r.stdout.strip() if r.returncode == 0 else None
    status = git("status", "--porcelain", "--untracked-files=no")
    return {"commit": git("rev-parse", "HEAD"), "tree_has_changes": bool(status) if status is not None else None}


def machine() -> dict:
    return {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
            "node": platform.node(), "python": platform.python_version(), "nproc": os.cpu_count(),
            "usable_cpus": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
            "load_average": [round(x, 2) for x in os.getloadavg()]}


def files_from(args) -> list[Path]:
    if args.files:
        return [Path(f).resolve() for f in args.files]
    pattern = args.parts or str(CORPUS / "*")
    found = sorted(glob.glob(pattern))
    return [Path(f).resolve() for f in found if f.lower().endswith((".dxf", ".svg"))]


def table(rows, tri_rate, planned: bool) -> str:
    head = ("| part | vertices (outline + holes) | holes | size (mm) | rollouts/s (1 thread) | vs triangle |"
            + (" answer | nearest yes | wall (s) | CPU (s) |" if planned else ""))
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    lines.append(f"| default triangle | 3 | 0 | 60 x 35 | {tri_rate:,.0f} | 1.00 |"
                 + (" | | | |" if planned else ""))
    for r in rows:
        hv = sum(r["hole_vertices"])
        line = (f"| {Path(r['file']).name} | {r['outline_vertices']} + {hv} | {r['holes']} | "
                f"{r['width_mm']:g} x {r['height_mm']:g} | {r['rollouts_per_s']:,.0f} | "
                f"{r['rollouts_per_s'] / tri_rate:.2f} |")
        if planned:
            p = r.get("plan") or {}
            line += (f" {p.get('answer', '')} | {p.get('nearest_yes') or ''} | {p.get('wall_s', '')} | "
                     f"{p.get('cpu_s', '')} |")
        lines.append(line)
    return "\n".join(lines)


def arguments(argv=None) -> tuple:
    """The command line: ``(parser, parsed arguments)``."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="*", help="drawings to run (default: the corpus, or --parts)")
    ap.add_argument("--parts", metavar="GLOB", help="a glob of drawings (default: benchmarks/corpus/*)")
    ap.add_argument("--time-limit", type=float, metavar="S",
                    help="seconds per part: passed to pinfeed plan --time-limit when it has it, else the "
                         "wall budget after which the planner is killed (default: no limit)")
    ap.add_argument("--jobs", type=int, default=1, help="parts planned at a time (default 1)")
    ap.add_argument("--only-speed", action="store_true", help="rollout rates only, no planning")
    ap.add_argument("--repeat", type=int, default=2, help="rollout rate: best of N timings (default 2)")
    ap.add_argument("--record", type=Path, help="JSON record to write (default: "
                    "benchmarks/records/real_parts_DATE.json; '-' for none)")
    ap.add_argument("--label", default="", help="a word for the record (e.g. baseline)")
    return ap, ap.parse_args(argv)


def rate_rows(files, repeat: int) -> tuple:
    """The triangle's rollout rate and one row per drawing (its outline and
    its rollout rate, also as a share of the triangle's), printing each:
    ``(triangle rate, rows)``."""
    tri = Part.from_vertices(TRIANGLE, name="triangle")
    tri_rate = rollout_rate(tri, repeat)
    rows = []
    for path in files:
        info = describe(path)
        part = info.pop("part")
        info["rollouts_per_s"] = round(rollout_rate(part, repeat), 1)
        info["vs_triangle"] = round(info["rollouts_per_s"] / tri_rate, 3)
        rows.append(info)
        print(f"  {path.name}: {info['outline_vertices']} + {sum(info['hole_vertices'])} vertices, "
              f"{info['rollouts_per_s']:,.0f} rollouts/s ({info['vs_triangle']:.2f} x triangle)", flush=True)
    return tri_rate, rows


def plan_rows(files, rows, time_limit, jobs: int) -> bool:
    """Plan every drawing (``jobs`` at a time), printing each answer, into
    its row's ``plan``; returns whether ``pinfeed plan`` has ``--time-limit``."""
    has_limit = planner_has_time_limit()
    print(f"pinfeed plan --time-limit: {'passed' if has_limit else 'not available: wall budget, then kill'}",
          flush=True)

    def one(k):
        r = plan(files[k], time_limit, has_limit)
        print(f"  {files[k].name}: {r['answer']} ({r['wall_s']} s wall, {r['cpu_s']} s CPU)", flush=True)
        return r
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        for row, result in zip(rows, pool.map(one, range(len(files)))):
            row["plan"] = result
    return has_limit


def plan_summary(rows) -> str:
    """The planning runs in one line: median and worst wall time, parts
    killed at the wall budget and stopped incomplete by the time limit."""
    walls = [r["plan"]["wall_s"] for r in rows]
    worst = max(rows, key=lambda r: r["plan"]["wall_s"])
    n_timeout = sum(r["plan"]["status"] == "timeout" for r in rows)
    n_cut = sum(r["plan"]["status"] == "not complete" for r in rows)
    return (f"{len(rows)} parts planned: median wall {statistics.median(walls):.1f} s, worst "
            f"{worst['plan']['wall_s']:.1f} s ({Path(worst['file']).name}); {n_timeout} killed at the "
            f"wall budget, {n_cut} stopped incomplete by --time-limit")


def write_record(args, started: dict, today: str, tri_rate: float, rows, planned: bool, has_limit,
                 summary) -> None:
    """Write the JSON record (``--record``, default by label and date) and say where."""
    record = args.record or RECORDS / f"real_parts_{(args.label + '_') if args.label else ''}{today}.json"
    doc = {"what": "benchmarks/real_parts.py: vertex counts, rollout rates and planner answers of CAD parts",
           "label": args.label or None, "date": today,
           "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
           "machine": dict(started, load_average_end=[round(x, 2) for x in os.getloadavg()]),
           "git": git_state(),
           "settings": {"rate_grid": {"theta_i_deg": [float(THETA[0]), float(THETA[-1]), 4.0], "n_theta_i": int(THETA.size),
                                      "d": D, "mu_c": MU_C, "pin_radius_mm": PIN_RADIUS, "model": MODEL,
                                      "threads": 1, "repeat": args.repeat},
                        "plan": None if not planned else {"mu_c": MU_C, "time_limit_s": args.time_limit,
                                                          "time_limit_option": has_limit, "jobs": args.jobs}},
           "triangle": {"vertices": TRIANGLE, "rollouts_per_s": round(tri_rate, 1)},
           "summary": summary, "rows": rows}
    record.parent.mkdir(parents=True, exist_ok=True)
    record.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"record: {_rel(record)}")


def main(argv=None):
    """Measure the drawings' rollout rates, plan them (unless ``--only-speed``),
    print the table and write the record."""
    ap, args = arguments(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # so a killed run stops its planners too
    files = files_from(args)
    if not files:
        ap.error("no .dxf or .svg files to run")
    started = machine()
    today = datetime.date.today().isoformat()
    print(f"{today} | {started['platform']} | {started['processor']} | {started['nproc']} CPUs | "
          f"load {started['load_average']}", flush=True)

    tri_rate, rows = rate_rows(files, args.repeat)
    planned = not args.only_speed
    has_limit = plan_rows(files, rows, args.time_limit, args.jobs) if planned else None

    print()
    print(table(rows, tri_rate, planned))
    summary = None
    if planned:
        summary = plan_summary(rows)
        print("\n" + summary)
    rates = [r["vs_triangle"] for r in rows]
    print(f"\nrollout rate vs the triangle: median {statistics.median(rates):.2f}, lowest {min(rates):.2f}; "
          f"load average at the end {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")

    if args.record is not None and str(args.record) == "-":
        return 0
    write_record(args, started, today, tri_rate, rows, planned, has_limit, summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
