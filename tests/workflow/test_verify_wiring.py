"""The verify stage replays each plan at the friction it was planned for.

A plan found at mu_c = 0.37 and then checked at mu_c = 0 (or at some
hard-coded value) would be "verified" for a feeder nobody builds, and the
verification would still look green. These tests run the verify rule's
script (rules/scripts/verify.py -> pipeline.workflow.plan.verify ->
verify_part) with a spy in place of ``verify_plan`` and check the friction
every call receives: the paper-mode plans at the plan's (the config's)
mu_c, each tight plan at its own friction (a value or a range).
"""
from __future__ import annotations

import inspect
import json
import runpy
from pathlib import Path
from types import SimpleNamespace

import pytest

from conftest import TRIANGLE
from pipeline.planning.claims.verify import verify_plan

ROOT = Path(__file__).resolve().parents[2]
CONFIG_MU = 0.37  # an unusual value: no default or fallback equals it
TIGHT_MU = [0.25, 0.35]


def _tight_entry(friction, mu_c, pins, height):
    """A stored tight-planner entry (the keys the plan schema requires) recommending ``pins``."""
    plan = {"pins": pins, "pin_heights_mm": [height], "pin_speeds": [0.0], "final_sets": [],
            "initial_states": {}}
    return {"friction": friction, "mu_c": mu_c, "belt_speed": None, "mu_s": None,
            "plans": [plan], "recommended": plan, "warning": None}


def _plan_result():
    plan = {"pins": ["A", "B"], "n_final_sets": 1, "n_dynamic_pins": 0, "final_sets": [],
            "initial_states": {}}
    return {
        "part": {"name": "tri", "vertices": [list(v) for v in TRIANGLE]},
        "model": "minpower", "mu_c": CONFIG_MU, "pins": {"A": 5.0, "B": 20.0}, "pin_speeds": {},
        "initial_states": {"state 1": {"theta": 0.0, "y_c": 10.0}},
        "plans": [plan], "best_static": plan,
        "tight": [_tight_entry("0.25:0.35", TIGHT_MU, ["A"], 7.5), _tight_entry("0.1", 0.1, ["B"], 12.5)],
    }


@pytest.fixture
def received(monkeypatch):
    """The mu_c of every verify_plan call the verify stage makes."""
    import pipeline.workflow.plan as wf
    seen = []
    signature = inspect.signature(verify_plan)

    def spy(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        seen.append((bound.arguments["plan"]["pins"], bound.arguments["mu_c"]))
        return {"plan": bound.arguments["plan"]["pins"], "rows": [], "trials_detail": [],
                "mu_c": bound.arguments["mu_c"]}

    monkeypatch.setattr(wf, "verify_plan", spy)
    return seen


def _config():
    from pipeline.config import load_config
    config = load_config(None)
    config["planner"].update(model="minpower", mu_c=CONFIG_MU)
    config["sweep"]["pin_radius"] = 3.0
    config["verify"].update(trials=3, rule="point")
    return config


def _check(seen):
    mus = {tuple(pins): mu for pins, mu in seen}
    assert set(mus) == {("A", "B"), ("A",), ("B",)}, seen
    assert mus[("A", "B")] == CONFIG_MU, f"paper plan verified at mu_c {mus[('A', 'B')]}, planned at {CONFIG_MU}"
    assert tuple(mus[("A",)]) == tuple(TIGHT_MU), f"tight plan verified at {mus[('A',)]}"
    assert mus[("B",)] == 0.1


def test_verify_part_passes_the_planned_friction(received):
    from pipeline.workflow.plan import verify_part
    from pipeline.planning import PlannerSettings
    verify_part(_plan_result(), PlannerSettings.from_config(_config()))
    _check(received)


def test_verify_rule_script_passes_the_planned_friction(received, tmp_path):
    """The Snakemake script itself, with a stand-in ``snakemake`` object."""
    plan_path = tmp_path / "plan.json"
    plan_path.write_text(json.dumps(_plan_result()))
    out = tmp_path / "verify.json"
    snakemake = SimpleNamespace(input=SimpleNamespace(plan=str(plan_path)), config=_config(),
                                output=SimpleNamespace(verify=str(out)), log=[str(tmp_path / "v.log")])
    runpy.run_path(str(ROOT / "rules" / "scripts" / "verify.py"), init_globals={"snakemake": snakemake})
    _check(received)
    written = json.loads(out.read_text())
    assert [c["mu_c"] for c in written["checks"]] == [CONFIG_MU, TIGHT_MU, 0.1]
