"""Replay plans with full rollouts under perturbations (the paper's Table 2).

Each trial starts from an initial resting state, perturbs the initial
orientation and centroid height, the friction and every pin's position, then
rolls the part past each pin of the plan in turn: ``theta`` and ``y_c`` carry
over from one pin to the next. The perturbation box is the planner's
(``propagate.Uncertainty``): orientation and friction are normal with the
configured sigma, truncated at 2 sigma (a friction range ``(lo, hi)`` is
sampled uniformly); centroid height and pin positions are uniform within
their half-widths. Besides the random trials, every corner of the box is
replayed (``corners``). What a plan does beyond the cut, on normals that
are not cut, is :mod:`pipeline.planning.claims.tails`. This shares no
arithmetic with the planner: it calls the public rollout API only.

A trial succeeds when the final orientation lies in the final orientation
sets the plan predicts for that initial state. Failures are counted by
reason: ``jammed (<why>)``, ``missed a pin`` (the plan expected a contact
and a pin missed, and the part ended elsewhere) and ``other band``.
"""
from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL, JAM_REASONS, JAMMED, MISS, TRUNCATED

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import in_arc, merge_arcs
from pipeline.planning.core.settings import TRUNCATE_SIGMA, Perturbation, VerifySettings
from pipeline.progress import SILENT, Stretch

PERTURB_DEFAULTS = dataclasses.asdict(Perturbation())  # the schema's verify perturbation sizes
DEFAULTS = VerifySettings().as_dict()  # the schema's verify section (trials, corners, seed, sizes)
HOLDOUT_STREAM = 4_001  # salt of the held-out trials' seed: a stream no screen or selection draws from


def verify_dict(settings) -> dict:
    """The trial settings as the flat dict the drawing functions read: a
    :class:`~pipeline.planning.core.settings.VerifySettings`, or a partial
    dict over the schema's defaults (:data:`DEFAULTS`)."""
    if isinstance(settings, VerifySettings):
        return settings.as_dict()
    return dict(DEFAULTS, **(settings or {}))


def holdout_settings(settings: dict, attempt: int = 0) -> dict:
    """The verification settings of the held-out trials that certify a plan.

    The search screens and selects plans on the trials of ``settings`` (seed
    ``seed``); the plan it picks is certified on fresh trials from a seed
    derived from ``(seed, HOLDOUT_STREAM, attempt)``, which no screen or
    selection draws from, ``holdout_trials`` per state (default: as many as
    ``trials``; fewer is refused). The same settings give the same held-out
    trials. The box corners are replayed again (they are not random)."""
    cfg = verify_dict(settings)
    n = cfg.get("holdout_trials")
    n = int(cfg["trials"]) if n is None else int(n)
    if n < int(cfg["trials"]):
        raise PinfeedError(f"verify.holdout_trials ({n}) must be at least verify.trials ({cfg['trials']}): "
                           "the trials that certify a plan may not be fewer than those that chose it")
    seed = int(np.random.SeedSequence([int(cfg["seed"]), HOLDOUT_STREAM, int(attempt)]).generate_state(1)[0])
    return dict(cfg, trials=n, seed=seed, holdout=True)


def normal_draws(rng, sigma, n, truncate=TRUNCATE_SIGMA):
    """``n`` draws of a normal with mean 0 and spread ``sigma``, cut at
    ``truncate`` sigma (a draw beyond is drawn again); ``truncate`` ``None``:
    not cut (the tails of :mod:`pipeline.planning.claims.tails`)."""
    out = rng.normal(0.0, sigma, n)
    if truncate is None:
        return out
    bad = np.abs(out) > truncate * sigma
    while np.any(bad):
        out[bad] = rng.normal(0.0, sigma, int(bad.sum()))
        bad = np.abs(out) > truncate * sigma
    return out


