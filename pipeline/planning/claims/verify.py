"""Does a stored plan do what it claims? Its trials replayed and judged (the paper's Table 2).

:func:`verify_plan` draws the trials of a plan (:mod:`.trials`: the
perturbation box and its corners, or the held-out trials that certify a
plan), replays them through the plan's pins (:mod:`.replay`) and judges
each one: a trial succeeds when the final orientation lies in the final
orientation sets the plan predicts for that initial state
(:func:`predicted_sets`). Failures are counted by reason: ``jammed
(<why>)``, ``missed a pin`` (the plan expected a contact and a pin missed,
and the part ended elsewhere) and ``other band``. What a plan does beyond
the cut, on normals that are not cut, is
:mod:`pipeline.planning.claims.tails`; whether the counts make a claim,
:mod:`pipeline.planning.claims.orient`.
"""
from __future__ import annotations

from pipeline.parts.part import Part
from pipeline.planning.claims.replay import ReplayMemo, replay
from pipeline.planning.claims.trials import state_start, trial_inputs
from pipeline.planning.core.arcs import in_arc, merge_arcs
from pipeline.planning.core.plan_records import Plan
from pipeline.planning.core.settings import KernelSettings, VerifySettings, as_kernel_settings, as_verify_settings
from pipeline.progress import SILENT, Stretch

# Kept here for the callers not yet switched to the trials and replay modules
# (plans/plan.py, tight/complete.py, family/*): import them from there.
from pipeline.planning.claims.replay import replay_shared  # noqa: F401
from pipeline.planning.claims.trials import (corner_inputs, holdout_settings,  # noqa: F401
                                             perturbed_batch, verify_dict)


def _arc(step):
    return (step["band"]["start"], step["band"]["width"])


def _branch_arcs(plan, label: str) -> list:
    """The orientation arcs ``(start, width)`` after each pin of every branch
    of one initial state: of a :class:`~pipeline.planning.core.plan_records.Plan`
    record (the planner's) or of a stored plan dict (as read from a file)."""
    if isinstance(plan, Plan):
        return [[step.band.pair for step in branch] for branch in plan.branches[label]]
    return [[_arc(step) for step in branch] for branch in plan["initial_states"][label]]


def _start_arc(plan, label: str):
    """The orientation arc the plan carries from one initial state (``None``
    when it keeps none: paper mode's plans, hand-made ones)."""
    first = (plan.initial_sets or {}).get(label) if isinstance(plan, Plan) else \
        plan.get("initial_sets", {}).get(label)
    if not first:
        return None
    return first.arc.pair if isinstance(plan, Plan) else (first["arc"]["start"], first["arc"]["width"])


def predicted_sets(plan, label: str):
    """The final orientation sets a plan (a record or a stored dict) predicts for one initial state."""
    return merge_arcs([branch[-1] for branch in _branch_arcs(plan, label) if branch])


def _expects_contact(branches: list, k: int, start_arc) -> bool:
    # A step whose orientation set differs from the one before it needed the pin to touch.
    for branch in branches:
        if k < len(branch):
            before = branch[k - 1] if k > 0 else start_arc
            if tuple(branch[k]) != tuple(before):
                return True
    return False


def _failure(jammed: str, theta_f: float, finals, missed, expected) -> str | None:
    """Why a trial failed (``None``: it ended in a predicted set): its jam, a pin
    it missed where the plan expected a contact, else another band."""
    if jammed:
        return jammed
    if any(in_arc(theta_f, s, w, 1e-6) for s, w in finals):
        return None
    return "missed a pin" if any(m and e for m, e in zip(missed, expected)) else "other band"


