"""Typed plan records (``pipeline.planning.core.types`` and
``pipeline.planning.core.plan_records``) and the schema of stored plan
files: files written by the current code validate and round-trip exactly;
hand-broken files are refused with the one-line error naming the file."""
from __future__ import annotations

import copy
import json

import numpy as np
import pytest
import xarray as xr
import yaml

from kernels.rollout import OK
from pipeline.errors import PinfeedError
from pipeline.maps.io import write_json
from pipeline.parts.part import Part
from pipeline.planning.paper.planner import Planner, load_maps
from pipeline.planning.core.plan_records import Plan, Step, Verification
from pipeline.planning.core.types import (SCHEMA_PATH, PlanFile, TightEntry, load_plan, plan_schema,
                                          validate_plan_dict, validate_plan_file)

VERTICES = "0,0 60,0 15,35"


@pytest.fixture(scope="module")
def tight_file(tmp_path_factory):
    """A plan file written by 'pinfeed plan' (tight planner, two pins, depth 2,
    few verification trials so that the test stays quick)."""
    from pipeline.cli import main
    from pipeline.config import load_config
    root = tmp_path_factory.mktemp("plan")
    config = load_config(None)  # its outline paths resolved
    config["verify"]["trials"] = 10
    config["planner"]["dynamic"]["depth"] = 0
    cfg = root / "config.yaml"
    cfg.write_text(yaml.safe_dump(config))
    out = root / "res" / "plans" / "tri.json"
    assert main(["plan", "--config", str(cfg), "--vertices", VERTICES, "--name", "tri",
                 "--catalog", str(root / "cat"), "--depth", "2", "--pins=7.5,27.5", "--mu-c", "0",
                 "--out", str(out)]) == 0
    return out


RECT = Part.from_vertices([(0, 0), (40, 0), (40, 20), (0, 20)], name="rect")


def _paper_file() -> dict:
    """A paper-mode plan file as ``workflow.plan.plan_part`` lays it out, from
    the paper planner on hand-made maps (every pin above the centroid turns
    the part to 45 deg; below, to 45 or 225 deg)."""
    grid = np.arange(0.0, 360.0, 1.0)
    d = np.round(np.concatenate([np.arange(-0.9, -0.05, 0.1), np.arange(0.1, 0.95, 0.1)]), 3)
    tf = np.where(d[:, None] > 0, 45.0, np.where(grid[None, :] < 180, 45.0, 225.0))
    dy = np.where(d[:, None] > 0, -2.0, 2.0) + 0 * tf
    st = np.full(tf.shape, OK, dtype=np.int8)
    ds = xr.Dataset({"theta_f": (("d", "theta_i"), tf), "dy": (("d", "theta_i"), dy),
                     "status": (("d", "theta_i"), st)}, coords={"d": d, "theta_i": grid})
    pins = {"low": 20 - 0.5 * RECT.a, "best": 15 + 0.5 * RECT.a}
    planner = Planner(RECT, load_maps(ds, 5.0, 2.0), pins, 0.1, 0.9)
    plans = planner.search(2)
    states = planner.initial_states()
    return {"part": RECT.to_dict(), "model": "minpower", "mu_c": 0.15, "selection": "hand-made maps",
            "pins": planner.pins, "pin_speeds": {}, "depth": 2, "dynamic_depth": 0,
            "d_min": 0.1, "d_max": 0.9, "coverage": planner.coverage,
            "best_static": plans[0].to_dict(),
            "initial_states": {k: {"theta": s.arc[0], "y_c": s.y_lo} for k, s in states.items()},
            "plans": [p.to_dict() for p in plans], "found": True, "tight": []}


def test_the_schema_is_package_data():
    import tomllib
    from pathlib import Path
    pyproject = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())
    assert SCHEMA_PATH.name in pyproject["tool"]["setuptools"]["package-data"]["pipeline.planning.core"]
    assert plan_schema()["type"] == "object"


