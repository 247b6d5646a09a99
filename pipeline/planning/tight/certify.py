"""The carried sets of a chosen pin sequence, for the stored plan.

A sequence the complete search picked (``complete.py``) is first followed by
the tight propagation (``search.TightPlanner.follow``): its carried sets are
then a sound bound (``"carried_sets_kind": "propagated"``), checked again by
the verification. When the propagation forbids one of its pins (the uncertainty
box reaches a jam or a centroid on both sides, or holds too many jumps),
the sets are *sampled* instead (``"carried_sets_kind": "sampled"``): the hull of a
separate replay of the perturbation box (the verification's settings with
the next seed) after each pin, one branch per cluster of final
orientations. Sampled sets are weaker: the verification, with its own
seed, is what then checks it.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from pipeline.parts.contact import contact_parameter
from pipeline.planning.core.arcs import merge_arcs, merge_modulo
from pipeline.planning.core.plan_records import Step
from pipeline.planning.claims.orient import narrowest_arc
from pipeline.planning.tight.propagate import friction_interval, snapped_state
from pipeline.planning.core.resting import resting_states
from pipeline.planning.tight.search import TightPlan, TightPlanner
from pipeline.planning.claims.replay import replay
from pipeline.planning.claims.trials import trial_inputs
from pipeline.planning.core.settings import VerifySettings

CLUSTER_GAP_DEG = 3.0  # sampled final orientations further apart than this are separate sets


def carried_plan(planner: TightPlanner, labels, margin: float, verify: VerifySettings, family=None,
                 memo=None) -> TightPlan:
    """The :class:`TightPlan` of the sequence ``labels``: propagated if the
    tight propagation allows every pin, else sampled (see the module notes).
    With a support ``family`` other than uniform alone the sets are always
    sampled, over the family's members (the propagation assumes uniform
    pressure). ``memo``: as for :func:`sampled_plan`."""
    plan = planner.follow(labels) if family is None or family.is_uniform else None
    if plan is not None:
        plan.carried = "propagated"
        return plan
    return sampled_plan(planner, labels, margin, verify, family, memo)


def sampled_plan(planner: TightPlanner, labels, margin: float, verify: VerifySettings,
                 family=None, memo=None) -> TightPlan:
    """A :class:`TightPlan` whose carried sets are sampled: a replay of the
    perturbation box (seed ``verify.seed + 1``; supports sampled from
    ``family`` as the verification does); per initial state, the trials
    whose final orientations form one cluster (gaps of more than
    ``CLUSTER_GAP_DEG`` split clusters) are one branch, and each step of a
    branch carries the hull of its trials after that pin. ``memo`` (a
    ``replay.ReplayMemo`` shared by the plans of one planner): plans that
    share their first pins share those rollouts (the same numbers)."""
    sampling = dataclasses.replace(verify, seed=int(verify.seed) + 1)
    part, unc = planner.part, planner.unc
    pins = [planner.pins[p] for p in labels]
    starts = planner.initial_states()
    resting = resting_states(part)
    mu_lo, mu_hi = friction_interval(planner.mu_c, unc)
    branches, finals = {}, []
    supports = None if family is None else family.kernel_supports
    inputs = trial_inputs(resting, planner.mu_c, len(pins), sampling, family)
    for label, (th, yc, mu, offs, sup) in zip(starts, inputs):
        path = []
        replay(part, [p.y for p in pins], [p.v_pin for p in pins], th, yc, mu, offs,
               planner.pin_radius, planner.model, path=path, belt_speed=planner.belt_speed,
               mu_s=planner.mu_s, support=sup, supports=supports, memo=memo)
        before = [yc] + [y for _, y in path[:-1]]
        alive = np.isfinite(path[-1][0])  # jammed trials end nowhere
        branches[label] = []
        for members in _clusters(path[-1][0], alive):
            steps = []
            for k, (pin, (theta_k, y_k)) in enumerate(zip(pins, path)):
                d = contact_parameter(pin.y + offs[members, k], before[k][members], part.a)
                arc = narrowest_arc(theta_k[members], members.size) or (0.0, 360.0)
                after = snapped_state(arc[0], arc[1], float(y_k[members].min()), float(y_k[members].max()),
                                      mu_lo, mu_hi)
                steps.append(Step.carried_by(pin.label, pin.y, pin.v_pin, (float(d.min()), float(d.max())),
                                               after))
            branches[label].append(steps)
            finals.append(steps[-1].band.pair)
    plan = TightPlan(tuple(labels), tuple(p.y for p in pins), tuple(p.v_pin for p in pins),
                     merge_arcs(finals), len(merge_modulo(finals, planner.order)), float(margin), 0,
                     branches, dict(starts), ())
    plan.carried = "sampled"
    return plan


def _clusters(theta, alive) -> list:
    """Index arrays of the trials in ``alive`` whose orientations ``theta`` form
    one cluster on the circle (sorted; a gap over ``CLUSTER_GAP_DEG`` splits)."""
    idx = np.flatnonzero(alive)
    if idx.size == 0:
        return []
    order = idx[np.argsort(np.mod(theta[idx], 360.0))]
    x = np.mod(theta[order], 360.0)
    gaps = np.diff(np.concatenate([x, [x[0] + 360.0]]))
    cut = np.flatnonzero(gaps > CLUSTER_GAP_DEG)
    if cut.size == 0:
        return [order]
    order = np.roll(order, -(cut[-1] + 1))  # start after the widest-wrapping gap
    x = np.mod(theta[order], 360.0)
    breaks = np.flatnonzero(np.mod(np.diff(x), 360.0) > CLUSTER_GAP_DEG) + 1
    return np.split(order, breaks)
