"""What ``pinfeed plan`` suggests next. After a plan that orients the part:
speed, layout and animate. After one that does not: what may still orient it,
only what applies to the search that ran (more trials, a force/torque sensor,
moving pins, a looser tolerance, one pin more, a wider pin grid), each as a
command that runs as printed; and the ``atlas`` header's wording."""
import contextlib
import copy
import io
import json
import shlex
from argparse import Namespace

import pytest
import yaml

from cli_runs import run_cli, small_config_file
from pipeline.cli import build_parser, join_signed_values, main
from pipeline.cli.next_steps import fallback_steps
from pipeline.cli.plans import plan_options
from pipeline.config import load_config

RECT = "0,0 60,0 60,40 0,40"  # four resting states, two sets after one pin: no orientation
RECT_ARGS = ["plan", "--vertices", RECT, "--name", "rect", "--depth", "1", "--speeds", ""]


def _tiny_config(root) -> dict:
    """The embedded config cut down to seconds: two candidate pins, one friction,
    fixed pins only, few trials."""
    c = load_config(None)
    c.pop("name")  # named after its file
    c.update(catalog_dir=str(root / "cat"), results_dir=str(root / "res"))
    c["planner"].update(pins=[7.5, 27.5], depth=2, mu_c=0, frictions=[])
    c["planner"]["dynamic"]["depth"] = 0
    c["verify"]["trials"] = 5
    c["speed"]["trials"] = 3
    return c


@pytest.fixture(scope="module")
def rect(tmp_path_factory):
    """The rectangle planned once with a tiny search: (folder, config file, printed text, stored plan)."""
    root = tmp_path_factory.mktemp("next_steps")
    config = root / "tiny.yaml"
    config.write_text(yaml.safe_dump(_tiny_config(root)))
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert main([*RECT_ARGS, "--config", str(config)]) == 0
    stored = json.loads((root / "res" / "tiny" / "plans" / "rect.json").read_text())
    return root, config, text.getvalue(), stored


def _steps(text: str) -> dict:
    """The suggestions after a plan that does not orient: first words -> (why, command or None)."""
    block = text.split("what may still work:\n", 1)[1].split("\nor look at the plan as it is", 1)[0]
    steps, lines = {}, block.splitlines()
    for k, line in enumerate(lines):
        if line.startswith("  ") and not line.startswith("      "):
            command = lines[k + 1].strip() if k + 1 < len(lines) and lines[k + 1].startswith("      ") else None
            steps[" ".join(line.split()[:2])] = (line.strip(), command)
    return steps


def _parses(command: str):
    words = shlex.split(command)
    assert words[0] == "pinfeed"
    return build_parser().parse_args(join_signed_values(words[1:]))


def test_a_plan_that_does_not_orient_leads_to_what_may_still_work(rect, capsys):
    root, config, text, stored = rect
    assert not stored["tight"][0]["orients"]
    assert "this plan does not orient rect within 10 deg; what may still work:" in text
    steps = _steps(text)
    assert list(steps) == ["more verification", "a force/torque", "moving pins", "more pins", "a wider"]
    # 5 trials per state cannot carry a 99.5 % claim: the config's verify.trials is named
    assert "raise verify.trials in " + str(config) in steps["more verification"][0]
    assert steps["more verification"][1] is None
    # One pin leaves two sets, one per pair of resting states: a sensor on P1 tells which.
    why, sense = steps["a force/torque"]
    assert "(P1 at 7.5 mm)" in why and "which of the 2 sets" in why
    assert sense == f"pinfeed sense classify --part rect --profile PROFILE.csv --config {config}"
    # --speeds '' searched fixed pins only: moving pins, from the config's sweep.v_pin
    args = _parses(steps["moving pins"][1])
    assert (args.speeds, args.dynamic_depth, args.depth, args.vertices) == ("-2,-1,1,2", 2, 1, RECT)
    assert _parses(steps["more pins"][1]).depth == 2
    assert "(this search tried up to 1)" in steps["more pins"][0]
    assert "each pin more" not in steps["more pins"][0]
    args = _parses(steps["a wider"][1])
    assert args.pins.startswith("-") and (args.speeds, args.depth) == ("", 1)
    # every suggestion repeats the command that ran, with one change
    for _, command in steps.values():
        if command and command.startswith("pinfeed plan"):
            assert f"--vertices '{RECT}' --name rect --config {config}" in command
    # The trials of the best plan spread over 54 deg and more: no looser tolerance
    assert not any("tolerance" in why for why, _ in steps.values())
    # then the plan as it is
    after = text.split("or look at the plan as it is (it leaves the part in several orientations):\n", 1)[1]
    assert [shlex.split(ln.replace("next: ", ""))[1] for ln in after.splitlines()] == ["speed", "layout", "animate"]

    # the sensor's command runs as printed on a measured profile
    profile = root / "run1.csv"
    profile.write_text("t,fx,fy\n0,0,0\n0.1,0.2,0.1\n0.2,0.5,0.2\n0.3,0.3,0.1\n0.4,0,0\n")
    code, out, err = run_cli(capsys, shlex.split(sense.replace("PROFILE.csv", str(profile)))[1:])
    assert code == 0, err
    assert "sensor pin at y = 7.5 mm" in out and "verdict:" in out