def perturbed_inputs(theta, y_c, mu_c, n_pins, cfg, rng):
    """One trial's inputs: theta_i, y_c, mu_c and an offset for each of
    ``n_pins`` pins, drawn from the perturbation box (sizes from ``cfg``)."""
    th, yc, mu, offs = perturbed_batch(theta, y_c, mu_c, n_pins, cfg, rng, 1)
    return float(th[0]), float(yc[0]), float(mu[0]), offs[0]


def perturbed_batch(theta, y_c, mu_c, n_pins, cfg, rng, n):
    """``n`` trials' inputs as arrays ``(theta (n,), y_c (n,), mu (n,), offsets (n, n_pins))``.
    ``mu_c`` is a value (normal, truncated at 2 sigma, clipped at 0) or a range ``(lo, hi)``.
    ``cfg["truncate_sigma"]`` (absent: ``TRUNCATE_SIGMA``; ``None``: not cut)
    is where the normals of theta and mu_c are cut."""
    cut = cfg.get("truncate_sigma", TRUNCATE_SIGMA)
    th = theta + normal_draws(rng, cfg["theta_sigma"], n, cut)
    yc = y_c + rng.uniform(-cfg["y_halfwidth"], cfg["y_halfwidth"], n)
    if isinstance(mu_c, (tuple, list)):
        mu = rng.uniform(float(mu_c[0]), float(mu_c[1]), n)
    else:
        mu = np.maximum(0.0, mu_c + normal_draws(rng, cfg["mu_sigma"], n, cut))
    offs = rng.uniform(-cfg["pin_halfwidth"], cfg["pin_halfwidth"], (n, n_pins))
    return th, yc, mu, offs


def corner_inputs(theta, y_c, mu_c, n_pins, cfg):
    """Every corner of the perturbation box, as arrays like :func:`perturbed_batch`."""
    ts = TRUNCATE_SIGMA
    if isinstance(mu_c, (tuple, list)):
        mus = (float(mu_c[0]), float(mu_c[1]))
    else:
        mus = (max(0.0, mu_c - ts * cfg["mu_sigma"]), mu_c + ts * cfg["mu_sigma"])
    h = cfg["pin_halfwidth"]
    rows = list(itertools.product((-1.0, 1.0), (-1.0, 1.0), mus, *[(-h, h)] * n_pins))
    arr = np.array([r[:3] for r in rows], dtype=float)
    offs = np.array([r[3:] for r in rows], dtype=float).reshape(len(rows), n_pins)
    return (theta + arr[:, 0] * ts * cfg["theta_sigma"], y_c + arr[:, 1] * cfg["y_halfwidth"],
            arr[:, 2], offs)


def trial_inputs(initial_states: dict, mu_c, n_pins: int, settings: dict, family=None) -> list:
    """The trials :func:`verify_plan` replays for a plan of ``n_pins`` pins: per
    initial state (in order), arrays ``(theta, y_c, mu, offsets (n, n_pins),
    support)`` of ``settings["trials"]`` random trials followed by every corner
    of the perturbation box (``settings["corners"]``). The same settings give the
    same trials, so a subset of them can be replayed first to reject a plan early.

    ``support`` is each trial's member index in ``family`` (a
    :class:`~pipeline.parts.support_family.SupportFamily`; all 0 without one,
    and then the trials are exactly those of uniform pressure). With a family,
    the random trials take its members in turn, in a seeded random order (a
    stratified sample: each member ``trials / len(family)`` times, give or take
    one), and the corners are replayed once under each of the family's
    ``representatives``."""
    cfg = verify_dict(settings)
    rng = np.random.default_rng(cfg["seed"])
    members = 1 if family is None else len(family.members)
    reps = (0,) if family is None else family.representatives
    pick = np.random.default_rng([int(cfg["seed"]), 25])  # its own stream: uniform trials stay as they were
    out = []
    for state in initial_states.values():
        theta0, yc0 = _start(state)
        n = int(cfg["trials"])
        th, yc, mu, offs = perturbed_batch(theta0, yc0, mu_c, n_pins, cfg, rng, n)
        sup = pick.permutation(np.resize(np.arange(members), n)) if members > 1 else np.zeros(n, int)
        if cfg.get("corners", True):
            corners = corner_inputs(theta0, yc0, mu_c, n_pins, cfg)
            k = corners[0].size
            th, yc, mu = (np.concatenate([x, np.tile(c, len(reps))]) for x, c in zip((th, yc, mu), corners[:3]))
            offs = np.concatenate([offs, np.tile(corners[3], (len(reps), 1))])
            sup = np.concatenate([sup, np.repeat(np.asarray(reps, int), k)])
        out.append((th, yc, mu, offs, sup))
    return out


