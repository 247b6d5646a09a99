"""How long a support family's answer takes, and where its time goes.

Runs ``pinfeed plan`` for one part and support family on an empty catalog
(a temporary folder), with a wall-clock limit, and reports:

* the wall time and the CPU time of the run (children's rusage);
* from the progress lines: when the fixed-pin levels ended, when the
  moving-pin stage began, and how many worst-member searches and kept-member
  first rounds ran;
* from the plan file (when the run finished): whether a plan holds for the
  family, its certificate's epsilon and beta, each level's counts
  (``broken_by_known_member`` among them) and the nearest "yes".

The target is a family answer, with its nearest "yes", within 5 minutes on
2 cores. Results go on the performance page with the date and the machine.

    .venv/bin/python benchmarks/family_answer.py [--part asym_triangle]
        [--mu-c 0.1:0.3] [--family tripods:12] [--limit 3600] [--log FILE]
"""
import argparse
import datetime
import json
import os
import platform
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(part: str, mu_c: str, family: str, limit: float, workdir: Path, log: Path | None = None) -> dict:
    """Run the plan command under ``limit`` seconds; its timings and its output's summary."""
    out = workdir / "plan.json"
    cmd = [sys.executable, "-m", "pipeline.cli", "plan", "--part", part, "--mu-c", mu_c,
           "--support-family", family, "--catalog", str(workdir / "catalog"), "--out", str(out)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    stamps = {}
    with subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}) as proc:
        try:
            for line in proc.stdout:
                _stamp(stamps, line, time.perf_counter() - t0)
                if log is not None:
                    with open(log, "a") as f:
                        f.write(f"{time.perf_counter() - t0:8.1f} s {line}")
                if time.perf_counter() - t0 > limit:
                    proc.kill()
                    stamps["stopped_at_limit"] = True
                    break
        finally:
            proc.wait()
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    summary = {"wall_s": round(wall, 1),
               "cpu_s": round(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, 1),
               "exit": proc.returncode, **stamps}
    if out.exists():
        summary.update(_plan_summary(json.loads(out.read_text())))
    return summary


def _stamp(stamps: dict, line: str, t: float) -> None:
    """Record when the stages of interest were reached."""
    if re.search(r"\d fixed pin\(s\): \d+ sequences", line):
        stamps["fixed_levels_done_s"] = round(t, 1)
    if "adding moving pins" in line:
        stamps["moving_stage_from_s"] = round(t, 1)
    if re.search(r"search \d+: \d+ member evaluations to do", line):
        stamps["worst_member_searches"] = stamps.get("worst_member_searches", 0) + 1
    if "nearest" in line and "yes" in line:
        stamps["nearest_yes_from_s"] = round(t, 1)


def _plan_summary(plan: dict) -> dict:
    """What the stored plan file says about the family."""
    tight = (plan.get("tight") or [{}])[0]
    cert = tight.get("family_certificate") or {}
    levels = (tight.get("fixed_pin_search") or {}).get("levels") or []
    return {"orients_for_family": bool(cert.get("holds")), "claim": cert.get("claim"),
            "recommended": (tight.get("recommended") or {}).get("pins"),
            "levels": [{k: lv.get(k) for k in ("sequences", "judged", "broken_by_known_member")} for lv in levels],
            "nearest_yes": [{k: a.get(k) for k in ("axis", "found", "value", "statement")}
                            for a in (tight.get("nearest_yes") or {}).get("axes", [])]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", default="asym_triangle")
    ap.add_argument("--mu-c", default="0.1:0.3")
    ap.add_argument("--family", default="tripods:12")
    ap.add_argument("--limit", type=float, default=3600.0, help="seconds before the run is stopped")
    ap.add_argument("--log", type=Path, help="also write the run's progress lines here, with their times")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        summary = run(args.part, args.mu_c, args.family, args.limit, Path(tmp), args.log)
    summary.update(date=datetime.date.today().isoformat(), machine=f"{platform.node()} ({os.cpu_count()} CPUs)",
                   load=os.getloadavg(), part=args.part, mu_c=args.mu_c, family=args.family)
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
