"""Time the tight planner on a default triangle: depth 4 over the default pin
grid and friction range, first from an empty refinement store (every rollout
computed), then again with the store the first run left (reuse).

    .venv/bin/python benchmarks/plan_speed.py [asym_triangle|sym_triangle] [MU_C]

Prints one line per run: seconds, new rollouts, the recommended plan and its
verification. Numbers quoted in the README come from this script.
"""
from __future__ import annotations

import platform
import sys
import tempfile
import time

from pipeline.config import load_config
from pipeline.parts.families import family_parts
from pipeline.planning.settings import parse_friction
from pipeline.planning.plan import plan_tight_all


def main() -> None:
    name = sys.argv[1] if len(sys.argv) > 1 else "asym_triangle"
    config = load_config()
    if len(sys.argv) > 2:
        config["planner"]["mu_c"] = sys.argv[2]
    config["planner"]["frictions"] = []
    part = next(p for fam, spec in config["families"].items() for p in family_parts(fam, spec)
                if p.name == name)
    print(f"{name}, depth {config['planner']['depth']}, {len(config['planner']['pins'])} pins, "
          f"mu_c {parse_friction(config['planner']['mu_c'])}, {platform.processor() or platform.machine()}")
    with tempfile.TemporaryDirectory() as root:
        for run in ("empty store", "stored rollouts"):
            t0 = time.perf_counter()
            res = plan_tight_all(part, config, root)[0]
            dt = time.perf_counter() - t0
            rec = res["recommended"]
            what = (f"{' '.join(rec['pins'])} -> {rec['n_final_sets']} set(s), verified "
                    f"{rec['verification']['successes']}/{rec['verification']['trials']}"
                    if rec else res["warning"])
            print(f"{run}: {dt:.1f} s, {res['stats']['rollouts']} new rollouts, "
                  f"search {res['stats']['seconds']:.1f} s; {what}")


if __name__ == "__main__":
    main()
