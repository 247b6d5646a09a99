"""Count the planner's rollouts by stage on the parts of ``plan_speed.py``:
the nominal enumeration (``NominalTree``), the replays of verification
trials (screens, judgements, held-out trials) and the rest (the tight
propagation, the verification of chosen plans), with the wall and CPU
seconds of each part, and store each part's answer for a later comparison.

    .venv/bin/python benchmarks/rollout_count.py --parts t_bracket --out /tmp/before.json
    .venv/bin/python benchmarks/rollout_count.py --compare /tmp/before.json /tmp/after.json

Rollout counts are deterministic (unlike times on a shared machine), so
they measure what a change of the search saves. ``--compare`` checks that
two runs gave the same answer: the plan entries, the fixed-pin and
moving-pin searches' records less their timings and rollout counts.
"""
from __future__ import annotations

import argparse
import collections
import json
import os
import sys
import tempfile
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

from benchmarks.plan_speed import PARTS  # noqa: E402
from pipeline.config import load_config  # noqa: E402
from pipeline.maps import simulate  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402
from pipeline.planning import PlannerSettings, plan_tight_all  # noqa: E402

REPLAY_STAGES = {"_probe": "probe", "_cascade": "cascade", "_drop_known_broken": "known members",
                 "_judge": "judge", "certify": "held-out", "several_sets": "evidence", "failures": "screen",
                 "judge": "judge", "verify_plan": "verification", "untruncated_check": "tails",
                 "sampled_plan": "sampled carried sets"}
COUNTS = collections.Counter()
SECONDS = collections.Counter()
_original = simulate.rollout_points


def _stage() -> str:
    names = [f.name for f in traceback.extract_stack()]
    if "_rollouts" in names:
        return "moving nominal" if "_moving_search" in names else "nominal"
    if "pin_step" in names:
        where = next((n for n in reversed(names) if n in REPLAY_STAGES and n not in ("failures", "judge")
                      and not (n == "verify_plan" and "untruncated_check" in names)),
                     "failures" if "failures" in names else "replay")
        return ("moving " if "_moving_search" in names else "") + REPLAY_STAGES.get(where, where)
    return "other"


def _counted(part, theta, *args, **kwargs):
    stage = _stage()
    t0 = time.perf_counter()
    out = _original(part, theta, *args, **kwargs)
    SECONDS[stage] += time.perf_counter() - t0
    COUNTS[stage] += int(np.size(theta))
    return out


DROP = {"seconds", "nominal_rollouts", "rollouts", "lattices", "stats", "provenance", "code_version"}


def _clean(x):
    """``x`` without timings and rollout counts (what a search change may alter)."""
    if isinstance(x, dict):
        return {k: _clean(v) for k, v in x.items() if k not in DROP}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, np.ndarray):
        return _clean(x.tolist())
    return x


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--depth", type=int, default=4)
    ap.add_argument("--mu-c", default="0.1:0.3")
    ap.add_argument("--tolerance", type=float, default=10.0)
    ap.add_argument("--parts", default="t_bracket")
    ap.add_argument("--out")
    ap.add_argument("--compare", nargs=2)
    args = ap.parse_args()
    if args.compare:
        a, b = (json.load(open(p)) for p in args.compare)
        for name in sorted(set(a) & set(b)):
            same = a[name]["answer"] == b[name]["answer"]
            print(f"{name:<17} answer {'identical' if same else 'DIFFERENT'}; rollouts "
                  f"{a[name]['counts']} -> {b[name]['counts']}; wall {a[name]['wall_s']} -> {b[name]['wall_s']} s")
        return
    simulate.rollout_points = _counted
    config = load_config()
    config["planner"].update(mu_c=args.mu_c, frictions=[], depth=args.depth, pins="auto",
                             tolerance_deg=args.tolerance)
    out = json.load(open(args.out)) if args.out and os.path.exists(args.out) else {}
    for name in args.parts.split(","):
        COUNTS.clear()
        SECONDS.clear()
        part = Part.from_vertices(PARTS[name], name=name)
        with tempfile.TemporaryDirectory() as root:
            c0, t0 = os.times(), time.perf_counter()
            res = plan_tight_all(part, PlannerSettings.from_config(config), root)[0].to_dict()
            wall, c1 = time.perf_counter() - t0, os.times()
        cpu = (c1.user - c0.user) + (c1.system - c0.system)
        answer = _clean({k: v for k, v in res.items() if k != "lattices"})
        out[name] = {"counts": dict(COUNTS), "kernel_s": {k: round(v, 1) for k, v in SECONDS.items()},
                     "wall_s": round(wall, 1), "cpu_s": round(cpu, 1), "load": os.getloadavg()[0],
                     "per_level": res["stats"]["per_level"], "answer": answer}
        print(f"{name:<17} wall {wall:6.1f} s cpu {cpu:6.1f} s (load {os.getloadavg()[0]:.1f}); rollouts "
              f"{dict(COUNTS)}; kernel s {out[name]['kernel_s']}; levels {res['stats']['per_level']}", flush=True)
        if args.out:
            with open(args.out, "w") as f:
                json.dump(out, f, default=str)


if __name__ == "__main__":
    main()
