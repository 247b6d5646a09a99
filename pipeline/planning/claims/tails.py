"""The tails of the arrivals: a certified plan replayed with untruncated normals.

Verification draws the initial orientation theta and a single friction value
mu_c from normals cut at ``TRUNCATE_SIGMA`` (2) sigma, the planner's box. A
cut at 2 sigma leaves out 4.55 % of a normal's mass, while a claim of 99.5 %
of the trials in one set is a claim about the tails. So the recommended plan
is replayed once more on trials whose normals are not cut (same sigmas;
y_c and the pin offsets keep their uniform boxes; a friction range stays
uniform over the range, only theta's normal is uncut), from a seed of its
own (:meth:`VerifySettings.untruncated
<pipeline.planning.core.settings.VerifySettings.untruncated>`), as many per
initial state as its held-out trials, and judged by the same rule
(:func:`pipeline.planning.claims.orient.judge`). The record says what the
plan does beyond the box; the claim itself stays the held-out one.
"""
from __future__ import annotations

from pipeline.planning.claims.orient import judge_verification
from pipeline.planning.claims.verify import verify_plan
from pipeline.planning.core.settings import (TRUNCATE_SIGMA, UNTRUNCATED_STREAM,  # noqa: F401 (re-exported)
                                             ClaimSettings, VerifySettings)


def normal_quantities(mu_c) -> list[str]:
    """Which perturbations are drawn from normals: theta, and mu_c unless it is a range."""
    return ["theta"] if isinstance(mu_c, (tuple, list)) else ["theta", "mu_c"]


def untruncated_check(part, plan: dict, pins: dict, initial_states: dict, mu_c, pin_radius: float,
                      model: str, settings: VerifySettings, trials_per_state: int, claims: ClaimSettings,
                      order: int = 1, **replay) -> dict:
    """Replay ``plan`` (a plan record or a stored plan dict) on untruncated trials and judge it.

    Parameters
    ----------
    part, plan, pins, initial_states, mu_c, pin_radius, model : as
        :func:`~pipeline.planning.claims.verify.verify_plan` takes them.
    settings : the verification's settings (sigmas, boxes, seed), whose
        :meth:`~pipeline.planning.core.settings.VerifySettings.untruncated`
        trials these are.
    trials_per_state : random trials per initial state (as many as the held-out trials).
    claims : the claim's tolerance, required share, confidence and rule.
    order : the part's rotational symmetry order.
    replay : passed on to ``verify_plan`` (``speeds``, ``kernel``,
        ``belt_speed``, ``mu_s``, ``family``, ``stretch``).

    Returns
    -------
    dict
        :func:`untruncated_record` of the verdict.
    """
    tails = settings.untruncated(trials_per_state)
    res = verify_plan(part, plan, pins, initial_states, mu_c, pin_radius, model, tails, **replay)
    verdict = judge_verification(res, claims.tolerance_deg, order, claims.required, claims.confidence,
                                 claims.rule)
    return untruncated_record(verdict, tails.seed, mu_c)


def untruncated_record(verdict: dict, seed: int, mu_c) -> dict:
    """The plan file's ``untruncated`` record of a verdict (``orient.judge``)."""
    return {"trials": verdict["trials"], "in_one_set": verdict["in_tolerance"], "share": verdict["share"],
            "lower_bound": verdict["share_lower_bound"], "confidence": verdict["confidence"],
            "tolerance_deg": verdict["tolerance_deg"], "required": verdict["required"],
            "jammed": verdict["jammed"], "width_deg": verdict["width_deg"],
            "width_interval_deg": verdict.get("width_interval_deg"), "orients": verdict["orients"],
            "point_rule": verdict["point_rule"], "rule": verdict["rule"], "seed": int(seed),
            "normal": normal_quantities(mu_c), "truncation_sigma": None}


def truncation_text(sigma: float = TRUNCATE_SIGMA, mu_range: bool = False) -> str:
    """How the claim's trials were drawn, in words."""
    if mu_range:
        return f"theta drawn from a normal truncated at {sigma:g} sigma, mu_c uniform over its range"
    return f"theta and mu_c drawn from normals truncated at {sigma:g} sigma"


def describe_untruncated(record: dict, sigma: float | None = TRUNCATE_SIGMA) -> str:
    """The ``untruncated`` record for people, in one line (``sigma``: where
    the claim's normals are cut; ``None``: ``TRUNCATE_SIGMA``)."""
    r, sigma = record, TRUNCATE_SIGMA if sigma is None else sigma
    uncut = ", ".join(r["normal"])
    what = f"untruncated normals ({uncut} not cut at {sigma:g} sigma"
    what += "; mu_c uniform over its range" if "mu_c" not in r["normal"] else ""
    what += "; random draws only, no box corners)"
    text = (f"{what}: {r['in_one_set']}/{r['trials']} in one set of {r['tolerance_deg']:g} deg, "
            f"at least {100 * r['lower_bound']:.2f} % with {100 * r['confidence']:g} % confidence")
    if r["width_deg"] is not None:
        text += f"; width {r['width_deg']:.1f} deg"
        iv = r.get("width_interval_deg")
        if iv and iv[0] is not None:
            text += (f" ({100 * r['confidence']:g} % bootstrap interval {iv[0]:.1f}-"
                     + (f"{iv[1]:.1f}" if iv[1] is not None else "inf") + " deg)")
    if r["orients"]:
        return text + ": orients the part"
    if r["point_rule"]:
        return text + ": clears the point rule but not its confidence bound"
    return text + ": does not orient the part"
