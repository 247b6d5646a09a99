"""Shape-tolerance families: every part within a manufacturing tolerance.

A drawing's part is made within a tolerance: each vertex of the outline may
lie anywhere within ``tol`` mm of where it is drawn (a disc per vertex; the
holes are kept as drawn). The family is every such part. A plan holds for
it when every member's finals, from every one of *its own* resting states
nominally and at every corner of the verification's perturbation box, end
in the plan's claimed set (its verified set widened to the tolerance about
its middle); a jam is outside.

* :func:`shape_worst_member` searches the 2n vertex offsets for the member
  farthest outside the set, with the same seeded multi-start Nelder-Mead
  as the support families (:func:`~pipeline.planning.family.member_search.search_worst_member`),
  started from every vertex pushed outwards and inwards along its bisector
  and from seeded random members.
* :func:`shape_certificate` adds a fresh seeded sample of members (uniform
  in each vertex's disc) and states epsilon and beta
  (:func:`~pipeline.planning.family.certificate.scenario_claim`).
* :func:`certified_radius` finds, when the plan does not hold at ``tol``,
  the largest tolerance (bisection, ``STEPS`` halvings) at which it holds
  with no fresh member outside: the plan's certified radius.

Each member is a new :class:`~pipeline.parts.part.Part` (its centroid, size
and resting states recomputed). Its frame is the drawing's, moved to the
member's own centroid, so orientations compare with the drawn part's.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part
from pipeline.planning.claims.replay import replay
from pipeline.planning.core.settings import VerifySettings
from pipeline.planning.core.types import PlanFile, TightEntry
from pipeline.planning.family.certificate import scenario_claim
from pipeline.planning.family.member_search import (WorstMember, kernel_steps, outside, probe_inputs,
                                                    search_worst_member)
from pipeline.planning.family.member_spaces import MemberSpace
from pipeline.planning.claims.plan_claim import claimed_arc
from pipeline.planning.family.worst_member import FamilyCheckSettings, stored_set

FRESH_MEMBERS = 300
STEPS = 5


def member_part(part: Part, offsets_mm: np.ndarray) -> Part:
    """The drawn ``part`` with its outline's vertices moved by ``offsets_mm``
    (n x 2, mm, the part's frame); None when the outline stops being simple."""
    verts = np.asarray(part.vertices, float) + np.asarray(offsets_mm, float).reshape(-1, 2)
    try:
        return Part.from_vertices([tuple(v) for v in verts], f"{part.name}~",
                                  holes=[np.asarray(h, float).tolist() for h in getattr(part, "holes", ())])
    except (PinfeedError, ValueError):
        return None


class ShapeProbe:
    """Scores a member part on a plan: its own resting states, nominal and
    at every box corner, past the plan's pins."""

    def __init__(self, part: Part, heights, mu_c, verify: VerifySettings, pin_radius=3.0, model="minpower",
                 kernel=None):
        self.part, self.heights, self.mu_c = part, tuple(float(h) for h in heights), mu_c
        self.verify, self.pin_radius, self.model = verify, float(pin_radius), model
        self.kernel = kernel_steps(kernel)
        self.nominal = np.zeros(0, int)

    def finals(self, member: Part | None) -> tuple[np.ndarray, np.ndarray]:
        """``(theta_f, jammed)`` of every probe start of ``member`` (None: a
        member whose outline is not simple, scored as a jam)."""
        if member is None:
            return np.array([np.nan]), np.array([True])
        n = len(self.heights)
        (th, yc, mu, offs), self.nominal = probe_inputs(member, self.mu_c, n, self.verify)
        tf, _, jam, _ = replay(member, list(self.heights), [0.0] * n, th, yc, mu, offs, self.pin_radius,
                               self.model, **self.kernel)
        return tf, jam != ""


def _probe(part: Part, heights, st: FamilyCheckSettings) -> ShapeProbe:
    """The shape probe of the plan of pins at ``heights`` under ``st``'s trials and mechanics."""
    return ShapeProbe(part, heights, st.mu_c, st.verify, st.search.pin_radius, st.search.model,
                      st.search.kernel_settings)


class ShapeSpace:
    """Vertex offsets within ``tol`` mm of the drawing: ``x`` holds 2n numbers,
    each vertex's offset in units of ``tol``, feasible inside the unit disc."""

    kind = "shape"

    def __init__(self, part: Part, tol: float):
        if not (np.isfinite(tol) and tol > 0):
            raise PinfeedError(f"a shape tolerance must be a length > 0 mm, got {tol!r}")
        self.part, self.tol = part, float(tol)
        self.n = len(part.vertices)
        self.size = 2 * self.n

    def violation(self, x) -> float:
        """0 inside every vertex's disc, else how far outside (in units of tol)."""
        r = np.hypot(*np.asarray(x, float).reshape(-1, 2).T)
        return float(np.maximum(0.0, r - 1.0).sum())

    def member(self, x, label: str = "") -> Part | None:
        """The member part of offsets ``x``."""
        return member_part(self.part, self.tol * np.asarray(x, float).reshape(-1, 2))

    def params(self, x) -> dict:
        """The offsets of ``x`` in mm."""
        return {"vertex_offsets_mm": np.round(self.tol * np.asarray(x, float).reshape(-1, 2), 4).tolist(),
                "tolerance_mm": self.tol}

    def corners(self) -> list[np.ndarray]:
        """All vertices pushed out, all pulled in (along their bisectors), and
        each vertex alone pushed out and in."""
        verts = np.asarray(self.part.vertices, float)
        bis = []
        for i in range(self.n):
            u1, u2 = verts[i - 1] - verts[i], verts[(i + 1) % self.n] - verts[i]
            b = -(u1 / np.linalg.norm(u1) + u2 / np.linalg.norm(u2))
            bis.append(b / (np.linalg.norm(b) or 1.0))
        bis = np.array(bis)
        out = [bis.ravel(), -bis.ravel()]
        for i in range(self.n):
            for s in (1.0, -1.0):
                x = np.zeros((self.n, 2))
                x[i] = s * bis[i]
                out.append(x.ravel())
        return out

    def random(self, rng, n: int) -> list[np.ndarray]:
        """``n`` members uniform in the vertices' discs."""
        ang = rng.uniform(0.0, 2 * np.pi, (n, self.n))
        r = np.sqrt(rng.uniform(0.0, 1.0, (n, self.n)))
        return list(np.stack([r * np.cos(ang), r * np.sin(ang)], axis=-1).reshape(n, -1))

    def describe(self) -> str:
        """The space in words."""
        return f"outline vertices within {self.tol:g} mm of the drawing"


def shape_worst_member(part: Part, heights, arc: tuple, tol: float, st, budget: int | None = None,
                       seed: int = 0) -> WorstMember:
    """The member within ``tol`` mm whose probe finals lie farthest outside
    ``arc`` (``(start, width)`` deg) for the plan of pins at ``heights``;
    ``st`` is a :class:`~pipeline.planning.family.worst_member.FamilyCheckSettings`."""
    probe = _probe(part, heights, st)
    space = MemberSpace(f"shape:tol:{tol:g}", [ShapeSpace(part, tol)], [])
    worst = search_worst_member(probe, space, arc, 360.0 / part.symmetry_order(), budget or st.budget, seed)
    worst.finals, _ = probe.finals(worst.support)  # the rows of the worst member's own resting states
    worst.nominal = probe.nominal
    return worst


def shape_certificate(part: Part, heights, arc: tuple, tol: float, st, members: int = FRESH_MEMBERS,
                      confidence: float = 0.95) -> dict:
    """The plan's claim for the shape family at ``tol`` mm: the worst member
    found and a fresh seeded sample (stream ``[verify.seed, 36]``), as a
    JSON-ready dict with ``holds`` and the ``claim`` (epsilon, beta)."""
    worst = shape_worst_member(part, heights, arc, tol, st)
    probe = _probe(part, heights, st)
    space = ShapeSpace(part, tol)
    rng = np.random.default_rng([int(st.seed), 36])
    period = 360.0 / part.symmetry_order()
    leaving = 0
    for x in space.random(rng, members):
        tf, jam = probe.finals(space.member(x))
        leaving += bool(np.any(jam) or np.any(outside(tf[~jam], arc, period) > 0.0))
    claim = scenario_claim(leaving, members, confidence)
    return {"family": f"shape:tol:{tol:g}", "tolerance_mm": tol, "space": space.describe(),
            "set_deg": stored_set(arc, period),
            "holds": bool(not worst.breaks and leaving == 0),
            "worst_member": _worst_dict(worst), "claim": claim}


def _worst_dict(worst: WorstMember) -> dict:
    """The worst member for a JSON file: its vertex offsets, how far outside, its nominal finals."""
    finals = np.asarray(worst.finals, float)
    return {"member": worst.params, "outside_deg": round(worst.objective, 4), "breaks": worst.breaks,
            "nominal_finals_deg": np.round(finals[worst.nominal[worst.nominal < finals.size]], 3).tolist(),
            "evaluations": worst.evaluations, "found_by": worst.source}


def certified_radius(part: Part, heights, arc: tuple, tol: float, st, steps: int = STEPS,
                     members: int = FRESH_MEMBERS) -> dict:
    """The shape certificate at ``tol`` when it holds; else the largest
    tolerance in ``(0, tol)`` found by bisection at which it holds (assuming
    holding is monotone in the tolerance), with its certificate; ``radius_mm``
    is None when none of the tolerances tried holds."""
    cert = shape_certificate(part, heights, arc, tol, st, members)
    if cert["holds"]:
        return {"radius_mm": tol, "requested_mm": tol, "certificate": cert}
    lo, hi, best = 0.0, tol, None
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        got = shape_certificate(part, heights, arc, mid, st, members)
        if got["holds"]:
            lo, best = mid, got
        else:
            hi = mid
    return {"radius_mm": None if best is None else round(lo, 4), "requested_mm": tol,
            "certificate": best, "at_requested": cert}


def shape_line(result: dict) -> str:
    """One line for people."""
    req = result["requested_mm"]
    if result.get("note"):
        return f"shape tolerance {req:g} mm: {result['note']}"
    cert = result["certificate"]
    if result["radius_mm"] is None:
        return (f"shape tolerance {req:g} mm: the plan does not hold, nor at any smaller tolerance tried "
                f"(down to {req / 2 ** STEPS:.3g} mm)")
    claim = cert["claim"]
    head = (f"shape tolerance {req:g} mm: the plan holds" if result["radius_mm"] == req else
            f"shape tolerance {req:g} mm: the plan does NOT hold; its certified radius is "
            f"{result['radius_mm']:g} mm")
    return (f"{head} (worst member found {cert['worst_member']['outside_deg']:+.2f} deg from the set's edge; "
            f"{claim['violations']} of {claim['members']} fresh members outside: epsilon "
            f"{100 * claim['epsilon']:.2f} % at beta {claim['beta']:g}; the worst-member search is a heuristic)")


def attach_shape_tolerance(result: PlanFile, part: Part, settings, tol: float, progress=None) -> PlanFile:
    """``result`` (a plan file's record) with ``shape_tolerance``
    (:func:`certified_radius`) in every tight entry whose recommended plan
    orients the part (fixed pins: the shape probe replays fixed pins), at
    that entry's friction; entries without such a plan get a one-line
    ``note``."""
    if not (np.isfinite(tol) and tol > 0):
        raise PinfeedError(f"--shape-tolerance must be a length > 0 mm, got {tol:g}")
    if not result.tight:
        return result
    return replace(result, tight=tuple(_with_shape_tolerance(entry, part, settings, tol, progress)
                                       for entry in result.tight))


def _with_shape_tolerance(entry: TightEntry, part: Part, settings, tol: float, progress=None) -> TightEntry:
    """One tight entry with its ``shape_tolerance`` (see :func:`attach_shape_tolerance`)."""
    rec = entry.recommended
    verdict = rec.verification.orientation if rec is not None else None
    if not (verdict and verdict["orients"]) or any(rec.pin_speeds or ()):
        return replace(entry, shape_tolerance={"requested_mm": tol, "radius_mm": None, "certificate": None,
                                               "note": "no fixed-pin plan orients the part: nothing to certify"})
    st = FamilyCheckSettings.from_settings(settings.at(entry.mu_c))
    arc = claimed_arc(verdict, st.claims.tolerance_deg)
    if progress:
        progress(f"shape tolerance {tol:g} mm for {' '.join(rec.pins)} at mu_c {entry.friction}")
    return replace(entry, shape_tolerance=certified_radius(part, list(rec.pin_heights_mm), arc, tol, st))
