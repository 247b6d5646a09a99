"""Where a compiled rollout's time goes, by kernel function: ``perf`` samples
named through ``gdb``.

``perf`` alone cannot name Numba's compiled functions (their code has no
symbol table it reads), but ``gdb`` attached to the same process can
(``info symbol`` on a sampled address). This script rolls out one part on
one thread in a child process (``compute_map`` over 90 theta_i x 12 d,
mu_c 0.2, a 3 mm pin, again and again), records ``perf record -p`` for
``--seconds``, names the sampled addresses of the compiled code with
``gdb -batch`` while the child still runs, and prints the share of the
samples per kernel function (the functions inlined into another count as
that one) and per library function (``hypot``, ``sincos``, Numba's
``NRT_incref``, ...)::

    .venv/bin/python benchmarks/kernel_profile.py                          # the default triangle
    .venv/bin/python benchmarks/kernel_profile.py --outline benchmarks/corpus/angle_gusset_r12_lines.dxf

Needs ``perf`` (with permission to attach: ``kernel.perf_event_paranoid``
at most 1, or root) and ``gdb``; the 2,000 most sampled addresses of the
compiled code are named, and the share of the others is printed as such.
"""
from __future__ import annotations

import argparse
import collections
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOP_ADDRESSES = 2000

CHILD = r'''
import os, sys, time
import numpy as np
sys.path.insert(0, sys.argv[1])
from pipeline.maps.simulate import compute_map
from pipeline.parts.part import Part
from pipeline.parts.outlines import read_outline
part = read_outline(sys.argv[2]).part() if sys.argv[2] else Part.from_vertices([(0, 0), (60, 0), (15, 35)])
theta, d = np.arange(0.0, 360.0, 4.0), np.linspace(-0.9, 0.9, 12)
compute_map(part, theta[:2], d[:2], 0.2, 3.0, threads=1)  # compiled or loaded before the samples
print("ready", flush=True)
end = time.time() + float(sys.argv[3])
while time.time() < end:
    compute_map(part, theta, d, 0.2, 3.0, threads=1)
'''


def _samples(report: str) -> tuple[dict, collections.Counter]:
    """``(jit, library)`` from ``perf report``'s lines: the share of each
    sampled address of the compiled code, and of each library function."""
    jit, library = {}, collections.Counter()
    for line in report.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+(\S.*?)\s+\[\.\]\s+(\S+)", line)
        if not m:
            continue
        share, dso, symbol = float(m.group(1)), m.group(2), m.group(3)
        if "JIT" in dso and symbol.startswith("0x"):
            jit[symbol] = share
        else:
            library[re.sub(r"@.*", "", symbol)] += share
    return jit, library


def _names(pid: int, addresses: list) -> list:
    """The kernel function holding each address (``module.function``), by ``gdb``."""
    with tempfile.NamedTemporaryFile("w", suffix=".gdb", delete=False) as f:
        f.write("".join(f"info symbol {a}\n" for a in addresses))
    out = subprocess.run(["gdb", "-p", str(pid), "-batch", "-x", f.name], capture_output=True, text=True).stdout
    lines = [ln for ln in out.splitlines() if " in section " in ln or ln.startswith("No symbol matches")]
    names = []
    for ln in lines:
        m = re.search(r"kernels::(\w+)::(\w+)", ln)
        names.append(f"{m.group(1)}.{m.group(2)}" if m else "(unnamed)")
    return names if len(names) == len(addresses) else ["(unnamed)"] * len(addresses)


def profile(outline: str, seconds: float) -> tuple[dict, collections.Counter]:
    """``(by_function, library)``: shares of the samples (%) of one child's
    rollouts; ``by_function["(other compiled code)"]`` holds the addresses
    beyond the ``TOP_ADDRESSES`` named."""
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(ROOT), outline, str(seconds + 60.0)],
                             stdout=subprocess.PIPE, text=True)
    try:
        child.stdout.readline()  # "ready": the kernels are compiled
        time.sleep(1.0)
        with tempfile.TemporaryDirectory() as tmp:
            data = Path(tmp) / "perf.data"
            rec = subprocess.run(["perf", "record", "-p", str(child.pid), "-o", str(data), "sleep", str(seconds)],
                                 capture_output=True, text=True)
            if rec.returncode:
                last = (rec.stderr.strip().splitlines() or ["no message"])[-1]
                sys.exit(f"kernel_profile: perf record failed ({last}): allow it with "
                         "'sysctl kernel.perf_event_paranoid=1' or run as root")
            report = subprocess.run(["perf", "report", "-i", str(data), "--no-children", "--sort", "dso,symbol",
                                     "-g", "none"], capture_output=True, text=True, check=True).stdout
        jit, library = _samples(report)
        addresses = sorted(jit, key=jit.get, reverse=True)[:TOP_ADDRESSES]
        by_function = collections.Counter()
        for address, name in zip(addresses, _names(child.pid, addresses)):
            by_function[name] += jit[address]
        by_function["(other compiled code)"] = sum(jit.values()) - sum(jit[a] for a in addresses)
        return by_function, library
    finally:
        child.kill()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--outline", default="", help="a CAD drawing (default: the triangle (0,0) (60,0) (15,35))")
    ap.add_argument("--seconds", type=float, default=6.0, help="how long perf samples")
    args = ap.parse_args()
    missing = [tool for tool in ("perf", "gdb") if shutil.which(tool) is None]
    if missing:
        sys.exit(f"kernel_profile: {' and '.join(missing)} not found: install them (e.g. linux-tools, gdb)")
    by_function, library = profile(args.outline, args.seconds)
    print(f"{args.outline or 'default triangle'}, one thread, {args.seconds:g} s of samples\n")
    print("| function | share of samples (%) |\n|---|---|")
    for name, share in by_function.most_common(15):
        print(f"| {name if name.startswith('(') else f'`kernels.{name}`'} | {share:.1f} |")
    for name, share in library.most_common(6):
        print(f"| library: `{name}` | {share:.1f} |")


if __name__ == "__main__":
    main()
