"""Replaying trials through a plan's pins: full rollouts, batched per pin.

Each trial rolls the part past each pin of a plan in turn: ``theta`` and
``y_c`` carry over from one pin to the next. :func:`replay` replays one plan
(or several of one length) on a set of trials, optionally keeping each
trial's state after each prefix of pins (:class:`ReplayMemo`) for the next
plan that shares it; :func:`replay_shared` replays many plans at once, each
distinct prefix once per trial; :func:`replayed_paths` gives the carried-sets
figure its replays. Every rollout goes through the public rollout API
(``simulate.rollout_points``): this shares no arithmetic with the planner.
"""
from __future__ import annotations

import numpy as np

from kernels.int_table import EMPTY, insert_keys, lookup_keys
from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL, JAM_REASONS, JAMMED, MISS, TRUNCATED

from pipeline.maps import simulate
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.claims.trials import corner_inputs, perturbed_batch
from pipeline.planning.core.settings import KernelSettings, VerifySettings
from pipeline.progress import SILENT, Stretch
from pipeline.rows import unique_rows


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
    if memo is not None and not memo.serves(part, pin_radius, model, kw, supports):
        memo = None  # kept for other rollout settings: its states are not this replay's
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
            jam[idx] = jam_reasons(res)
            alive[idx[(st == JAMMED) | (st == TRUNCATED)]] = False
            missed[idx, k] = st == MISS
            theta[idx] = res["theta_f"]
            y_c[idx] = y_c[idx] + res["dy"]
            if memo is not None:
                memo.add(node[idx], trial[idx], theta[idx], y_c[idx], jam[idx], missed[idx, k])
        if path is not None:
            path.append((np.where(alive, theta % 360.0, np.nan), np.where(alive, y_c, np.nan)))
    return theta % 360.0, y_c, jam, missed


def jam_reasons(res: dict) -> np.ndarray:
    """Why each rollout of ``res`` (``simulate.rollout_points``'s results)
    stopped its trial: ``jammed (REASON)`` (``jammed (truncated)`` for a
    rollout out of steps or travel), ``""`` when it did not."""
    st = res["status"]
    out = np.full(st.size, "", dtype=object)
    for j in np.flatnonzero((st == JAMMED) | (st == TRUNCATED)):
        out[j] = f"jammed ({JAM_REASONS[res['jam_reason'][j]] or 'truncated'})"
    return out


