"""The trials a plan is replayed on: draws from the perturbation box, and its corners.

Each trial starts from an initial resting state and perturbs the initial
orientation and centroid height, the friction and every pin's position.
The perturbation box is the planner's (``propagate.Uncertainty``):
orientation and friction are normal with the configured sigma, truncated at
2 sigma (a friction range ``(lo, hi)`` is sampled uniformly); centroid
height and pin positions are uniform within their half-widths. Besides the
random trials, every corner of the box is replayed (``corners``). The sizes
are a :class:`~pipeline.planning.core.settings.Perturbation`; how many
trials, from which seed and cut where, a
:class:`~pipeline.planning.core.settings.VerifySettings` (its held-out
trials: :meth:`~pipeline.planning.core.settings.VerifySettings.held_out`).
The same settings give the same trials.
"""
from __future__ import annotations

import dataclasses
import itertools

import numpy as np

from pipeline.planning.core.settings import (HOLDOUT_STREAM, TRUNCATE_SIGMA,  # noqa: F401 (re-exported)
                                             Perturbation, VerifySettings, as_verify_settings)

PERTURB_DEFAULTS = dataclasses.asdict(Perturbation())  # the schema's verify perturbation sizes
DEFAULTS = VerifySettings().as_dict()  # the schema's verify section (trials, corners, seed, sizes)


def box_sizes(box) -> tuple[Perturbation, float | None]:
    """``(sizes, cut)`` of a perturbation box: a
    :class:`~pipeline.planning.core.settings.Perturbation` (its normals cut at
    ``TRUNCATE_SIGMA``) or a :class:`~pipeline.planning.core.settings.VerifySettings`
    (its sizes, cut at its ``truncate_sigma``). A flat dict of
    ``VerifySettings.as_dict()`` keys, which callers not yet switched still
    pass, is read with :func:`~pipeline.planning.core.settings.as_verify_settings`."""
    if isinstance(box, Perturbation):
        return box, TRUNCATE_SIGMA
    settings = as_verify_settings(box)
    return settings.perturbation, settings.truncate_sigma


def verify_dict(settings) -> dict:
    """The trial settings as a flat dict, for callers not yet switched to
    :class:`~pipeline.planning.core.settings.VerifySettings`: its
    :meth:`~pipeline.planning.core.settings.VerifySettings.as_dict`, or a
    partial dict over the schema's defaults (:data:`DEFAULTS`)."""
    if isinstance(settings, VerifySettings):
        return settings.as_dict()
    return dict(DEFAULTS, **(settings or {}))


def holdout_settings(settings, attempt: int = 0) -> dict:
    """The held-out trials' settings as a flat dict
    (:meth:`VerifySettings.held_out <pipeline.planning.core.settings.VerifySettings.held_out>`
    of ``settings``), for callers not yet switched to it."""
    return as_verify_settings(settings).held_out(attempt).as_dict()


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


def perturbed_inputs(theta, y_c, mu_c, n_pins, box, rng):
    """One trial's inputs: theta_i, y_c, mu_c and an offset for each of
    ``n_pins`` pins, drawn from the perturbation box ``box`` (see :func:`box_sizes`)."""
    th, yc, mu, offs = perturbed_batch(theta, y_c, mu_c, n_pins, box, rng, 1)
    return float(th[0]), float(yc[0]), float(mu[0]), offs[0]


def perturbed_batch(theta, y_c, mu_c, n_pins, box, rng, n):
    """``n`` trials' inputs as arrays ``(theta (n,), y_c (n,), mu (n,), offsets (n, n_pins))``
    from the perturbation box ``box`` (a ``Perturbation``, or a
    ``VerifySettings``: its sizes and where its normals are cut; see
    :func:`box_sizes`). ``mu_c`` is a value (normal, truncated, clipped at
    0) or a range ``(lo, hi)`` (uniform)."""
    sizes, cut = box_sizes(box)
    th = theta + normal_draws(rng, sizes.theta_sigma, n, cut)
    yc = y_c + rng.uniform(-sizes.y_halfwidth, sizes.y_halfwidth, n)
    if isinstance(mu_c, (tuple, list)):
        mu = rng.uniform(float(mu_c[0]), float(mu_c[1]), n)
    else:
        mu = np.maximum(0.0, mu_c + normal_draws(rng, sizes.mu_sigma, n, cut))
    offs = rng.uniform(-sizes.pin_halfwidth, sizes.pin_halfwidth, (n, n_pins))
    return th, yc, mu, offs


