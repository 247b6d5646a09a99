"""Build a plan's one claim (:class:`~pipeline.planning.core.claim.Claim`)
from its held-out replay, or from its support family's check.

The claimed arc is the verified set (the narrowest arc holding the required
share of the trials) widened about its middle to the tolerance: the widest
arc the promise "one arc of at most T" allows around the trials, and the
arc the support-family and shape-tolerance certificates check. The counts
of the claim are the trials inside that arc, so a replay that counts the
finals in the printed arc gets the printed numbers.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from pipeline.planning.claims.confidence import share_lower_bound
from pipeline.planning.claims.orient import best_arc, max_failures
from pipeline.planning.core.arcs import in_arc
from pipeline.planning.core.claim import Claim
from pipeline.planning.core.settings import ClaimSettings, VerifySettings

UNIFORM = "the part (uniform pressure)"


def drawn_members(label: str) -> str:
    """The subject of a claim on a support family's drawn members, before (or
    without) the family's own check."""
    return f"the part on the drawn members of the support family {label}"


def claimed_arc(verdict: dict, tolerance: float) -> tuple | None:
    """The set a plan claims: its verified set widened about its middle to
    the tolerance (the widest arc the claim "one arc of at most T" allows
    around the trials), ``(start, width)`` in degrees; ``None`` when the
    verdict has no set (too many trials jammed). The support-family and
    shape-tolerance checks test members against this arc."""
    s = verdict.get("set")
    if not s:
        return None
    grow = max(0.0, tolerance - s["width"]) / 2.0
    return (s["start"] - grow, max(s["width"], tolerance))


def promised_arc(verdict: dict, tolerance: float) -> tuple | None:
    """:func:`claimed_arc` as the plan file stores it: the start in [0, 360)
    and both to 4 decimals."""
    arc = claimed_arc(verdict, tolerance)
    return None if arc is None else (round(arc[0] % 360.0, 4), round(arc[1], 4))


EDGE_DEG = 1e-4  # arcs are stored to 4 decimals: a final this close to an end counts as inside


def count_in_arc(finals, arc: tuple, order: int = 1) -> int:
    """How many of ``finals`` (deg) lie in ``arc`` on the circle of the part's
    distinct orientations (period ``360 / order``), its ends widened by
    ``EDGE_DEG`` (many trials can end at exactly the same orientation, on
    the end of the arc that holds them)."""
    return int(np.count_nonzero(in_arc(np.asarray(finals, float), arc[0] - EDGE_DEG, arc[1] + EDGE_DEG,
                                       tol=EDGE_DEG, period=360.0 / order)))


def trials_drawn(verify: VerifySettings, rows: list) -> dict:
    """How the claim's trials were drawn: ``verify`` are the settings they
    were drawn with (``VerifySettings.held_out`` for held-out trials), ``rows``
    the verification's per-state rows; held-out or not, the seed, and per
    resting state the random trials and the box corners."""
    per_state = sorted({int(r["trials"]) for r in rows})
    corners = sorted({max(0, n - int(verify.trials)) for n in per_state}) if verify.corners else [0]
    return {"kind": "held-out" if verify.holdout else "selection", "seed": int(verify.seed), "states": len(rows),
            "random_per_state": int(verify.trials),
            "corners_per_state": corners[0] if len(corners) == 1 else corners}


def perturbations(verify: VerifySettings, mu_c) -> dict:
    """The sizes of the errors each trial draws, and where the normals are cut."""
    p = verify.perturbation
    friction = ({"uniform": [float(mu_c[0]), float(mu_c[1])]} if isinstance(mu_c, (tuple, list))
                else {"normal_sigma": p.mu_sigma, "cut_at_sigma": verify.truncate_sigma, "floor": 0.0})
    return {"theta_deg": {"normal_sigma": p.theta_sigma, "cut_at_sigma": verify.truncate_sigma},
            "y_c_mm": {"uniform_halfwidth": p.y_halfwidth},
            "mu_c": friction, "pin_offset_mm": {"uniform_halfwidth": p.pin_halfwidth},
            "corners": "every corner of the box: theta and mu_c at their cuts, y_c and each pin at their "
                       "half-widths" if verify.corners else "none"}


