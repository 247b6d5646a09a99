"""Replay plans with full rollouts under perturbations (the paper's Table 2).

Each trial starts from an initial resting state, perturbs the initial
orientation and centroid height, the friction and every pin's position
(normal for angles and friction, uniform for positions; sizes from the
config), then rolls the part past each pin of the plan in turn: ``theta`` and
``y_c`` carry over from one pin to the next. A trial succeeds when the final
orientation lies in the final orientation sets the plan predicts for that
initial state. Failures are counted by reason: ``jammed (<why>)``, ``missed
a pin`` (the plan expected a contact) and ``other band``.
"""
from __future__ import annotations

import math

import numpy as np

from kernels.models import MODEL_NAMES
from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL, JAM_REASONS, JAMMED, MISS, _rollout

from .bands import in_arc
from .parts import Part
from .planner import merge_arcs
from .progress import progress

PERTURB_DEFAULTS = {"theta_sigma": 1.0, "y_halfwidth": 0.5, "mu_sigma": 0.02, "pin_halfwidth": 0.3}
DEFAULTS = {"trials": 30, **PERTURB_DEFAULTS, "seed": 1}


def perturbed_inputs(theta, y_c, mu_c, n_pins, cfg, rng):
    """One trial's inputs: theta_i (normal), y_c (uniform), mu_c (normal, clipped
    at 0) and an offset for each of ``n_pins`` pins (uniform), sizes from ``cfg``."""
    return (theta + rng.normal(0.0, cfg["theta_sigma"]),
            y_c + rng.uniform(-cfg["y_halfwidth"], cfg["y_halfwidth"]),
            max(0.0, mu_c + rng.normal(0.0, cfg["mu_sigma"])),
            rng.uniform(-cfg["pin_halfwidth"], cfg["pin_halfwidth"], n_pins))


def _arc(step):
    return (step["band"]["start"], step["band"]["width"])


def _predicted_sets(plan: dict, label: str):
    return merge_arcs([_arc(branch[-1]) for branch in plan["initial_states"][label]])


def _expects_contact(plan: dict, label: str, k: int, start_arc) -> bool:
    # A step whose orientation set differs from the one before it needed the pin to touch.
    for branch in plan["initial_states"][label]:
        before = _arc(branch[k - 1]) if k > 0 else start_arc
        if _arc(branch[k]) != before:
            return True
    return False


def verify_plan(part: Part, plan: dict, pins: dict, initial_states: dict, mu_c: float,
                pin_radius: float, model: str = "minpower", settings: dict | None = None,
                speeds: dict | None = None, show_progress: bool = True) -> dict:
    """Run the trials for a plan (as stored: ``Plan.to_dict()``); returns per-state
    counts and every trial's outcome. ``speeds`` gives the speed ratio
    v_pin / v_b of each dynamic pin's label (absent: a static pin); the
    perturbation of a dynamic pin's position shifts its whole path.
    ``show_progress``: a bar on a terminal, a line per tenth in logs (stderr)."""
    speeds = speeds or {}
    cfg = dict(DEFAULTS, **(settings or {}))
    rng = np.random.default_rng(cfg["seed"])
    prep = part.prepared()
    model_code = MODEL_NAMES.index(model)
    rows, trials = [], []
    for label, state in progress(initial_states.items(), len(initial_states),
                                 f"verify {' '.join(plan['pins'])}", unit="initial state",
                                 enabled=show_progress):
        finals = _predicted_sets(plan, label)
        counts = {"state": label, "trials": 0, "successes": 0, "failures": 0, "reasons": {}}
        for _ in range(int(cfg["trials"])):
            theta, y_c, mu, offsets = perturbed_inputs(state.arc[0], state.y_lo, mu_c,
                                                       len(plan["pins"]), cfg, rng)
            reason, path = None, [(theta % 360.0, y_c)]
            for k, (pin, off) in enumerate(zip(plan["pins"], offsets)):
                d = (pins[pin] + off - y_c) / part.a
                res = _rollout(*prep, model_code, mu, pin_radius, math.radians(theta), d,
                               float(speeds.get(pin, 0.0)),
                               np.inf, DEFAULT_DS_MAX, DEFAULT_TOL, False)
                status, why = res[0], res[1]
                if status == JAMMED:
                    reason = f"jammed ({JAM_REASONS[why]})"
                    break
                if status == MISS and _expects_contact(plan, label, k, state.arc):
                    reason = "missed a pin"
                    break
                theta, y_c = math.degrees(res[2]), y_c + res[3]
                path.append((theta % 360.0, y_c))
            if reason is None and not any(in_arc(theta % 360.0, s, w, 1e-6) for s, w in finals):
                reason = "other band"
            counts["trials"] += 1
            if reason is None:
                counts["successes"] += 1
            else:
                counts["failures"] += 1
                counts["reasons"][reason] = counts["reasons"].get(reason, 0) + 1
            trials.append({"state": label, "final_theta": theta % 360.0, "ok": reason is None,
                           "reason": reason or "", "path": path})
        rows.append(counts)
    return {"plan": list(plan["pins"]), "settings": cfg, "mu_c": mu_c, "model": model,
            "rows": rows, "trials": trials}