class ReplayMemo:
    """Each trial's state after a prefix of pins, for replays with one part
    and one set of rollout settings: ``(theta, y_c, jam reason, missed the
    last pin)`` by (prefix, trial), up to ``max_kept`` states. The searches'
    trial benches (``tight.judge.TrialBench``) keep theirs in one, and the
    final verification and the nearest "yes" read it: the held-out trials
    that certified a plan are not rolled out again.

    A prefix is numbered from the empty one (0) by (prefix, pin height, pin
    speed); a trial by its values (start, friction, pin offsets, support). A
    state depends on the prefix, the trial and the rollout settings only,
    and each rollout on its own inputs only, so a replay with a memo gives
    the numbers it gives without. The memo serves the part and rollout
    settings of its first replay alone (:meth:`serves`)."""

    def __init__(self, max_kept: int = 1_000_000):
        self.max_kept = int(max_kept)
        self.prefixes, self.trials, self.reasons = {}, {}, {"": 0}
        # where each (prefix, trial) state is kept: a table in two arrays (kernels.int_table)
        self.slot_keys, self.slot_at = np.full(1024, EMPTY, dtype=np.int64), np.zeros(1024, np.int64)
        self.size, self.written = 0, 0  # distinct (prefix, trial) keys; states written
        self.theta, self.y_c = np.zeros(256), np.zeros(256)
        self.reason, self.missed = np.zeros(256, dtype=np.int32), np.zeros(256, bool)
        self.rollout = None  # (part, supports, settings) of the first replay

    def __len__(self) -> int:
        """The number of distinct (prefix, trial) states kept."""
        return self.size

    @property
    def half_full(self) -> bool:
        """True once half of ``max_kept`` is used (a later stage then does
        better with a memo of its own)."""
        return 2 * self.written >= self.max_kept

    def serves(self, part: Part, pin_radius, model, kw: dict, supports) -> bool:
        """Whether replays of ``part`` with these rollout settings (pin radius,
        model, :func:`kernel_kw`, the supports ``support`` indexes) may use
        the memo: those of its first replay (the part and each support the
        same objects), which this call records when it is the first."""
        model = "dynamic" if "belt_speed" in kw else str(model)
        settings = (float(pin_radius), model, tuple(sorted((k, v if v is None else float(v)) for k, v in kw.items())))
        supports = None if supports is None else tuple(supports)
        if self.rollout is None:
            self.rollout = (part, supports, settings)
            return True
        kept_part, kept_supports, kept_settings = self.rollout
        same_supports = (kept_supports is None and supports is None) or (
            kept_supports is not None and supports is not None and len(kept_supports) == len(supports)
            and all(a is b for a, b in zip(kept_supports, supports)))
        return kept_part is part and kept_settings == settings and same_supports

    def trial_ids(self, theta, y_c, mu, offsets, support) -> np.ndarray:
        """The number of each trial (by its values)."""
        n = np.size(theta)
        values = np.column_stack([np.asarray(theta, float), np.asarray(y_c, float), np.asarray(mu, float),
                                  np.asarray(offsets, float).reshape(n, -1),
                                  np.zeros(n) if support is None else np.asarray(support, float)])
        return np.array([self.trials.setdefault(v.tobytes(), len(self.trials)) for v in values], dtype=np.int64)

    def nodes(self, parent, heights, speeds) -> np.ndarray:
        """The number of each prefix ``parent`` followed by a pin at ``heights``, ``speeds``."""
        uniq, inverse = unique_rows(np.column_stack([parent, heights, speeds]), return_inverse=True)
        ids = [self.prefixes.setdefault((int(p), float(h), float(v)), len(self.prefixes) + 1) for p, h, v in uniq]
        return np.asarray(ids, dtype=np.int64)[inverse]

    def lookup(self, nodes, trials) -> np.ndarray:
        """Where each (prefix, trial) state is kept (-1: not kept)."""
        codes = self._codes(nodes, trials)
        out = np.empty(codes.size, dtype=np.int64)
        lookup_keys(self.slot_keys, self.slot_at, codes, out)
        return out

    @staticmethod
    def _codes(nodes, trials) -> np.ndarray:
        """One int64 key per (prefix, trial): the prefix's number above bit 32."""
        return (np.asarray(nodes, dtype=np.int64) << 32) | np.asarray(trials, dtype=np.int64)

    def get(self, at) -> tuple:
        """``(theta, y_c, jam reason, missed)`` kept at ``at``."""
        names = np.array(list(self.reasons), dtype=object)
        return self.theta[at], self.y_c[at], names[self.reason[at]], self.missed[at]

    def add(self, nodes, trials, theta, y_c, reasons, missed) -> None:
        """Keep these states, as many as there is room for (the first ones).
        A (prefix, trial) given twice, in one call or two, is kept at its
        last place (equal trials have equal states)."""
        start, n = self.written, np.size(nodes)
        if start + n > self.max_kept:
            n = max(0, self.max_kept - start)
            if n == 0:
                return
            nodes, trials, theta, y_c, reasons, missed = (np.asarray(x)[:n] for x in (nodes, trials, theta, y_c,
                                                                                      reasons, missed))
        while self.theta.size < start + n:
            self.theta, self.y_c = np.concatenate([self.theta, self.theta]), np.concatenate([self.y_c, self.y_c])
            self.reason, self.missed = np.concatenate([self.reason, self.reason]), np.concatenate([self.missed,
                                                                                                  self.missed])
        self.theta[start:start + n], self.y_c[start:start + n], self.missed[start:start + n] = theta, y_c, missed
        names, which = np.unique(np.asarray(reasons, dtype=str), return_inverse=True)
        codes = np.array([self.reasons.setdefault(r, len(self.reasons)) for r in names.tolist()], dtype=np.int32)
        self.reason[start:start + n] = codes[which]
        self._index(self._codes(nodes, trials), np.arange(start, start + n, dtype=np.int64))
        self.written = start + n

    def _index(self, codes, at) -> None:
        """Enter ``codes -> at`` in the table, in a table twice as large (or
        more) when this one would end more than half full."""
        size = insert_keys(self.slot_keys, self.slot_at, codes, at, self.size)
        if size < 0:
            n_slots = self.slot_keys.size
            while n_slots < 2 * (self.size + codes.size):
                n_slots *= 2
            held = self.slot_keys != EMPTY
            old_codes, old_at = self.slot_keys[held], self.slot_at[held]
            self.slot_keys, self.slot_at = np.full(n_slots, EMPTY, dtype=np.int64), np.zeros(n_slots, np.int64)
            insert_keys(self.slot_keys, self.slot_at, old_codes, old_at, 0)
            size = insert_keys(self.slot_keys, self.slot_at, codes, at, self.size)
            if size < 0:
                raise ValueError("a replay memo key is negative: prefix and trial numbers start at 0")
        self.size = size


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
    rollouts' results (``rollouts_by_speed``). Rows whose rollout inputs are
    the same, bit for bit (:func:`distinct_rows`), are rolled out once and
    share the result, so ``stretch`` hears the share of distinct rows done.

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
    model = model if "belt_speed" not in kw else "dynamic"
    theta, d, mu, v_pin = np.broadcast_arrays(*(np.asarray(x, float) for x in (theta, d, mu, v_pin)))
    # Rows that meet the pin in the same state (the corners of a perturbation
    # box share their first pins' offsets) are rolled out once.
    first, inverse = distinct_rows(theta, d, mu, v_pin, support)
    rows = slice(None) if first is None else first
    res = rollouts_by_speed(part, theta[rows], d[rows], mu[rows], v_pin[rows], pin_radius, model, kw,
                            None if support is None else np.asarray(support)[rows], supports, stretch)
    return res if inverse is None else {key: arr[inverse] for key, arr in res.items()}


