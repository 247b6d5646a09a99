"""What a plan's claim "for the support family" rests on, in one record.

A plan recommended for a support family passed three checks: the sampled
verification on the members the family text draws, the worst-member search
(:mod:`pipeline.planning.family.worst_member`; worst members that broke the plan
joined the verification and the plan was judged again), and the fresh sample
below. The certificate records all three:

* the members and trials of the verification the claim rests on;
* the worst member found: its parameters (leg positions and weights, or warp
  coefficients), its nominal finals and how far its farthest final lies
  outside the plan's set (negative: inside, by that much);
* a *fresh* seeded sample of at least ``MIN_FRESH_MEMBERS`` members that
  neither the planner nor the search saw (seed stream ``[verify.seed, 34]``),
  each replayed from every resting state nominally and with
  ``FRESH_TRIALS`` perturbed trials: how many members put any trial outside
  the set, and the one-sided 95 % Clopper-Pearson upper bound on the share
  of such members in the family (:func:`~pipeline.planning.claims.confidence.share_upper_bound`).

The upper bound is a statement about members drawn the way the family text
draws them (uniform legs in the inset outline, or uniform warp directions);
the worst-member search is the statement about the family's edge.
"""
from __future__ import annotations

import numpy as np

from pipeline.planning.claims import orient
from pipeline.planning.claims.confidence import DEFAULT_CONFIDENCE, share_upper_bound
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import nominal_friction
from pipeline.planning.claims.replay import replay
from pipeline.planning.claims.trials import perturbed_batch
from pipeline.planning.family.member_search import JAM_SCORE, kernel_steps, outside
from pipeline.planning.family.member_spaces import member_space
from pipeline.planning.family.worst_member import arc_holds
from pipeline.progress import SILENT, Heartbeat, Stretch

MIN_FRESH_MEMBERS = 300
FRESH_TRIALS = 4  # perturbed trials per member and resting state (besides the nominal one)
FRESH_CHUNK = 50  # members replayed at once (a refutation may stop after the first chunks)


def fresh_members(part, family, n: int, seed: int) -> list:
    """``n`` members of each continuous part of ``family`` (tripods, warps),
    drawn with ``default_rng([seed, 34])``, and every listed member."""
    space = member_space(part, family)
    rng = np.random.default_rng([int(seed), 34])
    out = []
    for s in space.spaces:
        out.extend(s.sample(rng, n))
    return out + list(space.fixed)


def fresh_replay(part, heights, members, st, speeds=(), trials: int = FRESH_TRIALS, seed: int = 0,
                 stretch: Stretch = SILENT, give_up=None):
    """Final orientations ``(members, states * (1 + trials))`` and jam flags of
    every member, each from every resting state nominally and with ``trials``
    perturbed starts (the verification's perturbation box); ``stretch`` is
    told how far the replay has got.

    The members are replayed ``FRESH_CHUNK`` at a time (every start is drawn
    first, so the numbers do not depend on it); ``give_up(finals, jams)``,
    asked with the members replayed so far, may end the replay early: then
    the result is None."""
    rng = np.random.default_rng([int(seed), 35])
    n_pins = len(heights)
    rows = []
    for theta, y_c in resting_states(part).values():
        th, yc, mu, offs = perturbed_batch(theta, y_c, st.mu_c, n_pins, st.verify.as_dict(), rng,
                                           trials * len(members))
        mid = nominal_friction(st.mu_c)
        rows.append((np.full(len(members), theta), np.full(len(members), y_c), np.full(len(members), mid),
                     np.zeros((len(members), n_pins)), np.arange(len(members))))
        rows.append((th, yc, mu, offs, np.repeat(np.arange(len(members)), trials)))
    th, yc, mu, offs, sup = (np.concatenate([r[k] for r in rows]) for k in range(5))
    order = np.argsort(sup, kind="stable")  # member by member, each in the order above
    per = th.size // len(members)
    search, kw = st.search, kernel_steps(st.search.kernel_settings)
    tf, jam = np.empty((len(members), per)), np.empty((len(members), per), bool)
    for lo in range(0, len(members), FRESH_CHUNK):
        hi = min(len(members), lo + FRESH_CHUNK)
        idx = order[lo * per:hi * per]
        out, _, jams, _ = replay(part, list(heights), list(speeds) or [0.0] * n_pins, th[idx], yc[idx], mu[idx],
                                 offs[idx], search.pin_radius, search.model, **kw, support=sup[idx] - lo,
                                 supports=[None if m.is_uniform else m for m in members[lo:hi]],
                                 stretch=stretch.part(lo / len(members), hi / len(members)))
        tf[lo:hi], jam[lo:hi] = out.reshape(hi - lo, per), (jams != "").reshape(hi - lo, per)
        if give_up is not None and give_up(tf[:hi], jam[:hi]):
            return None
    return tf, jam


