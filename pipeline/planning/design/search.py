"""Design for feeding: the smallest outline change that lets fixed pins orient a part.

:func:`design_part` first plans the part as it is, with the planner of
``pinfeed plan`` (:func:`~pipeline.planning.plans.plan.plan_tight_all`,
fixed pins only, the same settings and seeds). If no fixed-pin plan orients
it, it makes every change of the grid (:mod:`.edits`: chamfers, notches,
tabs) that the user's limits allow, sorts them by the area they remove or
add relative to the part's area, smallest first, and plans each changed
part in that order. It stops at the first whose recommended plan orients
the part on the held-out trials (the plan file's verdict), at every
friction planned. The search is as reproducible as the planner: the same
outline, grid and settings try the same changes in the same order and get
the same verdicts.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from pipeline.parts.part import Part
from pipeline.planning.claims.orient import describe_claim
from pipeline.planning.core.settings import DesignSettings, PlannerSettings
from pipeline.planning.design.edits import (KINDS, ChangeRefused, OutlineChange, apply_change,
                                            candidate_changes, ccw_outline, changed_area, edge_lengths)
from pipeline.planning.plans.plan import plan_tight_all
from pipeline.progress import reporting


@dataclass(frozen=True)
class Candidate:
    """A change that the limits allow, with its outline and area share."""

    change: OutlineChange
    vertices: np.ndarray
    area_mm2: float
    share: float


def allowed_candidates(xy: np.ndarray, holes, part: Part, design: DesignSettings) -> tuple[list, list]:
    """``(candidates, refused)``: the grid's changes within the limits, smallest
    area share first, and each refused change with its reason."""
    limits = design.limits
    found, refused = [], []
    for change in candidate_changes(xy, part.a, design.grid):
        area = changed_area(xy, change)
        share = area / part.area
        if share > limits.max_change:
            refused.append({**change.to_dict(), "share": round(share, 6),
                            "why": f"changes {share:.2%} of the area, over --max-change {limits.max_change:.2%}"})
            continue
        try:
            new = apply_change(xy, change, holes, limits.keep_edges, limits.min_wall_mm)
        except ChangeRefused as exc:
            refused.append({**change.to_dict(), "share": round(share, 6), "why": str(exc)})
            continue
        found.append(Candidate(change, new, area, share))
    found.sort(key=lambda c: (round(c.share, 12), KINDS.index(c.change.kind), c.change.index,
                              c.change.size, c.change.at))
    return found, refused


def verdict_of(entries: list) -> dict:
    """What the planner's entries (one :class:`~pipeline.planning.core.types.TightEntry`
    per friction) say: ``orients`` at every friction, the recommended pins and
    the held-out verdict at the first."""
    first = entries[0]
    rec = first.recommended
    orients = all(e.orients for e in entries)
    if first.needs_no_pin:
        text = "no pin is needed"
    elif rec is None:
        text = f"no plan: {first.warning}"
    else:
        held = describe_claim(rec.verification.orientation)
        text = f"{' '.join(rec.pins)}: {held}" if orients else f"no plan; best {' '.join(rec.pins)}: {held}"
    return {"orients": bool(orients), "pins": list(rec.pins) if rec else [], "summary": text}


def plan_entries(part: Part, settings: PlannerSettings, catalog_root) -> list:
    """The planner's entries for ``part`` (fixed pins only), its own progress lines kept quiet."""
    with reporting(None):
        return plan_tight_all(part, settings, catalog_root)


def stored_entry(entry) -> dict:
    """A planner entry (a :class:`~pipeline.planning.core.types.TightEntry`) as
    the design file keeps it: the plan and its verdict, without the run's
    timings and rollout counts (which differ between runs)."""
    keep = ("mu_c", "friction", "mechanics", "depth", "tolerance_deg", "required", "orients", "needs_no_pin",
            "recommended", "warning", "initial_states", "symmetry_order", "pins_used")
    stored = entry.to_dict()
    return {k: stored.get(k) for k in keep}


