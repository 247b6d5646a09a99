"""A feeder you can build: pin stations, part pitch, belt width, throughput.

The design of the layout; :mod:`pipeline.present.layout` draws it.

Plain inputs (a part, the plan's pin labels and heights, the initial resting
states, the friction) and replayed trials with trajectories:

- **Trials.** The verification's perturbation box (``verify.perturbed_batch``
  and, if asked, ``verify.corner_inputs``: orientation and friction normal,
  truncated at 2 sigma, or a friction range drawn uniformly; centroid height
  and each pin's position uniform) replayed past the pins with
  ``simulate.rollout(..., trajectory=True)``: the dynamic model at the belt
  speed, or the plan's quasi-static model when no belt speed is given. Trials
  that jam are left out of the layout and counted (a jammed part stops the
  line whatever the spacing).
- **Stations.** World frame of the spec: x downstream, the fence at y = 0.
  The first pin stands at x = 0. In each trial the part's pose during a
  passage (from first touch until it rests on the belt again: the dynamic
  model integrates the slide after separation; the quasi-static part rests at
  once) is known relative to that pin's station. Pin j stands so far
  downstream of pin k that its disc, at the trial's perturbed height, misses
  every one of those poses (:func:`~pipeline.planning.feeder.lanes.pin_reach`,
  exact for polygons), plus ``station_margin_mm``: the part has left pin k and come to
  rest before pin j touches it. Every earlier pin k bounds pin j (a part that
  misses a pin rides on from the pin before).
- **Pitch.** Every trial becomes a lane on one clock, the belt travel B
  (``lanes.build_lane``). The next part runs the same course ``p`` later. For
  every B and every horizontal slab of the belt (``slab_mm`` high) the
  x-range that any trial's outline covers in that slab is known exactly
  (edges clipped to the slab); two parts cannot touch if in every slab the
  trailing part's range ends before the leading part's begins. This holds
  for every pair of trials at once (the ranges are envelopes over the
  trials), so it is conservative. The touch-free spacing is the smallest
  ``p`` on the ``time_step_mm`` grid from which every larger spacing is clear
  too; a pin must also never touch two parts at once: ``p`` exceeds, for each
  pin, the latest end of a contact minus the earliest start (contacts read
  from the force history). The pitch is the larger of the two plus
  ``pitch_margin_mm``.
- **Belt width.** From the fence at y = 0 to the highest point any outline
  sweeps, plus ``belt_margin_mm``; if a part sweeps below y = 0 downstream of
  the fence, the lower belt edge moves down to that point minus the margin.
- **Throughput.** ``60 x belt speed / pitch`` parts per minute.

Plans with moving pins are refused: their pin's path depends on each part's
arrival, which a fixed drawing cannot show.
"""
from __future__ import annotations

import math

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part
from pipeline.planning.core.settings import ClaimSettings, LayoutSettings, VerifySettings
from pipeline.planning.feeder.lanes import (Lane, Trial, outlines, passage_poses, pin_reach, rotated, run_trials,
                                            trial_lanes)

def place_stations(part: Part, trials: list[Trial], pin_radius: float, margin: float):
    """Stations of the pins along the belt (the first at x = 0; see the module notes).

    Returns ``(stations, bounds)``: ``bounds[j]`` says what placed pin j
    (``{"by_pin", "state", "reach_mm"}``, or the pins' diameters)."""
    n = len(trials[0].heights)
    poses = [[passage_poses(part, th, y, ds, t.heights[k], pin_radius)
              for k, (th, y, ds) in enumerate(t.steps)] for t in trials]
    stations, bounds = [0.0], [{"first pin": "x = 0"}]
    for j in range(1, n):
        need = stations[j - 1] + 2.0 * pin_radius + margin
        bound = {"by": "the pins' diameters plus the margin"}
        for t, trial in enumerate(trials):
            for k, pose in enumerate(poses[t][:j]):
                if pose is None:
                    continue
                reach = float(pin_reach(outlines(part.vertices, *pose), trial.heights[j],
                                        pin_radius).max())
                if math.isfinite(reach) and stations[k] + reach + margin > need:
                    need = stations[k] + reach + margin
                    bound = {"by_pin": k + 1, "state": trial.state, "reach_mm": reach}
        stations.append(need)
        bounds.append(bound)
    return stations, bounds


def contact_windows(trials: list[Trial], lanes: list[Lane], n_pins: int):
    """Per pin, the belt travel B of every contact: ``(starts, ends)`` lists, the
    end being the last sample with a force on the pin."""
    starts, ends = [[] for _ in range(n_pins)], [[] for _ in range(n_pins)]
    for trial, lane in zip(trials, lanes):
        for k, b0 in lane.contacts:
            ds = trial.steps[k][2]
            force = np.hypot(np.asarray(ds.force_x, float), np.asarray(ds.force_y, float))
            s = np.asarray(ds.force_s, float)
            last = float(s[force > 0].max()) if np.any(force > 0) else float(ds.traj_s[-1])
            starts[k].append(b0)
            ends[k].append(b0 + last)
    return starts, ends


