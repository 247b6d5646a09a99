"""Dynamic pins (spec section 8): pins that move across the belt, and plans that use them.

The kernel is checked three ways: a pin speed of 0 is the static pin bit for
bit; mirroring the scene negates the pin speed with everything else; and a
moving pin is a static pin in a rotated frame. In the belt frame the part
rests and the pin moves along u = (-1, v) (v = v_pin / v_b). The quasi-static
model has no time scale, so rotating the whole scene by beta = atan(v) turns
it into a static-pin problem: the part starts at theta_i + beta, the pin's
path lies d a cos(beta) from the centroid, and the part ends at
theta_f + beta. Hence

    theta_f(theta_i, d, v) = theta_f_static(theta_i + beta, d / sqrt(1 + v^2)) - beta.

No code path is shared between the two sides but the kernel itself, with a
different pin path and different integration steps.
"""
from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import assume, given
from hypothesis import strategies as st

from images import assert_animation, assert_png_figure
from conftest import fewer_examples
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.paper.planner import Planner, load_maps
from pipeline.planning.core.settings import VerifySettings, candidate_pins
from pipeline.planning.paper.planner import dynamic_label
from pipeline.planning.claims.verify import verify_plan
from test_invariants import (R_PIN, _contact_fraction, assert_maps_agree, d_values, models,
                             mu_values, parts, theta_grid)

ROOT = Path(__file__).resolve().parents[2]
speeds = st.floats(0.3, 2.5).flatmap(lambda v: st.sampled_from([v, -v]))


# ------------------------------------------------------------------ kernel

# Each example sweeps a map of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(part=parts(), theta=theta_grid(30.0), d=d_values(), mu_c=mu_values, model=models)
def test_speed_zero_is_the_static_pin_bit_for_bit(part, theta, d, mu_c, model):
    static = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model)
    for v in (0.0, -0.0):
        zero = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model, v_pin=v)
        for name in ("status", "theta_f", "dy", "contact_travel", "peak_force"):
            np.testing.assert_array_equal(zero[name].values, static[name].values, err_msg=name)


# Each example sweeps a map of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(part=parts(), theta=theta_grid(30.0), d=d_values(), mu_c=mu_values, model=models, v=speeds)
def test_mirror_negates_the_pin_speed(part, theta, d, mu_c, model, v):
    # Reflecting y -> -y maps the part to its mirror at -theta_i, the pin to
    # -d moving at -v, and the outcome to -theta_f, -dy.
    base = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model, v_pin=v)
    assume(_contact_fraction(base) > 0.3)
    got = simulate.compute_map(part.mirrored(), np.mod(-theta, 360.0), -d, mu_c, R_PIN, model=model, v_pin=-v)
    assert_maps_agree(base, part, mu_c, model, R_PIN, -base.theta_f.values, -base.dy.values, got,
                      v_pin=v)


# Each example sweeps a map of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(part=parts(), theta=theta_grid(30.0), d=d_values(), mu_c=mu_values, model=models, v=speeds)
def test_moving_pin_is_a_static_pin_in_a_rotated_frame(part, theta, d, mu_c, model, v):
    beta = math.degrees(math.atan(v))
    moving = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model, v_pin=v)
    assume(_contact_fraction(moving) > 0.3)
    d_static = d / math.sqrt(1.0 + v * v)
    rotated = [simulate.compute_map(part, [(t + beta) % 360.0], d_static, mu_c, R_PIN, model=model)
               for t in theta]
    got = moving.copy(deep=True)
    got["status"].values[:] = np.stack([r.status.values[:, 0] for r in rotated], axis=1)
    got["theta_f"].values[:] = np.stack([r.theta_f.values[:, 0] for r in rotated], axis=1) - beta
    assert_maps_agree(moving, part, mu_c, model, R_PIN, moving.theta_f.values, None, got, v_pin=v)


@pytest.mark.parametrize("vertices", [[(0, 0), (60, 0), (15, 35)], [(0, 0), (40, 0), (20, 60)],
                                      [(0, 0), (40, 0), (40, 10), (10, 10), (10, 30), (0, 30)]])
def test_moving_pin_displacement_is_the_rotated_static_one(vertices):
    # The rotated static problem also gives the displacement: the moving pin's dy
    # is the y part of the static displacement (x, y) turned back by -beta.
    part = Part.from_vertices(vertices)
    compared = 0
    for theta_i in range(0, 360, 40):
        for d, v in ((0.4, 1.0), (-0.5, -2.0), (0.3, 0.5), (-0.7, 1.5)):
            beta = math.atan(v)
            moving = simulate.rollout(part, theta_i, d, 0.15, R_PIN, v_pin=v)
            static = simulate.rollout(part, theta_i + math.degrees(beta), d / math.sqrt(1 + v * v), 0.15,
                                      R_PIN, trajectory=True)
            if moving.status.item() != "ok" or static.status.item() != "ok":
                continue
            if abs((float(moving.theta_f) + math.degrees(beta) - float(static.theta_f) + 180) % 360 - 180) > 0.05:
                continue  # at a band jump the two sides may legitimately differ
            x, y = float(static.traj_x.values[-1]), float(static.traj_y.values[-1])
            assert float(moving.dy) == pytest.approx(-math.sin(beta) * x + math.cos(beta) * y, abs=0.02)
            compared += 1
    assert compared >= 20


