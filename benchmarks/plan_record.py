"""Record what the planner answers, and compare two records: a refactor's
witness that no result changed.

    .venv/bin/python benchmarks/plan_record.py record OUT.json [--atlas-plans DIR] [--benchmark-parts also|only]
    .venv/bin/python benchmarks/plan_record.py compare BEFORE.json AFTER.json

``record`` plans, through the ``pinfeed plan`` command line (so the record
does not depend on any module's internals), the two default triangles on
the embedded default config (tight and paper modes) and seven parts outside
the configs: a rectangle, a trapezoid, an irregular pentagon, a plate with
an off-centre hole, two CAD drawings from the tests' corpus (a holed bracket
and a gusset), one of them under a tripod support family and one on a
moving belt. Each run starts from an empty catalog, so the refinement store
and the maps are computed afresh. ``--atlas-plans DIR`` also adds the plan
files a workflow run wrote (``results/NAME/plans/*.json``, e.g. the
working folder of ``benchmarks/family_atlas.py --workdir``).

Every plan file is kept whole except what a rerun changes by itself: the
time it was made, the code version, and every ``*seconds`` timing. So the
recommended plan, its pins and margins, the final sets and their widths,
the claims, the verification counts, the complete search's levels and
evidence, the carried sets and the warnings are all compared.

``compare`` prints each difference (part, path in the plan file, before,
after) and exits 1 when there is any, 0 when the two records are identical.
Either record may be gzipped. ``benchmarks/records/plans_before_house.json.gz``
is the record made before the planner's house was rebuilt (wings, typed
settings, one kernel driver): compare a new record with it to show that a
change of the house changed no plan.
"""
from __future__ import annotations

import argparse
import gzip
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CAD = ROOT / "tests" / "data" / "cad"

# name -> pinfeed plan arguments (besides --out and --catalog)
RUNS = {
    "asym_triangle": ["--part", "asym_triangle", "--mode", "both"],
    "sym_triangle": ["--part", "sym_triangle", "--mode", "both"],
    "rectangle_50x20": ["--vertices", "0,0 50,0 50,20 0,20", "--mu-c", "0.2"],
    "trapezoid": ["--vertices", "0,0 70,0 50,25 10,25", "--mu-c", "0.1:0.3", "--depth", "3"],
    "pentagon": ["--vertices", "0,0 40,0 50,20 20,35 -5,15", "--mu-c", "0.15"],
    "holed_plate": ["--vertices", "0,0 60,0 60,30 0,30", "--hole", "8,8 20,8 20,20 8,20",
                    "--mu-c", "0.2"],
    "holed_bracket_dxf": ["--outline", str(CAD / "holed_bracket.dxf"), "--mu-c", "0.2",
                          "--support-family", "tripods:3"],
    "gusset_dxf_belt": ["--outline", str(CAD / "gusset_bracket.dxf"), "--mu-c", "0.2",
                        "--belt-speed", "150"],
}
# The ten parts of benchmarks/plan_speed.py, as it plans them (--benchmark-parts).
BENCHMARK_PARTS = {
    "asym_triangle": "0,0 60,0 15,35", "sym_triangle": "0,0 40,0 20,60", "right_triangle": "0,0 50,0 0,30",
    "scalene_triangle": "0,0 70,0 20,30", "t_bracket": "0,0 60,0 60,10 35,10 35,40 25,40 25,10 0,10",
    "l_bracket": "0,0 60,0 60,15 15,15 15,40 0,40", "trapezoid": "0,0 70,0 50,25 10,25",
    "hexagon_slot": "0,0 50,0 60,10 50,20 0,20 -10,10", "small_20mm": "0,0 20,0 5,11.666666666666666",
    "large_150mm": "0,0 125,0 150,75 25,62.5",
}
BENCHMARK_ARGS = ["--mu-c", "0.1:0.3", "--depth", "4", "--tolerance", "10"]  # pins: the default, fitted
VOLATILE = {"created", "git_commit", "pinfeed_version"}