def held_out_claim(verdict: dict, finals, claims: ClaimSettings, order: int, drawn: dict, perturbed: dict,
                   subject: str = UNIFORM) -> Claim:
    """The claim of a plan judged on held-out trials: ``verdict`` is
    ``orient.judge`` of its ``finals`` (the trials that did not jam). When
    no arc of the tolerance holds the required share (the plan ends in
    several sets), the arc named is the one of the tolerance that holds the
    most trials, and the claim says that the plan does not orient the part."""
    tol = float(claims.tolerance_deg)
    arc = promised_arc(verdict, tol)
    if arc is None or arc[1] > tol + 1e-9:  # no arc of the tolerance holds the required share: name the best one
        arc = (round(best_arc(finals, tol, order)[1] % 360.0, 4), tol)
    n = int(verdict["trials"])
    inside = count_in_arc(finals, arc, order)
    share, lower = _share(inside, n, claims.confidence)
    clears = n > 0 and n - inside <= max_failures(n, claims.required, claims.confidence, claims.rule)
    interval = verdict.get("width_interval_deg")
    return Claim(subject, bool(verdict["orients"] and clears), arc, tol, claims.rule, claims.required,
                 claims.confidence, inside, n, int(verdict["jammed"]), share, lower,
                 verdict.get("width_deg"), verdict.get("spread_deg"), drawn, perturbed,
                 tuple(interval) if interval else None, int(order),
                 sets_within_tolerance=verdict.get("sets_within_tolerance"))


def with_untruncated(claim: Claim, record: dict | None) -> Claim:
    """``claim`` with the untruncated replay beside it (the plan file's
    ``untruncated`` record, see :mod:`~pipeline.planning.claims.tails`): its
    trials are random draws only, so it says that it does not replay the
    box corners (those are in the claim's own trials)."""
    if not record:
        return claim
    beside = {"trials": record["trials"], "in_best_arc": record["in_one_set"], "share": record["share"],
              "share_lower_bound": record["lower_bound"], "width_deg": record["width_deg"],
              "orients": record["orients"], "not_cut": list(record["normal"]), "seed": record["seed"],
              "box_corners": False,
              "note": "random draws from normals that are not cut; the box corners are not replayed here "
                      "(they are among the claim's own trials)"}
    return replace(claim, untruncated=beside)


def family_claim(claim: Claim, label: str, check: dict, certificate: dict | None = None) -> Claim:
    """The claim of a plan for the support family ``label``: the family
    check's set (the arc its worst members and fresh members are checked
    against; when no arc of the tolerance holds the required share, the one
    that holds the most, as for one part), its counts over the drawn members
    and the worst members that joined them, and its spread (every such
    trial, the worst member's included), not the drawn members' own width."""
    verdict = check["verdict"]
    named = verdict.get("claimed_arc_deg")  # a check stored before it was kept: the set it checked
    arc = tuple(named) if named else tuple(check["set_deg"]) if check.get("set_deg") else claim.arc
    family = {"label": label, "members": check.get("members"), "holds": bool(check.get("holds")),
              "worst_member_outside_deg": (check.get("worst_member") or {}).get("outside_deg"),
              "worst_member_search": "a heuristic: evidence about the family's edge, not a proof"}
    if certificate:
        fresh = certificate["fresh"]
        family.update(fresh_members=fresh["members"], fresh_members_outside=fresh["members_outside"],
                      share_outside_upper_bound=fresh["share_outside_upper_bound"],
                      epsilon=certificate["claim"]["epsilon"], beta=certificate["claim"]["beta"],
                      holds=bool(certificate["holds"]))
    n = int(verdict["trials"])
    # The count in the named arc itself; a check stored before it was kept counts the best arc
    # of the tolerance, the same number when the set fits the tolerance.
    inside = int(verdict["in_claimed_arc"] if named else verdict["in_tolerance"])
    share, lower = _share(inside, n, claim.confidence)
    return replace(claim, subject=f"every member of the support family {label}", arc=arc, in_arc=inside,
                   trials=n, jammed=int(verdict.get("jammed", 0)), share=share,
                   share_lower_bound=lower, orients=bool(verdict["orients"] and family["holds"]),
                   width_deg=verdict.get("width_deg"), spread_deg=verdict.get("spread_deg"),
                   width_interval_deg=None, trials_drawn=dict(claim.trials_drawn, kind="family check",
                                                              members=check.get("members")),
                   family=family)


def _share(inside: int, n: int, confidence: float) -> tuple[float, float]:
    """``(share, lower bound)`` of ``inside`` of ``n`` trials (to 6 decimals; 0 without trials)."""
    if not n:
        return 0.0, 0.0
    return round(inside / n, 6), round(share_lower_bound(inside, n, confidence), 6)