def _arc(step):
    return (step["band"]["start"], step["band"]["width"])


def predicted_sets(plan: dict, label: str):
    """The final orientation sets a stored plan predicts for one initial state."""
    return merge_arcs([_arc(branch[-1]) for branch in plan["initial_states"][label] if branch])


def _expects_contact(plan: dict, label: str, k: int, start_arc) -> bool:
    # A step whose orientation set differs from the one before it needed the pin to touch.
    for branch in plan["initial_states"][label]:
        if k < len(branch):
            before = _arc(branch[k - 1]) if k > 0 else start_arc
            if tuple(_arc(branch[k])) != tuple(before):
                return True
    return False


def _start(state):
    """``(theta, y_c)`` of an initial state given as a pair or as a planner state."""
    if isinstance(state, (tuple, list)):
        return float(state[0]), float(state[1])
    return float(state.arc[0]), float(state.y_lo)


def replay(part: Part, pin_heights, pin_speeds, theta, y_c, mu, offsets, pin_radius, model,
           ds_max=DEFAULT_DS_MAX, tol=DEFAULT_TOL, path=None, belt_speed=None, mu_s=0.5,
           support=None, supports=None, stretch: Stretch = SILENT, memo: "ReplayMemo | None" = None):
    """Roll every trial past every pin in turn (batched per pin).

    ``belt_speed`` (mm/s) replays with the dynamic model at that speed and
    belt friction ``mu_s`` (``model`` is then unused); ``None`` is
    quasi-static ``model``. ``pin_heights`` (mm) and ``pin_speeds`` (v_pin /
    v_b) are one value per pin, or arrays ``(n_trials, n_pins)`` to replay
    several plans of one length at once. ``support`` (an index per trial into
    ``supports``, a list of supports as ``simulate`` takes them) gives each
    trial its own support; ``None``: uniform pressure.

    Returns ``(theta_f, y_c, jam_reason_or_empty, missed)``: arrays over trials,
    ``missed`` a boolean array ``(n_trials, n_pins)``. If ``path`` is a list,
    ``(theta, y_c)`` arrays after each pin are appended to it. ``stretch``
    (:class:`pipeline.progress.Stretch`) is told how far the replay has got,
    each pin an equal share. ``memo`` (a :class:`ReplayMemo`, for replays
    with the same part and rollout settings) keeps each trial's state after
    each prefix of pins and reuses it: the numbers are the same."""
    theta, y_c = np.array(theta, float), np.array(y_c, float)
    n = theta.size
    n_pins = np.shape(pin_speeds)[-1] if np.ndim(pin_speeds) else 0
    heights = np.broadcast_to(np.asarray(pin_heights, dtype=float), (n, n_pins))
    speeds = np.broadcast_to(np.asarray(pin_speeds, dtype=float), (n, n_pins))
    support = None if support is None else np.broadcast_to(np.asarray(support, dtype=int), (n,))
    jam = np.full(n, "", dtype=object)
    missed = np.zeros((n, n_pins), bool)
    alive = np.ones(n, bool)
    kw = kernel_kw(ds_max, tol, belt_speed, mu_s)
    if memo is not None:
        trial, node = memo.trial_ids(theta, y_c, mu, offsets, support), np.zeros(n, dtype=np.int64)
    for k in range(n_pins):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        if memo is not None:
            node = memo.nodes(node, heights[:, k], speeds[:, k])
            at = memo.lookup(node[idx], trial[idx])
            old, idx = idx[at >= 0], idx[at < 0]
            theta[old], y_c[old], reason, missed[old, k] = memo.get(at[at >= 0])
            jam[old] = reason
            alive[old[reason != ""]] = False
        if idx.size:
            res = pin_step(part, heights[idx, k] + offsets[idx, k], speeds[idx, k], theta[idx], y_c[idx], mu[idx],
                            pin_radius, model, kw, None if support is None else support[idx], supports,
                            stretch.part(k / n_pins, (k + 1) / n_pins))
            st = res["status"]
            stuck = (st == JAMMED) | (st == TRUNCATED)
            for j in np.flatnonzero(stuck):
                jam[idx[j]] = f"jammed ({JAM_REASONS[res['jam_reason'][j]] or 'truncated'})"
            alive[idx[stuck]] = False
            missed[idx, k] = st == MISS
            theta[idx] = res["theta_f"]
            y_c[idx] = y_c[idx] + res["dy"]
            if memo is not None:
                memo.add(node[idx], trial[idx], theta[idx], y_c[idx], jam[idx], missed[idx, k])
        if path is not None:
            path.append((np.where(alive, theta % 360.0, np.nan), np.where(alive, y_c, np.nan)))
    return theta % 360.0, y_c, jam, missed


