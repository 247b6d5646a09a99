"""A part of your own from start to finish (issue 27): an outline file is
planned, and the speed, layout and animate commands the CLI prints run as
printed; a missing plan or layout names a command that makes it; --out is
checked before any planning; Ctrl-C is one line and keeps the rollouts."""
import json
import os
import re
import shlex
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from cli_runs import run_cli

from pipeline.config import load_config

ROOT = Path(__file__).resolve().parents[2]
SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" viewBox="0 0 100 60">'
       '<polygon points="0,0 60,0 15,35"/></svg>')


def tiny_config(pins=(7.5, 27.5)) -> dict:
    """The embedded config cut down to seconds: two candidate pins, depth 2, one
    friction, fixed pins only, few trials everywhere."""
    c = load_config(None)
    c.pop("name")  # named after its file
    c.update(catalog_dir="cat", results_dir="res")
    c["planner"].update(pins=list(pins), depth=2, mu_c=0, frictions=[])
    c["planner"]["dynamic"]["depth"] = 0
    c["verify"]["trials"] = 5
    c["speed"]["trials"] = 3
    c["layout"].update(trials=3, speed_trials=3)
    return c


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    """A fresh folder holding an outline file and a small config, as a new user has."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "tri.svg").write_text(SVG)
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump(tiny_config()))
    return tmp_path


def hints(text: str) -> list[str]:
    """The commands printed after 'next:'."""
    lines = text[text.index("next: "):].splitlines()
    return [ln.replace("next: ", "").strip() for ln in lines if ln.strip().startswith(("next: pinfeed", "pinfeed"))]


def run_hint(capsys, command: str):
    words = shlex.split(command)
    assert words[0] == "pinfeed"
    return run_cli(capsys, words[1:])


def test_outline_to_animation_with_the_printed_commands(fresh, capsys):
    # Before planning: the missing plan names the command that makes it.
    code, _, err = run_cli(capsys, ["speed", "--part", "tri", "--config", "tiny.yaml"])
    assert code == 2
    template = re.search(r"(pinfeed plan --outline FILE --name tri --config tiny.yaml)", err).group(1)
    code, out, err = run_hint(capsys, template.replace("FILE", "tri.svg"))
    assert code == 0, err
    plan_file = fresh / "res" / "tiny" / "plans" / "tri.json"
    assert plan_file.is_file() and f"stored the plan at {Path('res/tiny/plans/tri.json')}" in out
    progress = [ln for ln in err.splitlines() if ln.startswith("  ... ")]  # on stderr: stdout is the plan
    assert progress and all(ln.startswith("  ... mu_c 0: ") for ln in progress), [ln for ln in progress if not ln.startswith("  ... mu_c 0: ")]  # which friction
    assert "  ... " not in out
    stored_plans = json.loads(plan_file.read_text())["tight"][0]
    rec = [ln for ln in out.splitlines() if "(recommended)" in ln]
    assert len(rec) == 1 and rec[0].startswith(f"  #{stored_plans['plans'].index(stored_plans['recommended']) + 1}")
    steps = hints(out)
    assert [shlex.split(h)[1] for h in steps] == ["speed", "layout", "animate"]
    speed, layout, animate = steps

    code, out, err = run_hint(capsys, speed)
    assert code == 0, err
    stored = json.loads(plan_file.read_text())["tight"][0]["plans"][0]["speed_limit"]
    assert f"speed limit {stored['speed_limit_mm_s']:g} mm/s ({stored['trials']} trials per state)" in out

    # animate --layout before the layout exists: its error names the layout command printed above
    code, _, err = run_hint(capsys, animate)
    assert code == 2 and f"run '{layout}' first" in err
    code, out, err = run_hint(capsys, layout)
    assert code == 0, err
    laid = json.loads((fresh / "res" / "tiny" / "layout_tri.json").read_text())
    assert laid["speed_limit_mm_s"] == stored["speed_limit_mm_s"]
    assert laid["speed_limit_trials"] == stored["trials"]

    code, out, err = run_hint(capsys, animate + " --frames 3")
    assert code == 0, err
    assert "laid-out" in out and (fresh / "res" / "tiny" / "animations" / "tri.gif").is_file()


def test_out_under_a_file_is_refused_before_planning(fresh, capsys, monkeypatch):
    import pipeline.workflow.commands as commands

    def no_planning(*a, **k):
        raise AssertionError("planned before checking --out")
    monkeypatch.setattr(commands, "plan_command", no_planning)
    (fresh / "afile").write_text("x")
    code, _, err = run_cli(capsys, ["plan", "--config", "tiny.yaml", "--outline", "tri.svg",
                                    "--out", "afile/tri.json"])
    assert code == 2
    assert err.splitlines()[-1] == ("pinfeed: error: --out afile/tri.json: afile is a file, not a folder; "
                                    "choose another path")


def test_a_workflow_part_is_not_stored_over_the_workflows_file(fresh, capsys, monkeypatch):
    import pipeline.workflow.commands as commands
    monkeypatch.setattr(commands, "plan_command", lambda part, config, mode, progress=None: {
        "part": part.to_dict(), "tight": []})
    monkeypatch.setattr("pipeline.cli._print_plan_result", lambda *a: None)
    code, out, _ = run_cli(capsys, ["plan", "--config", "tiny.yaml", "--part", "asym_triangle"])
    assert code == 0 and "not stored" in out
    assert not (fresh / "res").exists()


def test_ctrl_c_is_one_line_exit_130_and_the_rollouts_are_kept(fresh):
    import xarray as xr
    config = tiny_config(pins=(0, 7.5, 15, 22.5, 30))
    # Five more frictions with more trials: still planning when interrupted
    # (one more friction alone finished before the signal arrived on a fast run).
    config["planner"]["frictions"] = [0.3, 0.05, 0.1, 0.2, 0.25]
    config["verify"]["trials"] = 60
    (fresh / "slow.yaml").write_text(yaml.safe_dump(config))
    cmd = [sys.executable, "-m", "pipeline.cli", "plan", "--config", "slow.yaml", "--vertices", "0,0 60,0 15,35",
           "--name", "tri"]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    # A job started in the background of a non-interactive shell (as CI may
    # run the suite) inherits SIGINT ignored, and Python keeps it ignored: give
    # the child the default disposition, so that it gets its KeyboardInterrupt.
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    for line in proc.stderr:  # the planner's progress lines
        if "mu_c 0: verified" in line:  # the first friction's plans are carried (rollouts done)
            proc.send_signal(signal.SIGINT)
            break
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130
    said = [ln for ln in err.splitlines() if not ln.startswith("  ... ")]
    assert len(said) == 1 and said[0].startswith("pinfeed: interrupted") and "Traceback" not in err
    assert not (fresh / "res").exists()  # no plan file, not even half of one
    kept = list((fresh / "cat" / "refine").rglob("*.h5"))
    assert kept, "the rollouts computed before Ctrl-C were not saved"
    with xr.open_dataset(kept[0], engine="h5netcdf") as ds:
        assert ds.sizes["sample"] > 0
    again = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert again.returncode == 0, again.stderr
    assert "stored the plan at" in again.stdout


def test_plan_help_explains_model_and_coverage(capsys):
    code, out, _ = run_cli(capsys, ["plan", "--help"])
    assert code == 0
    text = " ".join(out.split())
    assert "--model {minpower,tip,ellipsoid} quasi-static contact model" in text
    assert "--coverage {bracket,nearest} paper mode only" in text


def test_layout_names_the_fixed_pin_plans_and_speed_labels_other_trials(fresh, capsys):
    code, _, err = run_cli(capsys, ["plan", "--config", "tiny.yaml", "--outline", "tri.svg", "--name", "tri"])
    assert code == 0, err
    path = fresh / "res" / "tiny" / "plans" / "tri.json"
    stored = json.loads(path.read_text())
    limit = stored["tight"][0]["plans"][0]["speed_limit"]
    code, out, _ = run_cli(capsys, ["speed", "--part", "tri", "--config", "tiny.yaml", "--trials", "4"])
    assert code == 0 and "(4 trials per state)" in out
    assert (f"the plan file stores {limit['speed_limit_mm_s']:g} mm/s ({limit['trials']} trials per state)"
            in out)
    # Make plan 1 a plan with a moving pin: the layout names the others, which have fixed pins.
    plans = stored["tight"][0]["plans"]
    plans[0]["pin_speeds"] = [0.0] * (len(plans[0]["pins"]) - 1) + [2.0]
    path.write_text(json.dumps(stored))
    code, _, err = run_cli(capsys, ["layout", "--part", "tri", "--config", "tiny.yaml"])
    fixed = ", ".join(f"--plan {k} ({' '.join(p['pins'])})" for k, p in enumerate(plans, start=1) if k > 1)
    assert code == 2 and err.strip().endswith(f"plans of fixed pins: {fixed}")
    for p in plans:
        p["pin_speeds"] = [2.0] * len(p["pins"])
    path.write_text(json.dumps(stored))
    code, _, err = run_cli(capsys, ["layout", "--part", "tri", "--config", "tiny.yaml"])
    assert code == 2 and "no stored plan at this friction has fixed pins only" in err
