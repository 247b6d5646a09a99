"""A plan's one claim: the typed record of what the plan promises.

Every plan a planner verifies carries exactly one claim, and every place a
user reads about the plan (``pinfeed plan``, its ``--json`` document, the
plan file, the report, the manual) prints this record and nothing that
could be mistaken for it. The claim says:

* **what** ends where: ``subject`` (the part under uniform pressure, or
  every member of a support family) ends in ``arc`` (``start``, ``width``
  in degrees; ``width`` is the tolerance): the verified set widened about
  its middle to the tolerance, the widest arc "one arc of at most T" allows
  around the trials;
* **how sure**: ``in_arc`` of ``trials`` replayed trials ended in the arc
  (``jammed`` jammed), the share and its one-sided lower confidence bound
  at ``confidence`` under ``rule`` (``bound``: Clopper-Pearson; ``point``:
  the share itself, no confidence claim), and whether that clears the
  ``required`` share (``orients``);
* **how narrow**: ``width_deg``, the narrowest arc holding the required
  share of the trials, and ``spread_deg``, the narrowest arc holding every
  trial that did not jam;
* **on which trials**: ``trials_drawn`` (held-out or not, the seed, random
  trials and box corners per resting state) and ``perturbations`` (the
  sizes of the errors each trial draws, and where the normals are cut);
* **beside it**: ``untruncated`` (the same plan on normals that are not cut,
  a check that says whether it replays the box corners) and, for a support
  family, ``family`` (its worst member and fresh members: the certificate).

Every other set a plan file holds is named for what it is: the carried sets
(``carried_sets``: a sound propagated bound or the hull of a sampled replay)
and the certificates' windows, never "the claim".
"""
from __future__ import annotations

from dataclasses import dataclass, field


def _pct(x: float) -> str:
    return f"{100 * x:.2f} %"