def slab_extents(polygons, y0: float, dy: float, n_slabs: int):
    """For each outline and each slab ``[y0 + i dy, y0 + (i + 1) dy)``: the least and
    greatest x of the outline within the slab (``inf``/``-inf`` where it has none).

    Exact for polygons: the extremes lie at vertices inside the slab or where
    edges cross its bounds. Returns two arrays ``(n_outlines, n_slabs)``."""
    p = np.asarray(polygons, float)
    n_out = p.shape[0]
    lo = np.full((n_out, n_slabs), np.inf)
    hi = np.full((n_out, n_slabs), -np.inf)
    slab = np.floor((p[..., 1] - y0) / dy).astype(np.int64)
    ok = (slab >= 0) & (slab < n_slabs)
    rows = np.broadcast_to(np.arange(n_out)[:, None], slab.shape)
    np.minimum.at(lo, (rows[ok], slab[ok]), p[..., 0][ok])
    np.maximum.at(hi, (rows[ok], slab[ok]), p[..., 0][ok])
    a, b = p, np.roll(p, -1, axis=1)
    bounds = y0 + dy * np.arange(n_slabs + 1)
    ya, yb = a[..., 1][..., None], b[..., 1][..., None]
    flat = ya == yb
    t = (bounds - ya) / np.where(flat, 1.0, yb - ya)
    crossing = ~flat & (t >= 0.0) & (t <= 1.0)
    x = a[..., 0][..., None] + t * (b[..., 0] - a[..., 0])[..., None]
    x_lo = np.where(crossing, x, np.inf).min(axis=1)  # (n_out, n_slabs + 1)
    x_hi = np.where(crossing, x, -np.inf).max(axis=1)
    lo = np.minimum(lo, np.minimum(x_lo[:, :-1], x_lo[:, 1:]))
    hi = np.maximum(hi, np.maximum(x_hi[:, :-1], x_hi[:, 1:]))
    return lo, hi


def touch_free_spacing(part: Part, lanes: list[Lane], clock, slab_mm: float, y_range):
    """The smallest spacing on the clock's grid (a multiple of its step) from which
    on two consecutive parts never touch, for every pair of lanes (see the module
    notes); also the swept y extremes. Returns ``(spacing, y_min, y_max)``."""
    step = float(clock[1] - clock[0])
    y0 = y_range[0] - slab_mm
    n_slabs = int(math.ceil((y_range[1] - y_range[0]) / slab_mm)) + 2
    env_lo = np.full((clock.size, n_slabs), np.inf)
    env_hi = np.full((clock.size, n_slabs), -np.inf)
    y_min, y_max = np.inf, -np.inf
    for lane in lanes:
        polys = outlines(part.vertices, *lane.poses(clock))
        y_min, y_max = min(y_min, float(polys[..., 1].min())), max(y_max, float(polys[..., 1].max()))
        lo, hi = slab_extents(polys, y0, slab_mm, n_slabs)
        np.minimum(env_lo, lo, out=env_lo)
        np.maximum(env_hi, hi, out=env_hi)
    shifts = np.arange(1, clock.size)
    clear = np.array([not np.any(env_hi[:-m] >= env_lo[m:]) for m in shifts])
    if not clear[-1]:
        raise PinfeedError("no spacing up to the whole course keeps the parts apart; "
                           "check the plan's trials")
    first = shifts[np.flatnonzero(~clear)[-1] + 1] if np.any(~clear) else shifts[0]
    return float(first * step), y_min, y_max