def _fallback(stored, config, **args):
    """The suggestions for a (changed) stored plan, as ``why -> command``."""
    ns = Namespace(**{a.dest: a.default for a in plan_options()})
    ns.__dict__.update(vertices=RECT, name="rect", config=str(config), depth=1, speeds="", **args)
    out = config.parent / "res" / "tiny" / "plans" / "rect.json"
    return dict(fallback_steps(stored, out, load_config(config), ns, plan_options()))


def _first(steps, start):
    found = [(why, cmd) for why, cmd in steps.items() if why.startswith(start)]
    return found[0] if found else None


def test_only_what_applies_is_suggested(rect):
    _, config, _, stored = rect
    assert len(_fallback(stored, config)) == 5
    changed = copy.deepcopy(stored)
    tight = changed["tight"][0]
    # moving pins already searched; the search as deep as the embedded config's; the fitted grid
    tight["moving_pin_search"] = {"orients": False, "depth": 1}
    tight["depth"] = load_config(None)["planner"]["depth"]
    from pipeline.parts.part import Part
    from pipeline.planning.core.settings import fitted_pins
    tight["pins_used"] = fitted_pins(Part.from_dict(stored["part"]))
    for level in tight["fixed_pin_search"]["levels"]:
        level.pop("too_few_trials", None)
    steps = _fallback(changed, config)
    assert _first(steps, "moving pins") is None and _first(steps, "a wider") is None
    assert _first(steps, "more verification") is None
    why, command = _first(steps, "more pins")
    assert "each pin more multiplies the search" in why and "--depth 5" in command
    # every verified trial of a plan within 13.2 deg: a looser tolerance of 13.5 deg
    tight["plans"][1]["verification"]["orientation"]["spread_deg"] = 13.2
    why, command = _first(_fallback(changed, config), "a looser tolerance")
    assert f"of {' '.join(tight['plans'][1]['pins'])} ends within 13.2 deg" in why
    assert _parses(command).tolerance == 13.5
    # a near miss: more trials may show it
    tight["recommended"]["verification"]["orientation"]["point_rule"] = True
    assert "near miss" in _first(_fallback(changed, config), "more verification")[0]
    # a sensor on a moving first pin, or one resting state per set unknown to it: no sensor
    tight["recommended"]["pin_speeds"] = [2.0]
    assert _first(_fallback(changed, config), "a force/torque") is None
    tight["recommended"]["pin_speeds"] = [0.0]
    states = tight["recommended"]["initial_states"]
    states["state 1"] = states["state 1"] + states["state 2"]  # state 1 may end in either set
    assert _first(_fallback(changed, config), "a force/torque") is None


def test_a_plan_that_orients_leads_to_speed_layout_animate(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    config = small_config_file(tmp_path)  # verify.rule point: 20 trials per state may claim it
    code, out, err = run_cli(capsys, ["plan", "--config", str(config), "--vertices", "0,0 60,0 60,12 0,12",
                                      "--name", "bar", "--depth", "2", "--pins=4,32", "--mu-c", "0.15",
                                      "--dynamic-depth", "0", "--tolerance", "12"])
    assert code == 0, err
    stored = json.loads((tmp_path / "results" / "small" / "plans" / "bar.json").read_text())
    assert stored["tight"][0]["orients"]
    assert "does not orient" not in out and "what may still work" not in out
    after = out[out.index("next: "):].splitlines()
    assert [shlex.split(ln.replace("next: ", ""))[1] for ln in after] == ["speed", "layout", "animate"]


def test_atlas_names_the_config_once(rect, capsys):
    from pipeline.workflow.atlas import build_atlas, write_atlas
    root, config, _, _ = rect
    results = root / "res" / "tiny"
    write_atlas(build_atlas(load_config(config), [results / "plans" / "rect.json"]),
                results / "atlas.json", results / "atlas.csv")
    code, out, err = run_cli(capsys, ["atlas", "--config", str(config)])
    assert code == 0, err
    assert out.splitlines()[0] == (f"feedability atlas of the config 'tiny' ({results / 'atlas.json'}): "
                                   f"tolerance 10 deg, depth 2")