@dataclass(frozen=True)
class Claim:
    """What one plan promises; see the module docstring for each field."""

    subject: str
    orients: bool
    arc: tuple  # (start, width) in degrees
    tolerance_deg: float
    rule: str
    required: float
    confidence: float
    in_arc: int
    trials: int
    jammed: int
    share: float
    share_lower_bound: float
    width_deg: float | None
    spread_deg: float | None
    trials_drawn: dict
    perturbations: dict
    width_interval_deg: tuple | None = None
    symmetry_order: int = 1
    sets_within_tolerance: int | None = None
    untruncated: dict | None = None
    family: dict | None = None
    extra: dict = field(default_factory=dict)

    KEYS = ("statement", "subject", "orients", "arc", "tolerance_deg", "rule", "required", "confidence",
            "in_arc", "trials", "jammed", "share", "share_lower_bound", "width_deg", "spread_deg",
            "width_interval_deg", "symmetry_order", "sets_within_tolerance", "trials_drawn", "perturbations",
            "untruncated", "family")

    @classmethod
    def from_dict(cls, d: dict) -> "Claim":
        """The record of a stored ``claim`` dict."""
        arc = d["arc"]
        interval = d.get("width_interval_deg")
        return cls(d["subject"], bool(d["orients"]), (arc["start"], arc["width"]), d["tolerance_deg"], d["rule"],
                   d["required"], d["confidence"], d["in_arc"], d["trials"], d["jammed"], d["share"],
                   d["share_lower_bound"], d.get("width_deg"), d.get("spread_deg"), dict(d["trials_drawn"]),
                   dict(d["perturbations"]), tuple(interval) if interval is not None else None,
                   int(d.get("symmetry_order", 1)), d.get("sets_within_tolerance"), d.get("untruncated"),
                   d.get("family"), {k: v for k, v in d.items() if k not in cls.KEYS})

    def to_dict(self) -> dict:
        """The stored dict (with its one-line ``statement`` first)."""
        return {"statement": self.statement(), "subject": self.subject, "orients": self.orients,
                "arc": {"start": self.arc[0], "width": self.arc[1]}, "tolerance_deg": self.tolerance_deg,
                "rule": self.rule, "required": self.required, "confidence": self.confidence,
                "in_arc": self.in_arc, "trials": self.trials, "jammed": self.jammed, "share": self.share,
                "share_lower_bound": self.share_lower_bound, "width_deg": self.width_deg,
                "spread_deg": self.spread_deg,
                "width_interval_deg": list(self.width_interval_deg) if self.width_interval_deg else None,
                "symmetry_order": self.symmetry_order, "sets_within_tolerance": self.sets_within_tolerance,
                "trials_drawn": dict(self.trials_drawn), "perturbations": dict(self.perturbations),
                "untruncated": self.untruncated, "family": self.family, **self.extra}

    @property
    def arc_text(self) -> str:
        """The promised arc, e.g. ``19.6-29.6 deg`` (on a part with ``order``-fold
        symmetry, its copy in [0, 360 / order))."""
        period = 360.0 / self.symmetry_order
        start, width = self.arc
        return f"{start % period:.1f}-{(start % period) + width:.1f} deg"

    def trials_text(self) -> str:
        """The claim's trials and perturbations, in one line."""
        d, p = self.trials_drawn, self.perturbations
        corners = d.get("corners_per_state", 0)
        head = (f"{d.get('kind', 'replayed')} trials (seed {d.get('seed')}): {d.get('random_per_state')} random"
                f" + {corners} box corners per resting state, {d.get('states')} states")
        if d.get("members"):
            head += f", over {d['members']} support members"
        th, mu = p.get("theta_deg", {}), p.get("mu_c", {})
        friction = (f"mu_c uniform over {mu['uniform'][0]:g}-{mu['uniform'][1]:g}" if "uniform" in mu else
                    f"mu_c normal sigma {mu.get('normal_sigma'):g}")
        cut = th.get("cut_at_sigma")
        return (f"{head}; theta normal sigma {th.get('normal_sigma'):g} deg, {friction}"
                + (f", normals cut at {cut:g} sigma" if cut else "")
                + f"; y_c uniform +-{p.get('y_c_mm', {}).get('uniform_halfwidth'):g} mm, each pin uniform "
                  f"+-{p.get('pin_offset_mm', {}).get('uniform_halfwidth'):g} mm")

    def statement(self) -> str:
        """The claim in one line, as every output prints it."""
        held = f"{self.in_arc}/{self.trials} {self.trials_drawn.get('kind', '')} trials".replace("  ", " ")
        if self.rule == "bound":
            sure = (f"at least {_pct(self.share_lower_bound)} with {100 * self.confidence:g} % confidence "
                    f"({held} in it; required {_pct(self.required)})")
        else:
            sure = f"{_pct(self.share)} by the point rule, no confidence claim ({held} in it)"
        copies = (f"; or a copy of it every {360.0 / self.symmetry_order:g} deg, by symmetry"
                  if self.symmetry_order > 1 else "")
        if not self.orients and (self.sets_within_tolerance or 1) > 1:
            return (f"{self.subject} does NOT end in one arc of {self.tolerance_deg:g} deg: the best one, "
                    f"{self.arc_text}{copies}, holds {held} ({_pct(self.share)}; at least "
                    f"{_pct(self.share_lower_bound)} with {100 * self.confidence:g} % confidence, required "
                    f"{_pct(self.required)}); its trials end in {self.sets_within_tolerance} sets of at most "
                    f"{self.tolerance_deg:g} deg")
        verb = "ends" if self.orients else "does NOT reliably end"
        width = "" if self.width_deg is None else f"; {_pct(self.required)} of them within {self.width_deg:.1f} deg"
        if self.width_deg is not None and self.width_interval_deg and self.width_interval_deg[0] is not None:
            lo, hi = self.width_interval_deg
            width += (f" ({100 * self.confidence:g} % bootstrap interval {lo:.1f}-"
                      + ("inf" if hi is None else f"{hi:.1f}") + " deg)")
        if self.family and self.spread_deg is not None:
            width += f"; every trial, the worst member's included, within {self.spread_deg:.1f} deg"
        return (f"{self.subject} {verb} in {self.arc_text} (one arc of {self.tolerance_deg:g} deg{copies}): "
                f"{sure}{width}")