class ReplayMemo:
    """Each trial's state after a prefix of pins, for :func:`replay` calls with
    one part and one set of rollout settings (the chosen plans verified on
    the same held-out trials share their first pins): ``(theta, y_c, jam
    reason, missed the last pin)`` by (prefix, trial), up to ``max_kept``
    states. A prefix is numbered from the empty one (0) by (prefix, pin
    height, pin speed); a trial by its values (start, friction, pin offsets,
    support). A state depends on the prefix and the trial only, and each
    rollout on its own inputs only, so a replay with a memo gives the
    numbers it gives without."""

    def __init__(self, max_kept: int = 1_000_000):
        self.max_kept = int(max_kept)
        self.prefixes, self.trials, self.at, self.reasons = {}, {}, {}, {"": 0}
        self.theta, self.y_c = np.zeros(256), np.zeros(256)
        self.reason, self.missed = np.zeros(256, dtype=np.int32), np.zeros(256, bool)

    def trial_ids(self, theta, y_c, mu, offsets, support) -> np.ndarray:
        """The number of each trial (by its values)."""
        n = np.size(theta)
        values = np.column_stack([np.asarray(theta, float), np.asarray(y_c, float), np.asarray(mu, float),
                                  np.asarray(offsets, float).reshape(n, -1),
                                  np.zeros(n) if support is None else np.asarray(support, float)])
        return np.array([self.trials.setdefault(v.tobytes(), len(self.trials)) for v in values], dtype=np.int64)

    def nodes(self, parent, heights, speeds) -> np.ndarray:
        """The number of each prefix ``parent`` followed by a pin at ``heights``, ``speeds``."""
        uniq, inverse = np.unique(np.column_stack([parent, heights, speeds]), axis=0, return_inverse=True)
        ids = [self.prefixes.setdefault((int(p), float(h), float(v)), len(self.prefixes) + 1) for p, h, v in uniq]
        return np.asarray(ids, dtype=np.int64)[inverse.ravel()]

    def lookup(self, nodes, trials) -> np.ndarray:
        """Where each (prefix, trial) state is kept (-1: not kept)."""
        get = self.at.get
        return np.array([get(c, -1) for c in ((nodes << 32) | trials).tolist()], dtype=np.int64)

    def get(self, at) -> tuple:
        """``(theta, y_c, jam reason, missed)`` kept at ``at``."""
        names = np.array(list(self.reasons), dtype=object)
        return self.theta[at], self.y_c[at], names[self.reason[at]], self.missed[at]

    def add(self, nodes, trials, theta, y_c, reasons, missed) -> None:
        """Keep these states, while there is room."""
        start, n = len(self.at), np.size(nodes)
        if start + n > self.max_kept:
            return
        while self.theta.size < start + n:
            self.theta, self.y_c = np.concatenate([self.theta, self.theta]), np.concatenate([self.y_c, self.y_c])
            self.reason, self.missed = np.concatenate([self.reason, self.reason]), np.concatenate([self.missed,
                                                                                                  self.missed])
        self.theta[start:start + n], self.y_c[start:start + n], self.missed[start:start + n] = theta, y_c, missed
        self.reason[start:start + n] = [self.reasons.setdefault(r, len(self.reasons)) for r in reasons]
        self.at.update(zip(((nodes << 32) | trials).tolist(), range(start, start + n)))