def test_a_stored_tight_plan_file_validates_and_round_trips(tight_file):
    data = json.loads(tight_file.read_text())
    assert validate_plan_file(tight_file) == data
    typed = load_plan(tight_file)
    assert typed.to_dict() == data
    assert PlanFile.from_dict(typed.to_dict()) == typed
    # Written back, the file is the same text.
    again = tight_file.parent / "again.json"
    write_json(typed.to_dict(), again)
    assert again.read_text() == tight_file.read_text()
    # The records say what the dict says.
    entry = data["tight"][0]
    t = typed.tight[0]
    assert isinstance(t, TightEntry) and t.friction == entry["friction"] == "0"
    assert t.recommended is not None and t.recommended == t.plans[0]
    best = entry["plans"][0]
    assert t.recommended.pins == tuple(best["pins"]) and t.recommended.mode == "tight"
    assert t.recommended.heights() == best["pin_heights_mm"]
    assert isinstance(t.recommended.verification, Verification)
    assert t.recommended.verification.trials == best["verification"]["trials"] > 0
    assert t.recommended.final_arcs == [(s["start"], s["width"]) for s in best["final_sets"]]
    step = t.recommended.branches["state 1"][0][0]
    assert isinstance(step, Step) and step.carried is not None
    assert step.d_range == tuple(best["initial_states"]["state 1"][0][0]["d_range"])
    assert t.resting_states == {k: (v["theta"], v["y_c"]) for k, v in entry["initial_states"].items()}


def test_every_single_record_round_trips(tight_file):
    data = json.loads(tight_file.read_text())
    for entry in data["tight"]:
        assert TightEntry.from_dict(entry).to_dict() == entry
        for plan in entry["plans"] + entry["rejected"]:
            assert Plan.from_dict(plan).to_dict() == plan
            assert Verification.from_dict(plan["verification"]).to_dict() == plan["verification"]
            for branches in plan["initial_states"].values():
                for branch in branches:
                    for step in branch:
                        assert Step.from_dict(step).to_dict() == step


def test_a_paper_mode_plan_file_validates_and_round_trips(tmp_path):
    data = _paper_file()
    path = tmp_path / "rect.json"
    write_json(data, path)
    stored = json.loads(path.read_text())
    assert validate_plan_file(path) == stored
    typed = load_plan(path)
    assert typed.to_dict() == stored and PlanFile.from_dict(typed.to_dict()) == typed
    best = typed.plans[0]
    assert best.mode is None and best.verification is None and best.pin_heights_mm is None
    assert "mode" not in best.to_dict() and "verification" not in best.to_dict()
    assert best.heights(typed.pins) == [stored["pins"][p] for p in stored["plans"][0]["pins"]]
    assert all(s.carried is None for brs in best.branches.values() for br in brs for s in br)
    assert typed.extra["selection"] == "hand-made maps"


def test_unknown_keys_are_kept(tight_file):
    data = json.loads(tight_file.read_text())
    data["tight"][0]["plans"][0]["note"] = "kept"
    data["tight"][0]["plans"][0]["initial_states"]["state 1"][0][0]["extra_key"] = 1
    assert PlanFile.from_dict(validate_plan_dict(data)).to_dict() == data


def _broken(data, where, how):
    """A copy of ``data`` with the value at path ``where`` deleted or replaced."""
    out = copy.deepcopy(data)
    node = out
    for key in where[:-1]:
        node = node[key]
    if how == "delete":
        del node[where[-1]]
    else:
        node[where[-1]] = how
    return out


BROKEN = [
    (("part",), "delete", "(top level)", "'part' is a required property"),
    (("tight", 0, "plans", 0, "pins"), "delete", "tight/0/plans/0", "'pins' is a required property"),
    (("tight", 0, "friction"), "delete", "tight/0", "'friction' is a required property"),
    (("tight", 0, "plans", 0, "initial_states", "state 1", 0, 0, "y_pin"), "7.5",
     "tight/0/plans/0/initial_states/state 1/0/0/y_pin", "is not of type 'number'"),
    (("tight", 0, "plans", 0, "final_sets"), {"start": 1.0, "width": 2.0}, "tight/0/plans/0/final_sets",
     "is not of type 'array'"),
    (("tight", 0, "plans", 0, "verification", "trials"), 2.5, "tight/0/plans/0/verification/trials",
     "is not of type 'integer'"),
    (("tight", 0, "recommended", "verification"), "delete", "tight/0/recommended", "verification"),
    (("tight", 0, "mu_c"), [0.1, 0.2, 0.3], "tight/0/mu_c", ""),
]


@pytest.mark.parametrize("where,how,at,says", BROKEN)
def test_a_broken_plan_file_is_one_clear_line(tight_file, tmp_path, where, how, at, says):
    data = _broken(json.loads(tight_file.read_text()), where, how)
    path = tmp_path / "broken.json"
    path.write_text(json.dumps(data))
    with pytest.raises(PinfeedError) as err:
        load_plan(path)
    text = str(err.value)
    assert "\n" not in text and text.startswith(f"{path} is not a pinfeed plan file")
    assert f"(at {at}:" in text and says in text
    name = "NAME" if where == ("part",) else "tri"
    assert "make run" in text and f"pinfeed plan --part {name} --out {path}" in text