def test_moving_pin_changes_the_outcome():
    """The speed is not ignored: the default asymmetric triangle ends elsewhere
    when the pin moves."""
    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)])
    static = simulate.rollout(part, 30.0, 0.4, 0.15, R_PIN)
    moving = simulate.rollout(part, 30.0, 0.4, 0.15, R_PIN, v_pin=1.0)
    assert static.status.item() == moving.status.item() == "ok"
    assert abs(float(moving.theta_f) - float(static.theta_f)) > 1.0


# ------------------------------------------------------------------ planning with dynamic pins

def _default_config():
    with open(ROOT / "config" / "config.yaml") as fh:
        return yaml.safe_load(fh)


def _default_part(name):
    cfg = _default_config()
    spec = next(p for fam in cfg["families"].values() for p in fam.get("parts", []) if p["name"] == name)
    return Part.from_vertices(spec["vertices"], name=name)


PAPER_MU = 0.15  # the stored friction nearest the middle of the default range 0.1:0.3
PAPER_DEPTH = 3


@pytest.fixture(scope="module")
def default_planners():
    """Planners of the default config's two triangles: its d grid, theta step,
    pins, friction, bands and dynamic speeds."""
    cfg = _default_config()
    sw, pc, bc = cfg["sweep"], cfg["planner"], cfg["bands"]
    theta = np.arange(0.0, 360.0, sw["theta_step"])
    out = {}
    for name in ("asym_triangle", "sym_triangle"):
        part = _default_part(name)

        def maps(v, part=part):
            ds = simulate.compute_map(part, theta, sw["d"], PAPER_MU, sw["pin_radius"], model=pc["model"], v_pin=v)
            return load_maps(ds, bc["threshold_T"], bc["factor_c"])

        static = candidate_pins(part, pc["pins"])
        vs = [float(v) for v in pc["dynamic"]["speeds"]]
        dynamic = {dynamic_label(k, v): (y, v) for k, y in static.items() for v in vs}
        out[name] = Planner(part, maps(0.0), static, pc["d_min"], pc["d_max"], coverage=pc["coverage"],
                            dynamic=dynamic, dynamic_maps={v: maps(v) for v in vs})
    return cfg, out


def _search(cfg, planner, dynamic=True):
    pc = cfg["planner"]
    return planner.search(PAPER_DEPTH, keep=5, dynamic_depth=pc["dynamic"]["depth"] if dynamic else 0,
                          dynamic_beam=pc["dynamic"]["beam"])


@pytest.mark.parametrize("name", ["sym_triangle", "asym_triangle"])
def test_dynamic_pins_bring_default_triangles_to_one_orientation(default_planners, name):
    cfg, planners = default_planners
    planner = planners[name]
    best = _search(cfg, planner)[0]
    assert best.n_sets == 1 and best.n_dynamic >= 1
    # What each pin adds: the static pins leave two sets, the moving pins merge them.
    n_static = len(best.pins) - best.n_dynamic
    assert best.sets_after[n_static - 1] == 2 and best.sets_after[-1] == 1
    assert all(planner.speeds[p] != 0.0 for p in best.pins[n_static:])
    # Full rollouts with perturbed inputs confirm the single orientation set.
    res = verify_plan(planner.part, best.to_dict(), planner.pins, planner.initial_states(),
                      PAPER_MU, cfg["sweep"]["pin_radius"], cfg["planner"]["model"],
                      settings=replace(VerifySettings.from_section(cfg["verify"]), trials=30, corners=False),
                      speeds=planner.speeds)
    for row in res["rows"]:
        assert row["trials"] == 30 and row["successes"] >= 28, row


# ------------------------------------------------------------------ command line

def test_cli_plan_with_a_moving_pin_stores_its_maps(tmp_path, capsys):
    from pipeline.cli import main
    from pipeline.maps.catalog import Catalog
    cat = tmp_path / "cat"
    base = ["plan", "--vertices", "0,0 40,0 40,20 0,20", "--name", "rect", "--catalog", str(cat),
            "--depth", "1", "--pins=-5,5,15,25,35", "--mode", "paper"]
    assert main(base + ["--speeds", "-1.5", "--dynamic-depth", "1", "--out", str(tmp_path / "p.json")]) == 0
    capsys.readouterr()
    res = json.loads((tmp_path / "p.json").read_text())
    assert res["pin_speeds"] and set(res["pin_speeds"].values()) == {-1.5}
    assert all(label.endswith("v-1.5") for label in res["pin_speeds"])
    speeds = {e["v_pin"] for e in Catalog.open(cat).entries}
    assert speeds == {0.0, -1.5}  # the moving pin's maps were computed and indexed
    assert main(["catalog", "query", "--catalog", str(cat), "--part", "rect", "--mu-c", "0.15",
                 "--d", "0.3", "--theta-i", "0", "--v-pin", "-1.5", "--json"]) == 0
    q = json.loads(capsys.readouterr().out)
    assert q["v_pin"] == -1.5 and len(q["rows"]) == 1
    assert main(["catalog", "query", "--catalog", str(cat), "--part", "rect", "--v-pin", "3"]) == 2
    assert "no minpower maps at v_pin/v_b = 3" in capsys.readouterr().err
    assert main(base + ["--speeds", "0"]) == 2
    assert main(base + ["--dynamic-depth", "-1"]) == 2