def design_part(outline, holes, name: str, settings: PlannerSettings, design: DesignSettings, catalog_root,
                progress=None) -> dict:
    """Search the smallest change of ``outline`` (drawing frame, either winding;
    ``holes`` kept) that lets fixed pins orient the part named ``name``.

    Returns a JSON-ready dict: ``original`` (its outline, counter-clockwise,
    and verdict), ``outcome`` (``"already orients"``, ``"changed"`` or
    ``"no change helps"``), ``tried`` (each planned change with its area share
    and verdict, in order), ``refused`` (changes the limits rule out, with the
    reason), ``chosen`` (the change, its outline and the planner's entries) or
    ``None``, and the grid and limits. ``progress`` gets one line per change tried.
    """
    settings = settings.without_moving_pins()
    if design.depth is not None:
        settings = _with_depth(settings, design.depth)
    xy = ccw_outline(outline)
    design.check(len(xy))
    original = Part.from_vertices(xy, name=name, holes=holes)
    say = progress or (lambda line: None)
    t0 = time.perf_counter()
    entries = plan_entries(original, settings, catalog_root)
    first = verdict_of(entries)
    say(f"original {name}: {first['summary']} ({time.perf_counter() - t0:.0f} s)")
    result = _result_head(xy, holes, original, settings, design, first)
    if first["orients"]:
        result.update(outcome="already orients", original_plan=[stored_entry(e) for e in entries])
        return result
    candidates, result["refused"] = allowed_candidates(xy, holes, original, design)
    say(f"{len(candidates)} changes within the limits ({len(result['refused'])} refused), "
        f"smallest area share first")
    for k, cand in enumerate(candidates, start=1):
        record, entries = _try(cand, holes, name, settings, catalog_root)
        seconds = record.pop("seconds")  # said, not stored: it differs from run to run
        say(f"[{k}/{len(candidates)}] {cand.change.describe()} ({cand.share:.2%} of the area): "
            f"{record['summary']} ({seconds:.0f} s)")
        result["tried"].append(record)
        if record["orients"]:
            result.update(outcome="changed", chosen={
                **{k: v for k, v in record.items() if k not in ("orients", "pins", "summary")},
                "vertices": cand.vertices.round(9).tolist(), "plan": [stored_entry(e) for e in entries]})
            return result
    result["outcome"] = "no change helps"
    return result


def _try(cand: Candidate, holes, name: str, settings: PlannerSettings, catalog_root) -> tuple[dict, list]:
    """Plan the changed part of ``cand``: its record (change, area, share,
    verdict, seconds) and the planner's entries."""
    t0 = time.perf_counter()
    entries = plan_entries(Part.from_vertices(cand.vertices, name=name, holes=holes), settings, catalog_root)
    record = {**cand.change.to_dict(), "description": cand.change.describe(),
              "area_mm2": round(cand.area_mm2, 6), "share": round(cand.share, 8), **verdict_of(entries),
              "seconds": time.perf_counter() - t0}
    return record, entries


def _with_depth(settings: PlannerSettings, depth: int) -> PlannerSettings:
    """``settings`` searching up to ``depth`` fixed pins."""
    import dataclasses
    return dataclasses.replace(settings, search=dataclasses.replace(settings.search, depth=int(depth)))


def _result_head(xy: np.ndarray, part_holes, part: Part, settings: PlannerSettings, design: DesignSettings,
                 verdict: dict) -> dict:
    """The design result before the search: the original, the grid, the limits."""
    grid, limits = design.grid, design.limits
    return {
        "part": part.to_dict(),
        "original": {"vertices": xy.round(9).tolist(), "holes": [np.asarray(h, dtype=float).round(9).tolist()
                                                                  for h in part_holes],
                     "area_mm2": part.area, "a_mm": part.a,
                     "edge_lengths_mm": edge_lengths(xy).round(6).tolist(), **verdict},
        "planner": {"depth": settings.search.depth, "friction": settings.friction.label,
                    "tolerance_deg": settings.claims.tolerance_deg, "model": settings.search.model,
                    "fixed_pins_only": True},
        "grid": {"kinds": list(grid.kinds), "chamfer": list(grid.chamfer), "notch": [list(p) for p in grid.notch],
                 "tab": [list(p) for p in grid.tab], "positions": list(grid.positions), "unit": "a"},
        "limits": {"keep_edges": list(limits.keep_edges), "min_wall_mm": limits.min_wall_mm,
                   "max_change": limits.max_change},
        "tried": [], "refused": [], "chosen": None,
    }