def corner_inputs(theta, y_c, mu_c, n_pins, box):
    """Every corner of the perturbation box ``box`` (its sizes, normals at
    ``TRUNCATE_SIGMA``; see :func:`box_sizes`), as arrays like :func:`perturbed_batch`."""
    sizes, _ = box_sizes(box)
    ts = TRUNCATE_SIGMA
    if isinstance(mu_c, (tuple, list)):
        mus = (float(mu_c[0]), float(mu_c[1]))
    else:
        mus = (max(0.0, mu_c - ts * sizes.mu_sigma), mu_c + ts * sizes.mu_sigma)
    h = sizes.pin_halfwidth
    rows = list(itertools.product((-1.0, 1.0), (-1.0, 1.0), mus, *[(-h, h)] * n_pins))
    arr = np.array([r[:3] for r in rows], dtype=float)
    offs = np.array([r[3:] for r in rows], dtype=float).reshape(len(rows), n_pins)
    return (theta + arr[:, 0] * ts * sizes.theta_sigma, y_c + arr[:, 1] * sizes.y_halfwidth,
            arr[:, 2], offs)


def trial_inputs(initial_states: dict, mu_c, n_pins: int, settings: VerifySettings, family=None) -> list:
    """The trials :func:`~pipeline.planning.claims.verify.verify_plan` replays
    for a plan of ``n_pins`` pins: per initial state (in order), arrays
    ``(theta, y_c, mu, offsets (n, n_pins), support)`` of ``settings.trials``
    random trials followed by every corner of the perturbation box
    (``settings.corners``). The same settings give the same trials, so a
    subset of them can be replayed first to reject a plan early. (A flat
    dict of ``VerifySettings.as_dict()`` keys, which callers not yet
    switched still pass, is read with ``as_verify_settings``.)

    ``support`` is each trial's member index in ``family`` (a
    :class:`~pipeline.parts.support_family.SupportFamily`; all 0 without one,
    and then the trials are exactly those of uniform pressure). With a family,
    the random trials take its members in turn, in a seeded random order (a
    stratified sample: each member ``trials / len(family)`` times, give or take
    one), and the corners are replayed once under each of the family's
    ``representatives``."""
    settings = as_verify_settings(settings)
    rng = np.random.default_rng(settings.seed)
    members = 1 if family is None else len(family.members)
    reps = (0,) if family is None else family.representatives
    pick = np.random.default_rng([int(settings.seed), 25])  # its own stream: uniform trials stay as they were
    out = []
    for state in initial_states.values():
        theta0, yc0 = state_start(state)
        n = int(settings.trials)
        th, yc, mu, offs = perturbed_batch(theta0, yc0, mu_c, n_pins, settings, rng, n)
        sup = pick.permutation(np.resize(np.arange(members), n)) if members > 1 else np.zeros(n, int)
        if settings.corners:
            corners = corner_inputs(theta0, yc0, mu_c, n_pins, settings)
            k = corners[0].size
            th, yc, mu = (np.concatenate([x, np.tile(c, len(reps))]) for x, c in zip((th, yc, mu), corners[:3]))
            offs = np.concatenate([offs, np.tile(corners[3], (len(reps), 1))])
            sup = np.concatenate([sup, np.repeat(np.asarray(reps, int), k)])
        out.append((th, yc, mu, offs, sup))
    return out


def state_start(state):
    """``(theta, y_c)`` of an initial state given as a pair or as a planner state."""
    if isinstance(state, (tuple, list)):
        return float(state[0]), float(state[1])
    return float(state.arc[0]), float(state.y_lo)