def test_a_file_with_neither_paper_nor_tight_plans_is_refused(tight_file):
    data = _broken(json.loads(tight_file.read_text()), ("tight",), "delete")
    with pytest.raises(PinfeedError, match="is not a pinfeed plan file"):
        validate_plan_dict(data, "x.json")


def test_consumers_refuse_a_broken_file_with_the_same_line(tight_file, tmp_path, capsys):
    from pipeline.cli import main
    data = _broken(json.loads(tight_file.read_text()), ("tight", 0, "plans", 0, "pins"), "delete")
    path = tmp_path / "res" / "plans" / "tri.json"
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps(data))
    assert main(["speed", "--part", "tri", "--results", str(tmp_path / "res"), "--trials", "2"]) == 2
    err = capsys.readouterr().err
    assert "is not a pinfeed plan file" in err and str(path) in err


def test_the_verify_stage_replays_the_recommended_tight_plan_as_stored(tight_file):
    # verify_part reads the tight entries as typed records: its check must be
    # the replay of the stored dict with the stored heights, speeds and friction.
    from pipeline.config import load_config
    from pipeline.planning.claims.verify import verify_plan
    from pipeline.workflow.plan import verify_part
    data = json.loads(tight_file.read_text())
    entry = data["tight"][0]
    data.update(initial_states=entry["initial_states"], plans=[], pins={}, mu_c=entry["mu_c"])
    config = load_config(None)
    config["verify"] = dict(config.get("verify", {}), trials=4, rule="point")
    from pipeline.planning import PlannerSettings
    out = verify_part(data, PlannerSettings.from_config(config))
    assert [c["kind"] for c in out["checks"]] == [f"tight, mu_c {entry['friction']}"]
    rec = entry["recommended"]
    want = verify_plan(Part.from_vertices(data["part"]["vertices"], name="tri"), rec,
                       dict(zip(rec["pins"], rec["pin_heights_mm"])),
                       {k: (v["theta"], v["y_c"]) for k, v in entry["initial_states"].items()},
                       entry["mu_c"], config["sweep"]["pin_radius"], data["model"],
                       PlannerSettings.from_config(config).verify,
                       kernel=PlannerSettings.from_config(config).search.kernel_step)
    want.pop("trials_detail")
    got = dict(out["checks"][0])
    got.pop("kind")
    assert got == want and got["plan"] == rec["pins"] and got["trials"] > 0


def test_a_minimal_plan_file_still_reads():
    # Only what every reader needs is required: pins and final sets of each
    # plan, the friction of each tight entry (older and hand-made files).
    plan = {"pins": ["P1"], "final_sets": [{"start": 10.0, "width": 2.0}]}
    data = {"part": RECT.to_dict(), "tight": [{"mu_c": [0.1, 0.3], "friction": "0.1:0.3", "plans": [plan]}]}
    typed = PlanFile.from_dict(validate_plan_dict(data))
    assert typed.tight[0].mu_c == (0.1, 0.3) and typed.tight[0].plans[0].final_arcs == [(10.0, 2.0)]
    assert typed.tight[0].plans[0].to_dict() == plan
    assert PlanFile.from_dict(typed.to_dict()) == typed
    with pytest.raises(PinfeedError, match="'plans' is a required property"):
        validate_plan_dict({"part": RECT.to_dict(), "tight": [{"mu_c": 0.1, "friction": "0.1"}]})


def test_a_verification_without_its_model_still_reads():
    # Plans verified before the replay model was recorded have no
    # verification.model; they read, and are written back as they were.
    verification = {"trials": 4, "successes": 4, "failures": 0,
                    "rows": [{"state": "state 1", "trials": 4, "successes": 4, "failures": 0, "reasons": {}}]}
    plan = {"pins": ["P1"], "final_sets": [{"start": 10.0, "width": 2.0}], "verification": verification}
    data = {"part": RECT.to_dict(), "tight": [{"mu_c": 0.2, "friction": "0.2", "plans": [plan]}]}
    typed = PlanFile.from_dict(validate_plan_dict(data))
    assert typed.tight[0].plans[0].verification.model is None
    assert typed.to_dict()["tight"][0]["plans"][0]["verification"] == verification
