"""Presentation draws: ``pipeline/present`` replays no physics.

What a figure, a drawing or an animation shows from the physics (rollouts,
trials, lanes, a layout's stations and pitch, a contact's motion) is computed
below it, by the planner (``pipeline.planning``, mostly its ``feeder`` wing)
or by the workflow stage that calls both, and passed in. So no module under
``pipeline/present`` may

- import the rollout API or the map sweeps (``pipeline.maps.simulate``,
  ``sweep``, ``mujoco_rig``);
- import the kernels, except named constants of ``kernels.rollout`` (the
  outcome codes ``OK``, ``MISS``, ``JAMMED``, ``TRUNCATED`` a map figure
  colours by);
- import or call the planner's functions that roll parts past pins (trials,
  replays, verification, speed curves, lanes, the layout design).

Imports are read from the source (``ast``), including those inside
functions, so a lazy import cannot hide a replay.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from test_layers import MODULES, imports

PRESENT = "pipeline.present"
ROLLOUT_MODULES = ("pipeline.maps.simulate", "pipeline.maps.sweep", "pipeline.maps.mujoco_rig")
KERNEL_CONSTANTS = "kernels.rollout"
# The planner's functions that run rollouts (or lay out from them): present may neither
# import nor call them.
ROLLING = {
    "speed_curve", "perturbed_batch", "perturbed_inputs", "corner_inputs", "replay", "verify_plan",
    "replayed_paths", "run_trials", "trial_lanes", "build_lane", "roll_plan", "station_scene",
    "layout_plan", "layout_stored", "place_stations", "best_coarse_plan", "coarse_plan_paths",
    "mechanics_scene", "rollout", "rollout_points", "dynamic_rollout", "compute_map",
    "nominal_path", "contact_motion", "plan_tight_all", "support_study",
}


def present_modules() -> dict:
    """module name -> path of every module under ``pipeline/present``."""
    return {m: p for m, p in MODULES.items() if m == PRESENT or m.startswith(PRESENT + ".")}


def replays(module: str, path: Path) -> list[str]:
    """What in ``path`` (module ``module``) computes physics instead of drawing it."""
    found = []
    for line, target, name, _ in imports(module, path):
        if target in ROLLOUT_MODULES or any(target.startswith(m + ".") for m in ROLLOUT_MODULES):
            found.append(f"line {line}: imports {target}" + (f" ({name})" if name else ""))
        elif target.split(".")[0] == "kernels" and not (
                target == KERNEL_CONSTANTS and name is not None and name.isupper()):
            found.append(f"line {line}: imports {target}" + (f".{name}" if name else "")
                         + " (only the constants of kernels.rollout)")
        elif target.startswith("pipeline.") and name in ROLLING:
            found.append(f"line {line}: imports {name} from {target}")
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Call):
            f = node.func
            called = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
            if called in ROLLING:
                found.append(f"line {node.lineno}: calls {called}")
    return found


def test_there_are_present_modules():
    assert {"pipeline.present.layout", "pipeline.present.animate",
            "pipeline.present.figures.carried"} <= set(present_modules())


@pytest.mark.parametrize("module", sorted(present_modules()))
def test_present_only_draws(module):
    found = replays(module, present_modules()[module])
    assert not found, (f"{module} computes physics; compute it in the planner (pipeline.planning, "
                       f"its feeder wing) or the workflow stage and pass it in: {found}")


@pytest.mark.parametrize("source, caught", [
    ("from pipeline.maps import simulate\n", "imports pipeline.maps.simulate"),
    ("def f():\n    from pipeline.maps.simulate import contact_motion\n", "imports pipeline.maps.simulate"),
    ("from kernels.rollout import rollout_kernel\n", "only the constants"),
    ("import kernels.dynamic\n", "only the constants"),
    ("from pipeline.planning import run_trials\n", "imports run_trials"),
    ("import pipeline.planning as pp\npp.station_scene(1, 2, 3, 4)\n", "calls station_scene"),
])
def test_the_check_would_fail(tmp_path, source, caught):
    # A present module that replays physics is caught (the test above is not vacuous) ...
    probe = tmp_path / "probe.py"
    probe.write_text(source)
    found = replays("pipeline.present.probe", probe)
    assert any(caught in f for f in found), found
    with pytest.raises(AssertionError, match="computes physics"):
        assert not found, f"pipeline.present.probe computes physics: {found}"


def test_constants_and_drawing_pass(tmp_path):
    # ... while drawing from what is passed in, with the outcome codes, is not.
    probe = tmp_path / "probe.py"
    probe.write_text("from kernels.rollout import JAMMED, OK\nfrom pipeline.planning import pin_height\n"
                     "def draw(lane):\n    return pin_height(lane, 0, 1.0, 2.0, 0.0, 3.0), JAMMED, OK\n")
    assert replays("pipeline.present.probe", probe) == []