def fresh_finals(part, heights, family, st, n_members: int = MIN_FRESH_MEMBERS, speeds=(), progress=None,
                 must_fit: bool = False, members=None):
    """``(members, finals, jams)`` of the certificate's fresh sample (at least
    ``MIN_FRESH_MEMBERS`` of each continuous part of ``family``) replayed
    through the pins at ``heights`` (:func:`fresh_replay`); ``progress`` hears
    how far the replay has got. ``must_fit``: None as soon as the members
    replayed so far fail :func:`fresh_fit` (then the whole sample does), so
    a result is a sample that fits.
    ``members``: that sample, when drawn before (:func:`fresh_members` with
    these ``n_members`` and ``st.seed``), to replay it through other pins."""
    if members is None:
        members = fresh_members(part, family, max(int(n_members), MIN_FRESH_MEMBERS), st.seed)
    order = part.symmetry_order()
    replayed = [0]

    def give_up(tf, jam):
        replayed[0] = tf.shape[0]
        return must_fit and not fresh_fit((None, tf, jam), st.claims.tolerance_deg, order)
    with Heartbeat(f"fresh members of {family.label}", len(members), "member", progress) as beat:
        got = fresh_replay(part, heights, members, st, speeds, seed=st.seed, stretch=beat.stretch(0, len(members)),
                           give_up=give_up)
        if got is None:
            beat.finish(replayed[0], "stopped: their finals fit in no arc of the tolerance, so no set holds them all")
    return None if got is None else (members, *got)


def fresh_fit(fresh, tolerance: float, order: int = 1) -> bool:
    """Whether every final of the fresh sample ``fresh`` (:func:`fresh_finals`)
    lies in one arc of ``tolerance`` degrees and none jammed: when not, every
    set a plan may claim leaves a fresh member outside, whatever the
    worst-member search then finds, so the certificate cannot count 0
    violations (a falsifier that costs one replay instead of a search)."""
    _, tf, jam = fresh
    return not jam.any() and arc_holds(tf.ravel(), tolerance, order)


def family_certificate(part, heights, family, check: dict, st, n_members: int = MIN_FRESH_MEMBERS,
                       speeds=(), confidence: float = DEFAULT_CONFIDENCE, progress=None, fresh=None) -> dict:
    """The certificate of a plan (pins at ``heights``) for ``family`` given its
    worst-member ``check`` (:func:`~pipeline.planning.family.worst_member.check_plan_for_family`);
    a JSON-ready dict (see the module docstring). ``progress`` hears how far
    the fresh members' replay has got; ``fresh``: that replay
    (:func:`fresh_finals`), when it was done before (its members are drawn
    from ``st.seed`` alone, so it is the same sample)."""
    period = 360.0 / part.symmetry_order()
    members, tf, jam = fresh if fresh is not None else fresh_finals(part, heights, family, st, n_members, speeds,
                                                                    progress)
    arc = check.get("set_deg")
    dist = np.where(jam, JAM_SCORE, outside(tf, tuple(arc), period)) if arc else np.full(tf.shape, JAM_SCORE)
    leaving = int(np.sum(dist.max(axis=1) > 0.0))
    claims = st.claims
    verdict = orient.judge(tf[~jam], tf.size, claims.tolerance_deg, part.symmetry_order(), claims.required)
    worst = check.get("worst_member") or {}
    return {
        "family": family.label, "holds": bool(check["holds"] and verdict["orients"]),
        "set_deg": arc, "tolerance_deg": claims.tolerance_deg, "required": claims.required,
        "verification": {"members": check["members"], "trials": check["trials"],
                         "in_tolerance": check["verdict"]["in_tolerance"],
                         "width_deg": check["verdict"]["width_deg"]},
        "search": {"space": check["space"], "budget": check["budget"], "rounds": len(check["rounds"])},
        "worst_member": {k: worst.get(k) for k in ("parameters", "outside_deg", "breaks",
                                                    "nominal_finals_deg", "found_by", "evaluations")},
        "carried_sets": _ASSUMES["carried sets"].format(family.label),
        "fresh": {"members": len(members), "trials": int(tf.size), "seed": [st.seed, 34],
                  "members_outside": leaving, "confidence": confidence,
                  "share_outside_upper_bound": round(share_upper_bound(leaving, len(members), confidence), 5),
                  "in_tolerance": verdict["in_tolerance"], "width_deg": verdict["width_deg"],
                  "orients": verdict["orients"]},
        "claim": scenario_claim(leaving, len(members), confidence),
    }