def layout_plan(part: Part, labels, heights, states: dict, mu_c, pin_radius: float,
                model: str = "minpower", belt_speed: float | None = None, mu_s: float = 0.5,
                settings: LayoutSettings | None = None, verify: VerifySettings | None = None,
                claims: ClaimSettings | None = None) -> dict:
    """Stations, pitch, belt width and throughput of one plan of fixed pins.

    Parameters
    ----------
    part : the part (mm).
    labels, heights : the plan's pins in passage order (heights in mm).
    states : initial resting states, label -> ``(theta_deg, y_c_mm)``.
    mu_c : contact friction, a value or a range ``(lo, hi)``.
    pin_radius : mm.
    model : the quasi-static model used when ``belt_speed`` is None.
    belt_speed : mm/s: trials with the dynamic model (and belt friction
        ``mu_s``); None: the quasi-static ``model``, and no throughput.
    settings : margins, trials, grid steps (``None``: the schema's ``layout`` section).
    verify, claims : the trials draw from ``verify``'s perturbation sizes (``None``: the
        schema's); the method records both (:func:`perturbation_record`).

    Returns
    -------
    dict with ``stations`` (rows ``label``, ``x_mm``, ``y_mm``, ``radius_mm``),
    ``fence_y_mm``, ``fence_end_x_mm``, ``belt_width_mm``, ``belt_y_mm``,
    ``pitch_mm``, ``belt_speed_mm_s``, ``throughput_per_min`` (None without a
    belt speed), ``drawing`` (outlines at entry and exit) and ``method`` (how
    each number was obtained).
    """
    layout = settings or LayoutSettings()
    if len(labels) != len(heights) or not len(heights):
        raise PinfeedError("give one label per pin height, and at least one pin")
    if not states:
        raise PinfeedError("give at least one initial state")
    kw = dict(model=model, belt_speed=belt_speed, mu_s=mu_s, perturb=None if verify is None else verify.perturbation)
    trials, good, nominal = _layout_trials(part, heights, states, mu_c, pin_radius, layout, kw)
    margin = layout.station_margin_mm
    stations, bounds = place_stations(part, good, pin_radius, margin)
    entry = _entry_distance(part, good + nominal, pin_radius, margin)
    lanes = trial_lanes(part, good, stations, pin_radius, entry)
    nominal_lanes = trial_lanes(part, nominal, stations, pin_radius, entry)
    spacing, y_min, y_max, busy, pitch = _pitch(part, good, lanes, len(heights), entry, layout)
    belt_top = y_max + layout.belt_margin_mm
    belt_bottom = min(0.0, y_min - layout.belt_margin_mm) if y_min < 0 else 0.0
    fence_end = _fence_end(part, lanes, pin_radius)
    throughput = 60.0 * belt_speed / pitch if belt_speed else None
    drawing = entry_exit_outlines(part, states, nominal_lanes, stations, pitch, entry, pin_radius, margin)
    dynamic = belt_speed is not None
    return {
        "part": part.name, "part_id": part.id, "pins": list(labels),
        "stations": [{"label": str(lbl), "x_mm": float(x), "y_mm": float(h), "radius_mm": float(pin_radius)}
                     for lbl, x, h in zip(labels, stations, heights)],
        "fence_y_mm": 0.0, "fence_end_x_mm": float(fence_end),
        "belt_width_mm": float(belt_top - belt_bottom), "belt_y_mm": [float(belt_bottom), float(belt_top)],
        "pitch_mm": float(pitch), "belt_speed_mm_s": None if belt_speed is None else float(belt_speed),
        "mu_s": float(mu_s) if dynamic else None,
        "throughput_per_min": throughput, "drawing": drawing,
        "method": _layout_method(layout, "dynamic" if dynamic else model, trials, good,
                                 perturbation_record(verify, claims), bounds, spacing, busy, y_min, y_max, dynamic),
    }


def perturbation_record(verify: VerifySettings | None, claims: ClaimSettings | None) -> dict:
    """The verification's settings as a layout's method records them: the
    trials' settings (:meth:`~pipeline.planning.core.settings.VerifySettings.as_dict`),
    then the claim's ``required`` share, ``confidence`` and ``rule``; ``{}``
    without ``verify``."""
    if verify is None:
        return {}
    claim = {} if claims is None else {"required": claims.required, "confidence": claims.confidence,
                                       "rule": claims.rule}
    return {**verify.as_dict(), **claim}


def _layout_trials(part, heights, states, mu_c, pin_radius, layout: LayoutSettings, kw):
    """``(trials, good, nominal)``: the perturbed trials, those that did not
    jam (none left raises :class:`PinfeedError`) and the nominal replays."""
    trials = run_trials(part, heights, states, mu_c, pin_radius, trials=layout.trials,
                        corners=layout.corners, seed=layout.seed, **kw)
    good = [t for t in trials if not t.jam]
    if not good:
        raise PinfeedError(f"every layout trial jammed ({trials[0].jam}); this plan cannot be laid out")
    nominal = run_trials(part, heights, states, mu_c, pin_radius, nominal=True, **kw)
    return trials, good, nominal


def _entry_distance(part, trials, pin_radius, margin) -> float:
    """Entry (mm upstream of the first pin): every centroid starts far enough
    upstream that nothing touches yet, plus ``margin``."""
    first_touch = [float(pin_reach(rotated(part.vertices, t.theta), t.heights[0] - t.y_c,
                                   pin_radius)) for t in trials]
    return max([r for r in first_touch if math.isfinite(r)] + [part.a + pin_radius]) + margin