def kernel_kw(ds_max, tol, belt_speed, mu_s) -> dict:
    """The rollout keywords of the quasi-static kernel, or of the dynamic model at ``belt_speed``.

    Parameters
    ----------
    ds_max, tol : the quasi-static kernel's step and tolerance.
    belt_speed : belt speed (mm/s) of the dynamic model; ``None``: quasi-static.
    mu_s : belt friction of the dynamic model.

    Returns
    -------
    dict
        The keywords :func:`pin_step` (and ``simulate.rollout_points``) take.
    """
    return {"ds_max": ds_max, "tol": tol} if belt_speed is None else {"belt_speed": belt_speed, "mu_s": mu_s}


def pin_step(part, pin_y, v_pin, theta, y_c, mu, pin_radius, model, kw, support, supports, stretch) -> dict:
    """One pin (placed at ``pin_y`` mm, speed ``v_pin``) for every row: the
    rollouts' results (``rollouts_by_speed``).

    Parameters
    ----------
    part : the part.
    pin_y, v_pin : the pin's height (mm) and speed ratio ``v_pin / v_b``, per row or one for all.
    theta, y_c, mu : each row's orientation (deg), centroid height (mm) and friction.
    pin_radius, model : the pin's radius (mm) and the quasi-static model (unused with a belt speed).
    kw : the rollout keywords (:func:`kernel_kw`).
    support, supports : each row's index into ``supports``; ``None``: uniform pressure.
    stretch : told the share of rows done (:class:`pipeline.progress.Stretch`).

    Returns
    -------
    dict
        Arrays over the rows: ``theta_f``, ``dy``, ``status``, ``jam_reason`` and the rest
        of ``simulate.rollout_points``'s results.
    """
    d = contact_parameter(pin_y, y_c, part.a)
    return rollouts_by_speed(part, theta, d, mu, v_pin, pin_radius, model if "belt_speed" not in kw else "dynamic",
                             kw, support, supports, stretch)


def replay_shared(part: Part, pin_heights, pin_speeds, theta, y_c, mu, offsets, pin_radius, model,
                  ds_max=DEFAULT_DS_MAX, tol=DEFAULT_TOL, belt_speed=None, mu_s=0.5, support=None,
                  supports=None, stretch: Stretch = SILENT):
    """Every plan (a row of ``pin_heights``, ``pin_speeds``: ``(plans, pins)``)
    replayed on every trial (``theta``, ``y_c``, ``mu``, ``support``: one
    value per trial; ``offsets``: ``(trials, pins)``), as :func:`replay` on
    the plans' rows tiled over the trials would, but each distinct *prefix*
    (the first ``k`` pins of one or more plans) is rolled out once per trial:
    the plans of a search level share most of their pins (all of a moving-pin
    level's fixed prefix), so this saves most rollouts.

    Returns ``(theta_f, jammed)``, each ``(plans, trials)``. The numbers are
    :func:`replay`'s: a trial's state after a pin (``theta``, ``y_c``, jammed
    or not) depends only on the pins so far, and every rollout is
    independent of the others in its batch. ``stretch`` hears each pin as an
    equal share."""
    heights, speeds = np.atleast_2d(np.asarray(pin_heights, float)), np.atleast_2d(np.asarray(pin_speeds, float))
    n_plans, n_pins = heights.shape
    n = np.size(theta)
    kw = kernel_kw(ds_max, tol, belt_speed, mu_s)
    # The states of each distinct prefix (a node) on every trial; one node, no pin, to start.
    node = np.zeros(n_plans, int)
    th, yc = np.asarray(theta, float)[None, :].copy(), np.asarray(y_c, float)[None, :].copy()
    jam = np.zeros((1, n), bool)
    sup = None if support is None else np.broadcast_to(np.asarray(support, dtype=int), (n,))
    for k in range(n_pins):
        nodes, node = np.unique(np.column_stack([node, heights[:, k], speeds[:, k]]), axis=0, return_inverse=True)
        node = node.ravel()
        parent = nodes[:, 0].astype(int)
        th, yc, jam = th[parent], yc[parent], jam[parent]
        rows, cols = np.nonzero(~jam)
        if rows.size:
            res = pin_step(part, nodes[rows, 1] + offsets[cols, k], nodes[rows, 2], th[rows, cols], yc[rows, cols],
                            mu[cols], pin_radius, model, kw, None if sup is None else sup[cols], supports,
                            stretch.part(k / n_pins, (k + 1) / n_pins))
            th[rows, cols] = res["theta_f"]
            yc[rows, cols] = yc[rows, cols] + res["dy"]
            st = res["status"]
            jam[rows, cols] = (st == JAMMED) | (st == TRUNCATED)
    return th[node] % 360.0, jam[node]