def scenario_claim(violations: int, members: int, confidence: float = DEFAULT_CONFIDENCE) -> dict:
    """What the fresh members support, as epsilon and beta: with confidence
    ``1 - beta``, a member drawn the way the family text draws them puts a
    final outside the set with probability at most ``epsilon`` (the one-sided
    Clopper-Pearson bound of ``violations`` in ``members``; with none, the
    scenario approach's ``members >= ln(1/beta) / -ln(1 - epsilon)``, Campi
    and Garatti). The worst-member search adds no probability: it is a
    heuristic, evidence about the family's edge, not a proof."""
    epsilon = share_upper_bound(violations, members, confidence)
    beta = 1.0 - confidence
    return {"epsilon": round(epsilon, 5), "beta": round(beta, 6), "members": int(members),
            "violations": int(violations),
            "statement": (f"with confidence {1 - beta:.4g}, a member drawn as the family text draws them ends "
                          f"outside the set with probability at most {100 * epsilon:.2f} % ({violations} of "
                          f"{members} fresh members did)"),
            "search": ("the worst-member search is a heuristic (multi-start Nelder-Mead from the family's "
                       "corners): finding no member outside is evidence about the family's edge, not a proof")}


def members_needed(epsilon: float, beta: float) -> int:
    """Members with no violation needed for ``epsilon`` at confidence ``1 - beta``:
    ``ceil(ln(1/beta) / -ln(1 - epsilon))`` (299 for 1 % at 0.05)."""
    return int(np.ceil(np.log(1.0 / beta) / -np.log1p(-epsilon)))


def family_certificate_line(cert: dict) -> str:
    """One line for ``pinfeed plan --support-family``: what "for the family" rests on."""
    w, f = cert["worst_member"], cert["fresh"]
    where = ("inside the set by" if (w.get("outside_deg") or 0) <= 0 else "outside the set by")
    verdict = "holds" if cert["holds"] else "does NOT hold"
    return (f"family {cert['family']}: the plan {verdict} for {cert['verification']['members']} members "
            f"({cert['verification']['trials']} trials) and the worst member found "
            f"({w.get('found_by')}, {cert['search']['budget']} evaluations; farthest final "
            f"{where} {abs(w.get('outside_deg') or 0):.2f} deg); {f['members_outside']} of {f['members']} "
            f"fresh members leave the set (share <= {100 * f['share_outside_upper_bound']:.2f} % at "
            f"{100 * f['confidence']:g} % confidence), {f['in_tolerance']} of {f['trials']} fresh trials "
            f"in one set of {cert['tolerance_deg']:g} deg; epsilon {100 * cert['claim']['epsilon']:.2f} %, "
            f"beta {cert['claim']['beta']:g}; the worst-member search is a heuristic")


# --------------------------------------------------------------------------- what downstream stages assume

_ASSUMES = {
    "speed limit": "the speed limit assumes uniform pressure: the dynamic model integrates the uniform "
                   "belt force and refuses point supports, so it is not checked for the support family {}",
    "layout": "the layout's belt speed and pin spacing assume uniform pressure (the dynamic model "
              "refuses point supports): they are not checked for the support family {}",
    "carried sets": "the carried sets are sampled over the support family {}'s drawn members (and the "
                    "worst members that broke an earlier verdict); the worst member found last is checked "
                    "against the claimed final set only",
}


def plan_family_label(source) -> str | None:
    """The support family a stored plan was made for (its label), or None: ``source``
    is a plan file (:class:`~pipeline.planning.core.types.PlanFile` or its dict) or one
    of its ``tight`` entries."""
    entries = source.get("tight") if isinstance(source, dict) else getattr(source, "tight", None)
    for entry in (entries if entries is not None else [source]):
        family = entry.get("support_family") if isinstance(entry, dict) else getattr(entry, "support_family", None)
        if family:
            return family["label"] if isinstance(family, dict) else str(family)
    return None


def family_assumption(source, stage: str) -> dict:
    """``{}`` for a plan made for uniform pressure; else ``{"assumes": "uniform
    pressure", "assumption": one line}`` for ``stage`` (``"speed limit"``,
    ``"layout"``) of a plan made for a support family (``source`` as for
    :func:`plan_family_label`)."""
    label = plan_family_label(source)
    if label is None:
        return {}
    assumes = "uniform pressure" if stage != "carried sets" else "the sampled members"
    return {"assumes": assumes, "assumption": _ASSUMES[stage].format(label)}
