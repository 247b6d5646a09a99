"""The kernels' warm-up (``pipeline.maps.warm``): it says so when it takes
long (compiling), and a plan after it compiles nothing more, so the first
level's pace is the planner's own and a real drawing planned after ``make
run`` does not spend its time limit compiling."""
import importlib
import json
import math
import pkgutil
import subprocess
import sys
from pathlib import Path

from numba.core.registry import CPUDispatcher

import kernels
from cli_runs import run_cli, small_config_file
from pipeline.maps.warm import NOTICE, warm_kernels

ROOT = Path(__file__).resolve().parents[2]


def _overloads() -> dict:
    """Compiled signatures per CPU kernel (``module.name`` -> count)."""
    out = {}
    for info in pkgutil.iter_modules(kernels.__path__):
        if info.name == "cuda":  # the GPU kernels: not run on a CPU
            continue
        module = importlib.import_module(f"kernels.{info.name}")
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher):
                out[f"{info.name}.{name}"] = len(obj.overloads)
    return out


def _ring(cx, cy, r, n, clockwise=False):
    sign = -1.0 if clockwise else 1.0
    return " ".join(f"{cx + r * math.cos(sign * 2 * math.pi * k / n):.4f},"
                    f"{cy + r * math.sin(sign * 2 * math.pi * k / n):.4f}" for k in range(n))


def test_notice_comes_only_when_the_warm_up_takes_long():
    lines = []
    warm_kernels(lines.append, notice_after=600.0)  # cached by now (or compiled): well under 600 s
    assert lines == []
    warm_kernels(lines.append, notice_after=0.0)
    assert lines == [NOTICE]


def test_plans_after_the_warm_up_compile_no_kernel(tmp_path):
    """A holed part of 40 + 12 vertices (its support table) with a moving pin,
    and a plain quadrilateral: every kernel they run was compiled (or loaded)
    by the warm-up, with the same signature. In a process of its own: in
    this one, earlier tests have loaded kernels the warm-up might miss."""
    config = small_config_file(tmp_path)
    holed = ["--vertices", _ring(0, 0, 20, 40), "--hole", _ring(5, 0, 4, 12, clockwise=True), "--name", "disc",
             "--speeds=1", "--dynamic-depth", "1"]
    plain = ["--vertices", "0,0 40,0 40,20 10,25", "--name", "quad", "--dynamic-depth", "0"]
    runs = [["plan", "--config", str(config), *part, "--depth", "1", "--pins=5,15", "--mu-c", "0.2",
             "--catalog", str(tmp_path / "cat"), "--out", str(tmp_path / "plan.json")] for part in (holed, plain)]
    script = (f"import json, sys; sys.path[:0] = {[str(ROOT), str(ROOT / 'tests'), str(ROOT / 'tests' / 'maps')]!r}\n"
              "from pipeline.cli import main\n"
              "from pipeline.maps.warm import warm_kernels\n"
              "from test_warm import _overloads\n"
              "warm_kernels()\n"
              "before = _overloads()\n"
              f"codes = [main(argv) for argv in {runs!r}]\n"
              "after = _overloads()\n"
              "print(json.dumps([codes, {k: (before.get(k, 0), n) for k, n in after.items() "
              "if n > before.get(k, 0)}]))\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path,
                          check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    codes, new = json.loads(done.stdout.strip().splitlines()[-1])
    assert codes == [0, 0] and new == {}


def test_a_time_limit_counts_from_after_the_compile(tmp_path, capsys, monkeypatch):
    """A first run's compile (here a warm-up made to take 3 s) does not eat a
    2 s limit: the quadrilateral's one-pin search is still complete, and the
    progress says the compile took place."""
    import time

    import pipeline.maps.warm as warm

    def slow_warm_up(progress=None, every=False, notice_after=warm.NOTICE_AFTER):
        time.sleep(3.0)
        return 3.0

    monkeypatch.chdir(tmp_path)
    warm_kernels()  # the real kernels, before the clock matters
    monkeypatch.setattr(warm, "warm_kernels", slow_warm_up)
    code, out, err = run_cli(capsys, ["plan", "--config", str(small_config_file(tmp_path)), "--vertices",
                                      "0,0 40,0 40,20 10,25", "--name", "quad", "--depth", "1", "--pins=5,15",
                                      "--mu-c", "0.2", "--dynamic-depth", "0", "--time-limit", "2",
                                      "--catalog", str(tmp_path / "cat"), "--json"])
    assert code == 0, err
    assert "kernels compiled in 3 s; the time limit counts from now" in err
    assert json.loads(out)["complete"] is True