def rollouts_by_speed(part, theta, d, mu, v_pin, pin_radius, model, kw, support=None,
                      supports=None, stretch: Stretch = SILENT) -> dict:
    """``simulate.rollout_points`` for rows whose pins may move at different
    speeds ``v_pin`` and, with ``support`` (an index per row into
    ``supports``), rest on different supports: one batch per (speed,
    support), results in row order. ``stretch`` is told the share of rows
    done."""
    v_pin = np.broadcast_to(np.asarray(v_pin, dtype=float), theta.shape)
    supports = supports or [None]
    support = np.zeros(theta.size, int) if support is None else np.asarray(support, dtype=int)
    groups, group_of = np.unique(np.column_stack([v_pin, support]), axis=0, return_inverse=True)
    group_of = group_of.ravel()

    def batch(rows, g, share):
        v, s = groups[g]
        extra = {} if supports[int(s)] is None else {"support": supports[int(s)]}
        return simulate.rollout_points(part, theta[rows], d[rows], mu[rows], pin_radius, model,
                                       v_pin=float(v), **kw, **extra, stretch=share)

    if len(groups) == 1:
        return batch(np.arange(theta.size), 0, stretch)
    out, before = None, 0
    for g in range(len(groups)):
        rows = np.flatnonzero(group_of == g)
        res = batch(rows, g, stretch.part(before / theta.size, (before + rows.size) / theta.size))
        before += rows.size
        if out is None:
            out = {key: np.empty(theta.size, dtype=arr.dtype) for key, arr in res.items()}
        for key, arr in res.items():
            out[key][rows] = arr
    return out


def _failure(jammed: str, theta_f: float, finals, missed, expected) -> str | None:
    """Why a trial failed (``None``: it ended in a predicted set): its jam, a pin
    it missed where the plan expected a contact, else another band."""
    if jammed:
        return jammed
    if any(in_arc(theta_f, s, w, 1e-6) for s, w in finals):
        return None
    return "missed a pin" if any(m and e for m, e in zip(missed, expected)) else "other band"