def stable(value):
    """``value`` without the keys a rerun changes by itself (times, versions)."""
    if isinstance(value, dict):
        return {k: stable(v) for k, v in value.items()
                if k not in VOLATILE and not k.endswith("seconds")}
    if isinstance(value, list):
        return [stable(v) for v in value]
    return value


def plan_one(name: str, args: list, work: Path) -> dict:
    """The stable plan file of one ``pinfeed plan`` run, from an empty catalog."""
    out = work / f"{name.replace('/', '_')}.json"
    named = [] if args[0] == "--part" else ["--name", name.replace("/", "_")]
    cmd = [sys.executable, "-m", "pipeline.cli", "plan", *args, *named,
           "--catalog", str(work / f"catalog_{name.replace('/', '_')}"), "--out", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{name}: pinfeed plan failed:\n{done.stderr[-2000:]}")
    return stable(json.loads(out.read_text()))


def record(out: Path, atlas_plans: Path | None, benchmark_parts: str | None = None) -> None:
    plans = {}
    runs = {} if benchmark_parts == "only" else dict(RUNS)
    if benchmark_parts:
        runs.update({f"bench/{name}": ["--vertices", vertices, *BENCHMARK_ARGS]
                     for name, vertices in BENCHMARK_PARTS.items()})
    with tempfile.TemporaryDirectory() as tmp:
        for name, args in runs.items():
            print(f"planning {name} ...", file=sys.stderr, flush=True)
            plans[name] = plan_one(name, args, Path(tmp))
    if atlas_plans is not None:
        for path in sorted(Path(atlas_plans).glob("*.json")):
            plans[f"atlas/{path.stem}"] = stable(json.loads(path.read_text()))
    text = json.dumps(plans, indent=1, sort_keys=True) + "\n"
    if out.suffix == ".gz":  # as ``compare`` reads it
        out.write_bytes(gzip.compress(text.encode(), mtime=0))
    else:
        out.write_text(text)
    print(f"recorded {len(plans)} plan files in {out}", file=sys.stderr)


def differences(before, after, path=""):
    """Every ``(path, before, after)`` where the two JSON values differ."""
    if isinstance(before, dict) and isinstance(after, dict):
        for k in sorted(set(before) | set(after)):
            yield from differences(before.get(k, "<absent>"), after.get(k, "<absent>"), f"{path}/{k}")
    elif isinstance(before, list) and isinstance(after, list) and len(before) == len(after):
        for i, (b, a) in enumerate(zip(before, after)):
            yield from differences(b, a, f"{path}[{i}]")
    elif before != after:
        yield path, before, after


def load(path: Path) -> dict:
    """A record (``.json`` or ``.json.gz``)."""
    data = gzip.decompress(path.read_bytes()) if path.suffix == ".gz" else path.read_bytes()
    return json.loads(data)


def compare(before: Path, after: Path) -> int:
    old, new = load(before), load(after)
    diffs = list(differences(old, new))
    for path, b, a in diffs[:200]:
        print(f"{path}: {str(b)[:100]} -> {str(a)[:100]}")
    print(f"{len(old)} plan files before, {len(new)} after; {len(diffs)} differences")
    return 1 if diffs else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record")
    rec.add_argument("out", type=Path)
    rec.add_argument("--atlas-plans", type=Path, default=None)
    rec.add_argument("--benchmark-parts", choices=("also", "only"), default=None,
                     help="also (or only) the ten parts of benchmarks/plan_speed.py (mu_c 0.1:0.3, depth 4, "
                          "fitted pins)")
    cmp_ = sub.add_parser("compare")
    cmp_.add_argument("before", type=Path)
    cmp_.add_argument("after", type=Path)
    args = ap.parse_args(argv)
    if args.command == "record":
        record(args.out, args.atlas_plans, args.benchmark_parts)
        return 0
    return compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