def distinct_rows(theta, d, mu, v_pin, support) -> tuple:
    """The rows whose rollout inputs (orientation, contact parameter, friction,
    pin speed, support) differ, bit for bit: ``(first, inverse)``, the first
    row of each distinct input and each row's index among them, or
    ``(None, None)`` when every row is distinct. A rollout depends on its
    inputs only, so one rollout per distinct input gives every row's result."""
    theta = np.asarray(theta, float)
    n = theta.size
    columns = [theta, d, mu, v_pin, np.zeros(n) if support is None else support]
    key = np.column_stack([np.broadcast_to(np.asarray(c, float), (n,)) for c in columns])
    _, first, inverse = unique_rows(np.ascontiguousarray(key).view(np.int64), return_index=True,
                                    return_inverse=True)
    if first.size == n:
        return None, None
    return first, inverse


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
        nodes, node = unique_rows(np.column_stack([node, heights[:, k], speeds[:, k]]), return_inverse=True)
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
    groups, group_of = unique_rows(np.column_stack([v_pin, support]), return_inverse=True)

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


def replayed_paths(part: Part, plan: dict, starts: dict, mu_c, pin_radius, model,
                   verify: VerifySettings | None = None, trials=100, kernel: KernelSettings | None = None,
                   belt_speed=None, mu_s=0.5):
    """Per initial state: arrays of theta and y_c (trials x steps) of perturbed replays
    (with the dynamic model at ``belt_speed`` mm/s and belt friction ``mu_s`` if given):
    ``trials`` random trials from ``verify``'s seed and perturbation sizes
    (``None``: the schema's) and every corner of the perturbation box, replayed
    through the plan's pins (:func:`replay` with a path, at the kernel step
    ``kernel``). The carried-sets figure
    (:func:`pipeline.present.figures.carried.plot_carried`) draws them."""
    verify = verify or VerifySettings()
    kernel = kernel or KernelSettings()
    rng = np.random.default_rng(verify.seed)
    n = len(plan["pins"])
    out = {}
    for label, (theta, y_c) in starts.items():
        th, yc, mu, offs = perturbed_batch(theta, y_c, mu_c, n, verify, rng, trials)
        corners = corner_inputs(theta, y_c, mu_c, n, verify)
        th, yc, mu = (np.concatenate([x, c]) for x, c in zip((th, yc, mu), corners[:3]))
        offs = np.concatenate([offs, corners[3]])
        path = [(th % 360.0, yc.copy())]
        replay(part, plan["pin_heights_mm"], plan["pin_speeds"], th, yc, mu, offs, pin_radius, model,
               path=path, belt_speed=belt_speed, mu_s=mu_s, **kernel.as_kwargs())
        out[label] = (np.stack([p[0] for p in path], axis=1), np.stack([p[1] for p in path], axis=1))
    return out