def verify_plan(part: Part, plan: dict, pins: dict, initial_states: dict, mu_c, pin_radius: float,
                model: str = "minpower", settings: dict | None = None,
                speeds: dict | None = None, kernel: dict | None = None,
                belt_speed: float | None = None, mu_s: float = 0.5, family=None,
                stretch: Stretch = SILENT, memo: ReplayMemo | None = None) -> dict:
    """Run the trials for a stored plan (``to_dict()`` of a plan).

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
    cfg = verify_dict(settings)
    kernel = kernel or {}
    labels = list(plan["pins"])
    heights = [float(pins[p]) for p in labels]
    vs = [float(speeds.get(p, 0.0)) for p in labels]
    rows, trials = [], []
    inputs = trial_inputs(initial_states, mu_c, len(labels), cfg, family)
    supports = None if family is None else family.kernel_supports
    for i, ((label, state), (th, yc, mu, offs, sup)) in enumerate(zip(initial_states.items(), inputs)):
        outcome = replay(part, heights, vs, th, yc, mu, offs, pin_radius, model,
                         kernel.get("ds_max", DEFAULT_DS_MAX), kernel.get("tol", DEFAULT_TOL),
                         belt_speed=belt_speed, mu_s=mu_s, support=sup, supports=supports,
                         stretch=stretch.part(i / len(inputs), (i + 1) / len(inputs)), memo=memo)
        counts, detail = _judge_state(plan, label, state, len(labels), (th, yc, mu, sup), outcome, family)
        trials += detail
        rows.append(counts)
    return _verification_record(labels, cfg, mu_c, model, belt_speed, mu_s, family, rows, trials)


def _judge_state(plan: dict, label: str, state, n_pins: int, start, outcome, family) -> tuple:
    """Judge the replayed trials of one initial state against the sets the plan predicts.

    Parameters
    ----------
    plan : the stored plan.
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
    theta0, _ = _start(state)
    finals = predicted_sets(plan, label)
    first = plan.get("initial_sets", {}).get(label)
    start_arc = (first["arc"]["start"], first["arc"]["width"]) if first else (theta0, 0.0)
    expected = [_expects_contact(plan, label, k, start_arc) for k in range(n_pins)]
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


def _verification_record(labels, cfg, mu_c, model, belt_speed, mu_s, family, rows, trials) -> dict:
    """The verification's record: the plan's pins, the settings, the
    mechanics, the per-state ``rows``, their totals and every trial's
    outcome (``trials_detail``)."""
    total = {k: sum(r[k] for r in rows) for k in ("trials", "successes", "failures")}
    mu_out = list(mu_c) if isinstance(mu_c, (tuple, list)) else mu_c
    belt = {} if belt_speed is None else {"belt_speed": float(belt_speed), "mu_s": float(mu_s)}
    return {"plan": labels, "settings": cfg, "mu_c": mu_out,
            "model": model if belt_speed is None else "dynamic", **belt, "rows": rows,
            **({} if family is None else {"support_family": family.label}),
            **total, "trials_detail": trials}


def replayed_paths(part: Part, plan: dict, starts: dict, mu_c, pin_radius, model, cfg=None,
                   trials=100, kernel=None, belt_speed=None, mu_s=0.5):
    """Per initial state: arrays of theta and y_c (trials x steps) of perturbed replays
    (with the dynamic model at ``belt_speed`` mm/s and belt friction ``mu_s`` if given):
    ``trials`` random trials and every corner of the perturbation box, replayed through
    the plan's pins (:func:`replay` with a path). The carried-sets figure
    (:func:`pipeline.present.figures.carried.plot_carried`) draws them."""
    cfg = dict(DEFAULTS, **(cfg or {}))
    kernel = kernel or {}
    rng = np.random.default_rng(cfg["seed"])
    n = len(plan["pins"])
    out = {}
    for label, (theta, y_c) in starts.items():
        th, yc, mu, offs = perturbed_batch(theta, y_c, mu_c, n, cfg, rng, trials)
        corners = corner_inputs(theta, y_c, mu_c, n, cfg)
        th, yc, mu = (np.concatenate([x, c]) for x, c in zip((th, yc, mu), corners[:3]))
        offs = np.concatenate([offs, corners[3]])
        path = [(th % 360.0, yc.copy())]
        replay(part, plan["pin_heights_mm"], plan["pin_speeds"], th, yc, mu, offs, pin_radius, model,
               path=path, belt_speed=belt_speed, mu_s=mu_s,
               **{k: v for k, v in kernel.items() if k in ("ds_max", "tol")})
        out[label] = (np.stack([p[0] for p in path], axis=1), np.stack([p[1] for p in path], axis=1))
    return out