def verify_plan(part: Part, plan, pins: dict, initial_states: dict, mu_c, pin_radius: float,
                model: str = "minpower", settings: VerifySettings | None = None,
                speeds: dict | None = None, kernel: KernelSettings | None = None,
                belt_speed: float | None = None, mu_s: float = 0.5, family=None,
                stretch: Stretch = SILENT, memo: ReplayMemo | None = None) -> dict:
    """Run the trials of ``settings`` (``None``: the schema's) for a plan (a
    :class:`~pipeline.planning.core.plan_records.Plan` record, as the
    planner verifies its candidates, or a stored plan's dict), each rollout at the kernel step
    ``kernel`` (``None``: the kernel's defaults). Flat dicts of either, which
    callers not yet switched still pass, are read with ``as_verify_settings``
    and ``as_kernel_settings``.

    ``memo`` (a :class:`ReplayMemo`): replays of plans with the same part and
    rollout settings share the states after their common first pins (the
    result is the same).

    ``family`` (a :class:`~pipeline.parts.support_family.SupportFamily`)
    samples each trial's support from it (see :func:`trial_inputs`); each
    trial then records its ``support`` label. ``None``: uniform pressure.

    ``belt_speed`` (mm/s) replays every trial with the dynamic model at that
    belt speed and belt friction ``mu_s``; ``None`` (default) with the
    quasi-static ``model``.

    ``pins`` maps labels to heights (mm); ``speeds`` gives the speed ratio
    v_pin / v_b of each moving pin's label (absent: a static pin); a perturbed
    pin position shifts a moving pin's whole path. ``initial_states`` maps
    labels to ``(theta_deg, y_c_mm)``. ``mu_c`` is a value or a range
    ``(lo, hi)``. Returns per-state counts (``rows``), totals and every
    trial's outcome. ``stretch`` (:class:`pipeline.progress.Stretch`) is told
    how far the trials have got, each initial state an equal share."""
    speeds = speeds or {}
    settings, kernel = as_verify_settings(settings), as_kernel_settings(kernel)
    labels = list(plan.pins if isinstance(plan, Plan) else plan["pins"])
    heights = [float(pins[p]) for p in labels]
    vs = [float(speeds.get(p, 0.0)) for p in labels]
    rows, trials = [], []
    inputs = trial_inputs(initial_states, mu_c, len(labels), settings, family)
    supports = None if family is None else family.kernel_supports
    for i, ((label, state), (th, yc, mu, offs, sup)) in enumerate(zip(initial_states.items(), inputs)):
        outcome = replay(part, heights, vs, th, yc, mu, offs, pin_radius, model, **kernel.as_kwargs(),
                         belt_speed=belt_speed, mu_s=mu_s, support=sup, supports=supports,
                         stretch=stretch.part(i / len(inputs), (i + 1) / len(inputs)), memo=memo)
        counts, detail = _judge_state(plan, label, state, len(labels), (th, yc, mu, sup), outcome, family)
        trials += detail
        rows.append(counts)
    return _verification_record(labels, settings, mu_c, model, belt_speed, mu_s, family, rows, trials)


def _judge_state(plan, label: str, state, n_pins: int, start, outcome, family) -> tuple:
    """Judge the replayed trials of one initial state against the sets the plan predicts.

    Parameters
    ----------
    plan : the plan (a record or a stored dict).
    label, state : the initial state's label and its ``(theta, y_c)`` (or planner state).
    n_pins : the plan's pins.
    start : the trials' inputs ``(theta, y_c, mu, support)``.
    outcome : what :func:`replay` returned for them, ``(theta_f, y_c, jam, missed)``.
    family : the support family the trials sampled (``None``: uniform pressure).

    Returns
    -------
    tuple
        ``(counts, trials)``: the state's counts (``trials``, ``successes``,
        ``failures``, ``reasons``) and each trial's outcome, in order.
    """
    th, yc, mu, sup = start
    tf, yf, jam, missed = outcome
    theta0, _ = state_start(state)
    finals = predicted_sets(plan, label)
    start_arc = _start_arc(plan, label) or (theta0, 0.0)
    branches = _branch_arcs(plan, label)
    expected = [_expects_contact(branches, k, start_arc) for k in range(n_pins)]
    counts = {"state": label, "trials": 0, "successes": 0, "failures": 0, "reasons": {}}
    trials = []
    for j in range(tf.size):
        reason = _failure(jam[j], tf[j], finals, missed[j], expected)
        counts["trials"] += 1
        counts["successes" if reason is None else "failures"] += 1
        if reason:
            counts["reasons"][reason] = counts["reasons"].get(reason, 0) + 1
        trials.append({"state": label, "final_theta": float(tf[j]), "final_y_c": float(yf[j]),
                       "ok": reason is None, "reason": reason or "",
                       "start": [float(th[j]) % 360.0, float(yc[j])], "mu_c": float(mu[j]),
                       **({} if family is None else {"support": family.members[sup[j]].label})})
    return counts, trials


def _verification_record(labels, settings: VerifySettings, mu_c, model, belt_speed, mu_s, family, rows,
                         trials) -> dict:
    """The verification's record: the plan's pins, the settings (their flat
    dict), the mechanics, the per-state ``rows``, their totals and every
    trial's outcome (``trials_detail``)."""
    total = {k: sum(r[k] for r in rows) for k in ("trials", "successes", "failures")}
    mu_out = list(mu_c) if isinstance(mu_c, (tuple, list)) else mu_c
    belt = {} if belt_speed is None else {"belt_speed": float(belt_speed), "mu_s": float(mu_s)}
    return {"plan": labels, "settings": settings.as_dict(), "mu_c": mu_out,
            "model": model if belt_speed is None else "dynamic", **belt, "rows": rows,
            **({} if family is None else {"support_family": family.label}),
            **total, "trials_detail": trials}