def _pitch(part, good, lanes, n_pins, entry, layout: LayoutSettings):
    """``(spacing, y_min, y_max, busy, pitch)`` in mm: the touch-free spacing of
    two consecutive parts, the swept y range, each pin's contact span and the
    pitch (the larger of spacing and busy span on the time grid, plus margin)."""
    step = layout.time_step_mm
    course = max(float(lane.B[-1]) for lane in lanes) + entry + 4.0 * part.a
    clock = step * np.arange(-int(math.ceil(course / step)), int(math.ceil(2 * course / step)) + 1)
    y_lanes = np.concatenate([lane.y for lane in lanes])
    spacing, y_min, y_max = touch_free_spacing(
        part, lanes, clock, layout.slab_mm,
        (float(y_lanes.min()) - part.a, float(y_lanes.max()) + part.a))
    starts, ends = contact_windows(good, lanes, n_pins)
    busy = [max(e) - min(s) if s else 0.0 for s, e in zip(starts, ends)]
    pin_spacing = step * (math.floor(max(busy) / step) + 1)
    pitch = max(spacing, pin_spacing) + layout.pitch_margin_mm
    return spacing, y_min, y_max, busy, pitch


def _layout_method(layout: LayoutSettings, model, trials, good, perturbation: dict, bounds, spacing, busy,
                   y_min, y_max, dynamic) -> dict:
    """The ``method`` entry of a layout: how each number was obtained."""
    return {
        "model": model,
        "trials": {"per_state": int(layout.trials), "corners": bool(layout.corners),
                   "replayed": len(trials), "jammed_left_out": len(trials) - len(good),
                   "jams": sorted({t.jam for t in trials if t.jam}), "seed": int(layout.seed),
                   "perturbation": perturbation},
        "margins_mm": {k: float(v) for k, v in layout.margins.items()},
        "stations": "first pin at x = 0; each next pin where its disc misses every pose of "
                    "every trial from first touch at any earlier pin until the part rests, "
                    "plus the station margin",
        "station_bounds": bounds,
        "pitch": {"touch_free_spacing_mm": spacing, "pin_busy_mm": [float(b) for b in busy],
                  "time_step_mm": layout.time_step_mm, "slab_mm": layout.slab_mm,
                  "rule": "max(touch-free spacing of two consecutive parts over every pair "
                          "of trials, the longest span of any pin's contacts) + pitch margin"},
        "belt_width": "fence y = 0 (or the lowest swept point minus the margin) to the "
                      "highest swept point plus the belt margin",
        "swept_y_mm": [y_min, y_max],
        "throughput": "60 x belt speed / pitch" if dynamic else
                      "none: the quasi-static model has no belt speed",
    }


def _fence_end(part: Part, lanes: list[Lane], pin_radius: float) -> float:
    """Where the fence stops: at the rear of the most upstream outline at the
    moment the first pin touches it, so the fence never stands in the way of
    a part that a pin pushes towards it."""
    rears = [float(outlines(part.vertices, *lane.poses(np.array([b0])))[..., 0].min())
             for lane in lanes for k, b0 in lane.contacts[:1] if k == 0]
    return min(rears + [-pin_radius])


def entry_exit_outlines(part, states, nominal_lanes, stations, pitch, entry, pin_radius, margin) -> dict:
    """Outlines to draw: each resting state at the entry (one pitch apart,
    nearest the pins first) and each state's nominal exit pose, clear of the
    last pin; each entry's ``holes`` (a part with holes only) are its holes at
    the same pose."""
    entry_parts, exit_parts = [], []

    def shape(x, y, theta):  # the outline, and the holes of a part with holes, at a pose
        out = {"outline": outlines(part.vertices, [x], [y], [theta])[0].tolist()}
        if part.has_holes:
            out["holes"] = [outlines(h, [x], [y], [theta])[0].tolist() for h in part.holes]
        return out

    for k, ((label, (theta, y_c)), lane) in enumerate(zip(states.items(), nominal_lanes)):
        x = -entry - k * pitch
        entry_parts.append({"state": label, "x_mm": x, "y_mm": float(y_c), "theta_deg": float(theta) % 360,
                            **shape(x, y_c, theta)})
        x_end, y_end, th_end = (float(v) for v in (lane.x[-1], lane.y[-1], lane.theta[-1]))
        poly = rotated(part.vertices, th_end)
        clear_x = stations[-1] + pin_radius + margin - float(poly[:, 0].min())
        x_exit = max(x_end, clear_x) + k * pitch
        exit_parts.append({"state": label, "x_mm": x_exit, "y_mm": y_end, "theta_deg": th_end % 360,
                           "outcome": lane.outcome, **shape(x_exit, y_end, th_end)})
    return {"entry_parts": entry_parts, "exit_parts": exit_parts}