def test_config_speeds_must_be_swept():
    from pipeline.config import validate_config
    from pipeline.errors import PinfeedError
    cfg = _default_config()
    cfg["planner"]["dynamic"]["speeds"] = [-2.0, 3.0]
    with pytest.raises(PinfeedError, match="planner/dynamic/speeds: 3 must be non-zero and listed in sweep/v_pin"):
        validate_config(cfg)
    cfg["planner"]["dynamic"]["speeds"] = [0.0]
    with pytest.raises(PinfeedError, match="planner/dynamic/speeds: 0 must be non-zero"):
        validate_config(cfg)
    cfg["planner"]["dynamic"]["speeds"] = [-2.0]
    cfg["sweep"]["v_pin"] = [-2.0]
    with pytest.raises(PinfeedError, match="sweep/v_pin: the planner needs static maps; add 0"):
        validate_config(cfg)


# ------------------------------------------------------------------ workflow

def test_workflow_plans_verifies_and_draws_moving_pins(tmp_path):
    """The whole downstream chain on a small sweep with one moving-pin speed:
    plan, verify (both plans), sensing, figures (maps by speed, both sequence
    diagrams) and the report."""
    from workflow_runs import run_snakemake as _snakemake
    cfg = {
        "catalog_dir": "cat", "results_dir": "res",
        "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]}]}},
        "sweep": {"models": ["ellipsoid"], "mu_c": [0.2], "v_pin": [0.0, -1.5],
                  "d": [-0.8, -0.6, -0.4, -0.2, 0.2, 0.4, 0.6, 0.8], "theta_step": 10, "pin_radius": 3.0},
        "planner": {"parts": ["tri"], "model": "ellipsoid", "mu_c": 0.2, "depth": 1,
                    "pins": [-10, -5, 0, 5, 10, 15, 20, 25, 30, 35, 40],
                    "dynamic": {"speeds": [-1.5], "depth": 1}},
        "verify": {"trials": 3, "rule": "point"}, "sensing": {"trials": 3}, "figures": {"d": [0.4], "animation_frames": 3},
    }
    (tmp_path / "cfg.yaml").write_text(yaml.safe_dump(cfg))
    run = _snakemake(tmp_path, "--configfile", str(tmp_path / "cfg.yaml"))
    assert run.returncode == 0, run.stderr[-3000:]
    plan = json.loads((tmp_path / "res" / "cfg" / "plans" / "tri.json").read_text())
    assert plan["pin_speeds"] == {f"P{k}v-1.5": -1.5 for k in range(1, 12)}
    assert plan["best_static"]["n_dynamic_pins"] == 0
    for p in plan["plans"]:  # what each pin adds, and moving pins only at the end
        assert len(p["sets_after_each_pin"]) == len(p["pins"]) and p["sets_after_each_pin"][-1] == p["n_final_sets"]
        kinds = [q in plan["pin_speeds"] for q in p["pins"]]
        assert kinds == sorted(kinds) and sum(kinds) == p["n_dynamic_pins"]
    checks = json.loads((tmp_path / "res" / "cfg" / "verify" / "tri.json").read_text())["checks"]
    want = ["paper mode, fixed pins"] + (["paper mode, with dynamic pins"] if plan["plans"][0]["n_dynamic_pins"] else [])
    want += ["tight, mu_c 0.2"] if plan["tight"][0]["recommended"] else []
    assert [c["kind"] for c in checks] == want
    assert all(r["trials"] == 3 + 2 ** (3 + len(c["plan"])) for c in checks for r in c["rows"])
    figures = tmp_path / "res" / "cfg" / "figures"  # results_dir/<config file's stem>
    dynamic = bool(plan["plans"][0]["n_dynamic_pins"])
    for kind in ("maps", "speeds", "sequence", "sequence_dynamic", "profiles", "scores"):
        if kind == "sequence_dynamic" and not dynamic:  # a one-line placeholder says so
            assert_png_figure(figures / f"{kind}_tri.png", min_height=100, min_ink=0.001, axes=False)
        else:
            assert_png_figure(figures / f"{kind}_tri.png")
    assert_animation(tmp_path / "res" / "cfg" / "animations" / "tri.gif", min_frames=3)
    page = (tmp_path / "res" / "cfg" / "report.html").read_text()
    assert "speeds_tri.png" in page and "sequence_dynamic_tri.png" in page and "sets after each pin" in page
