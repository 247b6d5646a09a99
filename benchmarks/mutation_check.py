"""Mutation checks: does the test suite notice deliberate wrong edits?

Each mutation is one exact text replacement in one source file (a wrong
friction handed to verification, a dropped pin, a swapped sign, ...) and a
short pytest selection that ought to catch it. The script copies the
repository to a temporary folder (the working tree is never edited), runs
every selection once unmutated (it must pass, else "killed" would mean
nothing), then for each mutation: applies it to the copy, runs its
selection with ``-x``, records whether a test failed (killed) or all
passed (survived), and puts the file back byte for byte with its old
modification time (so Numba's kernel cache stays valid for the next one).

    .venv/bin/python benchmarks/mutation_check.py [--only NAME ...] [--no-baseline]
        [--markdown FILE]

Prints one line per mutation and, at the end, the Markdown table the
README's "Mutation checks" section shows. Exit status 1 if any mutation
survived or a baseline failed. A kernel mutation recompiles the Numba
kernels in the copy (a minute or two each).
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Mutation:
    name: str
    what: str
    path: str
    old: str
    new: str
    tests: tuple


MUTATIONS = [
    Mutation("verify-mu0", "verify stage replays paper plans at mu_c = 0, not the planned friction",
             "pipeline/workflow/plan.py",
             'states, plan_result["mu_c"], radius,', "states, 0.0, radius,",
             ("tests/workflow/test_verify_wiring.py",)),
    Mutation("replay-drops-pin", "verification replay skips the plan's last pin",
             "pipeline/planning/claims/replay.py",
             "    for k in range(n_pins):\n        idx = np.flatnonzero(alive)",
             "    for k in range(n_pins - 1):\n        idx = np.flatnonzero(alive)",
             ("tests/planning/test_belt_planning.py", "-k", "replay_at_belt_speed")),
    Mutation("d-sign", "contact parameter d = (y_c - y_pin)/a instead of (y_pin - y_c)/a (the one helper)",
             "pipeline/parts/contact.py",
             "return (pin_y - y_c) / a",
             "return (y_c - pin_y) / a",
             ("tests/planning/test_belt_planning.py", "-k", "replay_at_belt_speed")),
    Mutation("kernel-rotation-sign", "rollout kernel turns the part the wrong way at the start (sin sign)",
             "kernels/rollout.py",
             "cs, sn = math.cos(theta_i), math.sin(theta_i)\n    dx, dy0",
             "cs, sn = math.cos(theta_i), -math.sin(theta_i)\n    dx, dy0",
             ("tests/kernels/test_vectors.py",)),
    Mutation("wrap-360", "theta_f wrap returns 360.0 for tiny negative angles (>= 360 became > 360)",
             "pipeline/maps/simulate.py",
             "np.where(w >= 360.0, 0.0, w) if np.ndim(w) else (0.0 if w >= 360.0 else float(w))",
             "np.where(w > 360.0, 0.0, w) if np.ndim(w) else (0.0 if w > 360.0 else float(w))",
             ("tests/house/test_mutation_kills.py", "-k", "wrap or seam")),
    Mutation("cone-angle-mu", "friction cone edge at angle mu (tan(mu) slope) instead of atan(mu) (slope mu)",
             "kernels/models.py",
             "ex = nx - side * mu * ny\n    ey = ny + side * mu * nx",
             "ex = nx - side * math.tan(mu) * ny\n    ey = ny + side * math.tan(mu) * nx",
             ("tests/kernels/test_models.py", "-k", "cone")),
    Mutation("model-hessian-scale", "minpower warm-start model moved onto the sliding family with H / |ue| "
             "instead of H |ue| (Hessian homogeneous of degree -1)",
             "kernels/models.py",
             "model[7] * au, model[8] * au, model[9] * au,\n                     model[10] * au, model[11] * au, model[12] * au)",
             "model[7] / au, model[8] / au, model[9] / au,\n                     model[10] / au, model[11] / au, model[12] / au)",
             ("tests/kernels/test_warm_start.py",)),
    Mutation("lattice-skips-key", "stored refinement lattice reused without comparing the kernel tolerance",
             "pipeline/planning/tight/store.py",
             "for k, v in want.items()):", 'for k, v in want.items() if k != "kernel_tol"):',
             ("tests/planning/test_tight_planner.py", "tests/house/test_mutation_kills.py", "-k", "refinement or reused")),
    Mutation("predicted-first-branch", "a stored plan's predicted sets read from the first branch only",
             "pipeline/planning/claims/verify.py",
             'for branch in plan["initial_states"][label] if branch]',
             'for branch in plan["initial_states"][label][:1] if branch]',
             ("tests/planning/test_planning.py", "tests/house/test_mutation_kills.py", "-k",
              "verification or triangle_plan or predicted")),
]


def copy_repo(dest: Path) -> Path:
    """The working tree (no .git, caches or results) under ``dest``."""
    ignore = shutil.ignore_patterns(".git", ".hypothesis", ".pytest_cache", "__pycache__", "results",
                                    "catalog", ".venv", "*.egg-info")
    repo = dest / "repo"
    shutil.copytree(ROOT, repo, ignore=ignore)
    return repo


def run_tests(repo: Path, selection, timeout: float) -> tuple[str, float, str]:
    """``("passed" | "failed" | "timeout", seconds, last output line)``."""
    env = dict(os.environ, PYTHONPATH=str(repo), HYPOTHESIS_PROFILE="ci")
    env.pop("NUMBA_CACHE_DIR", None)
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *selection]
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, cwd=repo, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0, ""
    lines = [ln for ln in proc.stdout.strip().splitlines() if ln.strip()]
    return ("passed" if proc.returncode == 0 else "failed"), time.perf_counter() - t0, (lines[-1] if lines else "")


def apply(repo: Path, m: Mutation) -> tuple[Path, bytes, os.stat_result]:
    path = repo / m.path
    raw, st = path.read_bytes(), path.stat()
    text = raw.decode()
    if text.count(m.old) != 1:
        raise SystemExit(f"{m.name}: the snippet occurs {text.count(m.old)} times in {m.path}, "
                         "not once; update the mutation to the current source")
    path.write_text(text.replace(m.old, m.new))
    return path, raw, st


def restore(path: Path, raw: bytes, st: os.stat_result) -> None:
    path.write_bytes(raw)
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))


def table(rows) -> str:
    out = ["| mutation | wrong edit | file | tests run | result |", "|---|---|---|---|---|"]
    for m, outcome in rows:
        out.append(f"| `{m.name}` | {m.what} | `{m.path}` | `{' '.join(m.tests)}` | {outcome} |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="*", help="names of the mutations to run (default: all)")
    ap.add_argument("--no-baseline", action="store_true", help="skip the unmutated runs")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per pytest run")
    ap.add_argument("--markdown", help="also write the table to this file")
    args = ap.parse_args(argv)
    chosen = [m for m in MUTATIONS if not args.only or m.name in args.only]
    bad = 0
    with tempfile.TemporaryDirectory(prefix="pinfeed-mutants-") as tmp:
        repo = copy_repo(Path(tmp))
        if not args.no_baseline:
            for sel in dict.fromkeys(m.tests for m in chosen):
                status, secs, last = run_tests(repo, sel, args.timeout)
                print(f"baseline {' '.join(sel)}: {status} in {secs:.0f} s  {last}", flush=True)
                bad += status != "passed"
        rows = []
        for m in chosen:
            path, raw, st = apply(repo, m)
            try:
                status, secs, last = run_tests(repo, m.tests, args.timeout)
            finally:
                restore(path, raw, st)
            outcome = {"failed": "killed", "passed": "**survived**", "timeout": "timeout"}[status]
            bad += status != "failed"
            print(f"{m.name}: {outcome} in {secs:.0f} s  {last}", flush=True)
            rows.append((m, outcome))
    md = table(rows)
    print(md)
    if args.markdown:
        Path(args.markdown).write_text(md + "\n")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
