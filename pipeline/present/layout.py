"""A feeder you can build: pin stations, part pitch, belt width, throughput.

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
  every one of those poses (:func:`pipeline.present.lanes.pin_reach`, exact for
  polygons), plus ``station_margin_mm``: the part has left pin k and come to
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
from pipeline.present.lanes import Lane, Trial, outlines, passage_poses, pin_reach, rotated, run_trials, trial_lanes

LAYOUT_DEFAULTS = {
    "trials": 20,
    "corners": False,
    "station_margin_mm": 5.0,
    "pitch_margin_mm": 5.0,
    "belt_margin_mm": 5.0,
    "speed_fraction": 0.8,
    "speed_trials": 20,
    "mu_s": 0.5,
    "time_step_mm": 0.5,
    "slab_mm": 0.5,
    "seed": 1,
}
MARGIN_KEYS = ("station_margin_mm", "pitch_margin_mm", "belt_margin_mm")


def check_layout_settings(settings: dict | None) -> dict:
    """``settings`` over :data:`LAYOUT_DEFAULTS`, checked: a one-line
    :class:`PinfeedError` for a negative margin or a bad count or step."""
    cfg = dict(LAYOUT_DEFAULTS, **(settings or {}))

    def number(key):
        v = cfg[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise PinfeedError(f"layout setting {key} must be a finite number, got {v!r}")
        return float(v)

    for key in MARGIN_KEYS:
        if number(key) < 0:
            raise PinfeedError(f"layout margin {key} must be a length >= 0 mm, got {cfg[key]!r}")
    for key in ("time_step_mm", "slab_mm"):
        if number(key) <= 0:
            raise PinfeedError(f"layout setting {key} must be > 0 mm, got {cfg[key]!r}")
    if not 0 < number("speed_fraction") <= 1:
        raise PinfeedError(f"layout speed_fraction must be in (0, 1], got {cfg['speed_fraction']!r}")
    for key in ("trials", "speed_trials"):
        if isinstance(cfg[key], bool) or not isinstance(cfg[key], int) or cfg[key] < 1:
            raise PinfeedError(f"layout {key} must be a whole number >= 1, got {cfg[key]!r}")
    return cfg


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
                settings: dict | None = None, perturb: dict | None = None) -> dict:
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
    settings : :data:`LAYOUT_DEFAULTS` keys (margins, trials, grid steps).
    perturb : the verification's perturbation sizes.

    Returns
    -------
    dict with ``stations`` (rows ``label``, ``x_mm``, ``y_mm``, ``radius_mm``),
    ``fence_y_mm``, ``fence_end_x_mm``, ``belt_width_mm``, ``belt_y_mm``,
    ``pitch_mm``, ``belt_speed_mm_s``, ``throughput_per_min`` (None without a
    belt speed), ``drawing`` (outlines at entry and exit) and ``method`` (how
    each number was obtained).
    """
    cfg = check_layout_settings(settings)
    if len(labels) != len(heights) or not len(heights):
        raise PinfeedError("give one label per pin height, and at least one pin")
    if not states:
        raise PinfeedError("give at least one initial state")
    kw = dict(model=model, belt_speed=belt_speed, mu_s=mu_s, perturb=perturb)
    trials, good, nominal = _layout_trials(part, heights, states, mu_c, pin_radius, cfg, kw)
    margin = cfg["station_margin_mm"]
    stations, bounds = place_stations(part, good, pin_radius, margin)
    entry = _entry_distance(part, good + nominal, pin_radius, margin)
    lanes = trial_lanes(part, good, stations, pin_radius, entry)
    nominal_lanes = trial_lanes(part, nominal, stations, pin_radius, entry)
    spacing, y_min, y_max, busy, pitch = _pitch(part, good, lanes, len(heights), entry, cfg)
    belt_top = y_max + cfg["belt_margin_mm"]
    belt_bottom = min(0.0, y_min - cfg["belt_margin_mm"]) if y_min < 0 else 0.0
    fence_end = _fence_end(part, lanes, pin_radius)
    throughput = 60.0 * belt_speed / pitch if belt_speed else None
    drawing = _drawing(part, states, nominal_lanes, stations, pitch, entry, pin_radius, margin)
    dynamic = belt_speed is not None
    return {
        "part": part.name, "part_id": part.id,
        "pins": list(labels),
        "stations": [{"label": str(lbl), "x_mm": float(x), "y_mm": float(h), "radius_mm": float(pin_radius)}
                     for lbl, x, h in zip(labels, stations, heights)],
        "fence_y_mm": 0.0, "fence_end_x_mm": float(fence_end),
        "belt_width_mm": float(belt_top - belt_bottom), "belt_y_mm": [float(belt_bottom), float(belt_top)],
        "pitch_mm": float(pitch),
        "belt_speed_mm_s": None if belt_speed is None else float(belt_speed),
        "mu_s": float(mu_s) if dynamic else None,
        "throughput_per_min": throughput,
        "drawing": drawing,
        "method": _layout_method(cfg, "dynamic" if dynamic else model, trials, good, perturb, bounds,
                                 spacing, busy, y_min, y_max, dynamic),
    }


def _layout_trials(part, heights, states, mu_c, pin_radius, cfg, kw):
    """``(trials, good, nominal)``: the perturbed trials, those that did not
    jam (none left raises :class:`PinfeedError`) and the nominal replays."""
    trials = run_trials(part, heights, states, mu_c, pin_radius, trials=cfg["trials"],
                        corners=cfg["corners"], seed=cfg["seed"], **kw)
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


def _pitch(part, good, lanes, n_pins, entry, cfg):
    """``(spacing, y_min, y_max, busy, pitch)`` in mm: the touch-free spacing of
    two consecutive parts, the swept y range, each pin's contact span and the
    pitch (the larger of spacing and busy span on the time grid, plus margin)."""
    step = cfg["time_step_mm"]
    course = max(float(lane.B[-1]) for lane in lanes) + entry + 4.0 * part.a
    clock = step * np.arange(-int(math.ceil(course / step)), int(math.ceil(2 * course / step)) + 1)
    y_lanes = np.concatenate([lane.y for lane in lanes])
    spacing, y_min, y_max = touch_free_spacing(
        part, lanes, clock, cfg["slab_mm"],
        (float(y_lanes.min()) - part.a, float(y_lanes.max()) + part.a))
    starts, ends = contact_windows(good, lanes, n_pins)
    busy = [max(e) - min(s) if s else 0.0 for s, e in zip(starts, ends)]
    pin_spacing = step * (math.floor(max(busy) / step) + 1)
    pitch = max(spacing, pin_spacing) + cfg["pitch_margin_mm"]
    return spacing, y_min, y_max, busy, pitch


def _layout_method(cfg, model, trials, good, perturb, bounds, spacing, busy, y_min, y_max,
                   dynamic) -> dict:
    """The ``method`` entry of a layout: how each number was obtained."""
    return {
        "model": model,
        "trials": {"per_state": int(cfg["trials"]), "corners": bool(cfg["corners"]),
                   "replayed": len(trials), "jammed_left_out": len(trials) - len(good),
                   "jams": sorted({t.jam for t in trials if t.jam}), "seed": int(cfg["seed"]),
                   "perturbation": perturb or {}},
        "margins_mm": {k: float(cfg[k]) for k in MARGIN_KEYS},
        "stations": "first pin at x = 0; each next pin where its disc misses every pose of "
                    "every trial from first touch at any earlier pin until the part rests, "
                    "plus the station margin",
        "station_bounds": bounds,
        "pitch": {"touch_free_spacing_mm": spacing, "pin_busy_mm": [float(b) for b in busy],
                  "time_step_mm": cfg["time_step_mm"], "slab_mm": cfg["slab_mm"],
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


def _drawing(part, states, nominal_lanes, stations, pitch, entry, pin_radius, margin) -> dict:
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


# ------------------------------------------------------------- stored plans


def layout_stored(result, config: dict, plan_number: int = 1, mu_text=None,
                  belt_speed: float | None = None, mu_s: float | None = None,
                  quasi_static: bool = False, settings: dict | None = None) -> dict:
    """The layout of tight plan ``plan_number`` of a stored plan result
    (``RESULTS/plans/NAME.json``; a :class:`~pipeline.planning.core.types.PlanFile`
    or its dict), as ``pinfeed layout`` and the workflow make it.

    The plan's speed limit is the one stored with the plan (at the same belt
    friction; ``speed_limit.attach_speed_limits``), else computed
    (``speed_limit.speed_curve`` with ``speed_trials`` trials per state);
    ``speed_limit_trials`` says which trials it comes from and
    ``stored_speed_limit`` the plan file's figure. Without ``belt_speed`` the
    belt runs at ``speed_fraction`` (80 %) of it. A belt speed above the limit is kept and
    named in ``warnings``. Trials use the dynamic model at that speed, or the
    plan's quasi-static model with ``quasi_static`` (or when no belt speed
    passes the speed grid at all: then there is no belt speed and no
    throughput, and ``warnings`` says so).
    """
    from pipeline.maps import simulate
    from pipeline.planning import friction_label
    from pipeline.planning import DEFAULT_SPEEDS
    from pipeline.planning import as_plan_file
    from pipeline.provenance import provenance_attrs
    cfg = check_layout_settings({**config.get("layout", {}), **(settings or {})})
    result = as_plan_file(result)
    plan, mu_c, states = _fixed_pin_plan(result, plan_number, mu_text)
    part = Part.from_dict(result.part, name=result.name)
    pin_radius = float(result.extra.get("pin_radius", config["sweep"]["pin_radius"]))
    mu_s = float(cfg["mu_s"] if mu_s is None else mu_s)
    heights = [float(h) for h in plan.pin_heights_mm]
    # A bad belt speed or mu_s is refused before any work.
    simulate.check_belt(part, min(DEFAULT_SPEEDS) if belt_speed is None else belt_speed, mu_s)
    curve, trials, stored = _speed_limit(plan, part, list(states.values()), mu_c, mu_s, pin_radius,
                                         config, cfg)
    limit = curve["speed_limit_mm_s"]
    belt_speed, source, quasi_static, warnings = _belt_speed_choice(belt_speed, limit, cfg,
                                                                    quasi_static)
    out = layout_plan(part, list(plan.pins), heights, states, mu_c, pin_radius, model=result.model,
                      belt_speed=None if quasi_static else belt_speed, mu_s=mu_s, settings=cfg,
                      perturb=config.get("verify"))
    out["belt_speed_mm_s"] = None if belt_speed is None else float(belt_speed)
    out["mu_s"] = mu_s
    out["throughput_per_min"] = None if belt_speed is None else 60.0 * belt_speed / out["pitch_mm"]
    out["speed_limit_mm_s"] = float(limit)
    out["mu_c"] = list(mu_c) if isinstance(mu_c, tuple) else mu_c
    out["plan"] = {"number": int(plan_number), "friction": friction_label(mu_c),
                   "pins": list(plan.pins), "pin_heights_mm": heights,
                   "final_sets": [s.to_dict() for s in plan.final_sets],
                   "n_final_sets": plan.n_final_sets}
    verified = plan.verification.to_dict() if plan.verification else None
    out["warnings"] = warnings + final_sets_warning(dict(out["plan"], verification=verified))
    _family_assumption(out, result)
    out["method"]["belt_speed"] = source
    out["method"]["throughput"] = "60 x belt speed / pitch" if belt_speed else "none: no belt speed"
    _record_speed_limit(out, curve, trials, stored)
    out.update(provenance_attrs())
    return out


def _family_assumption(out: dict, result) -> None:
    """For a plan made for a support family: ``assumes`` and a one-line
    ``assumption`` (also among the warnings): the belt speed and spacing come
    from the dynamic model, which assumes uniform pressure."""
    from pipeline.planning import family_assumption
    note = family_assumption(result, "layout")
    if note:
        out.update(note)
        out["warnings"].append(note["assumption"])


def _record_speed_limit(out: dict, curve: dict, trials: int, stored: dict | None) -> None:
    """Write into the layout ``out`` where its speed limit comes from: the trials per
    state (``speed_limit_trials``), the plan file's figure (``stored_speed_limit``)
    and ``method.speed_limit``."""
    from pipeline.planning import DEFAULT_SPEEDS
    out["speed_limit_trials"] = int(trials)
    out["stored_speed_limit"] = None if stored is None else {
        k: stored[k] for k in ("speed_limit_mm_s", "trials", "mu_s")}
    out["method"]["speed_limit"] = {
        "model": "dynamic", "trials_per_state": int(trials), "corners_per_state": 4,
        "source": "stored with the plan" if curve is stored else "computed for this layout",
        "required_fraction": 0.99, "speeds_mm_s": list(DEFAULT_SPEEDS), "bisection_mm_s": 5.0,
        "curve": curve["curve"]}


def _speed_limit(plan, part, states, mu_c, mu_s, pin_radius, config, cfg) -> tuple:
    """``(curve, trials, stored)``: the speed limit stored with ``plan`` when it was
    computed at belt friction ``mu_s`` (one speed limit per plan), else one computed
    here with ``speed_trials`` trials per state; ``stored``: the plan's record or None."""
    from pipeline.planning import PlannerSettings, perturbation_from_verify, speed_curve, stored_speed_limit
    stored = stored_speed_limit(plan)
    if stored and stored["settings"]["mu_s"] == mu_s:
        return stored, stored["trials"], stored
    heights = [float(h) for h in plan.pin_heights_mm]
    curve = speed_curve(part, heights, [0.0] * len(heights), states, plan.final_arcs, mu_c, mu_s=mu_s,
                        perturb=perturbation_from_verify(PlannerSettings.from_config(config).verify.perturbation),
                        trials=cfg["speed_trials"], r_pin=pin_radius, seed=cfg["seed"])
    return curve, cfg["speed_trials"], stored


def _fixed_pin_plan(result, plan_number, mu_text):
    """``(plan, mu_c, states)``: tight plan ``plan_number`` at friction ``mu_text``
    of the :class:`~pipeline.planning.core.types.PlanFile` ``result``
    (:func:`~pipeline.planning.plans.plan.pick_tight_plan`), refused with a one-line
    :class:`PinfeedError` if it has moving pins; ``states``: label ->
    ``(theta_deg, y_c_mm)``, the entry's resting states, else the file's."""
    from pipeline.planning import pick_tight_plan
    plan, mu_c, entry = pick_tight_plan(result, int(plan_number), mu_text)
    if any(float(v) for v in plan.pin_speeds or ()):
        fixed = [f"--plan {k} ({' '.join(p.pins)})" for k, p in enumerate(entry.plans, start=1)
                 if not any(float(v) for v in p.pin_speeds or ())]
        usable = (f"plans of fixed pins: {', '.join(fixed)}" if fixed else
                  "no stored plan at this friction has fixed pins only; re-plan with --dynamic-depth 0")
        raise PinfeedError(f"plan {plan_number} ({' '.join(plan.pins)}) has moving pins; a layout "
                           f"places fixed pins only; {usable}")
    stored_states = entry.initial_states or result.initial_states or {}
    return plan, mu_c, {k: (float(s.theta), float(s.y_c)) for k, s in stored_states.items()}


def _belt_speed_choice(belt_speed, limit, cfg, quasi_static):
    """``(belt_speed, source, quasi_static, warnings)`` of a stored plan's layout.

    Without ``belt_speed`` (mm/s): ``speed_fraction`` of the speed ``limit``
    (mm/s), or none and the quasi-static model when no speed passes; a given
    speed above the limit is kept with a warning.
    """
    from pipeline.planning import DEFAULT_SPEEDS
    warnings = []
    if belt_speed is None and limit > 0:
        belt_speed = cfg["speed_fraction"] * limit
        source = f"{100 * cfg['speed_fraction']:g} % of the plan's speed limit {limit:g} mm/s"
    elif belt_speed is None:
        source = "none"
        quasi_static = True
        warnings.append(f"no belt speed of the grid ({', '.join(f'{v:g}' for v in DEFAULT_SPEEDS)} "
                        f"mm/s) passes the plan's trials: laid out with the quasi-static model, no "
                        f"throughput; give --belt-speed MM_S")
    else:
        source = "given"
        if belt_speed > limit:
            warnings.append(f"belt speed {belt_speed:g} mm/s is above the plan's speed limit "
                            f"{limit:g} mm/s (fewer than 99 % of its trials end in the final set)")
    return belt_speed, source, quasi_static, warnings


def final_sets_warning(plan: dict) -> list[str]:
    """A warning (a list of none or one line) when a laid-out plan leaves the parts in
    several final orientation sets: such a feeder does not orient them fully. A
    plan whose verification says it orients (its trials end in one set within
    the tolerance, though the claim names several narrower ones) gets none."""
    from pipeline.planning import format_arcs
    n = plan.get("n_final_sets") or len(plan.get("final_sets") or ())
    orientation = (plan.get("verification") or {}).get("orientation") or {}
    if n <= 1 or orientation.get("orients"):
        # Claimed sets that the verified trials show to lie in one set of the
        # tolerance's width are one orientation to the user.
        return []
    return [f"plan {plan['number']} leaves {n} final orientation sets ({format_arcs(plan['final_sets'])}): "
            f"parts leave this feeder in more than one orientation"]


def speed_limit_text(layout: dict) -> str:
    """A layout's speed limit with the trials it comes from, and the plan file's
    figure when that differs: one speed limit per plan, or a labelled other one."""
    trials = layout.get("speed_limit_trials")
    text = f"{layout['speed_limit_mm_s']:g} mm/s" + (f" ({trials} trials per state)" if trials else "")
    stored = layout.get("stored_speed_limit")
    if stored and (stored["speed_limit_mm_s"], stored["trials"]) != (layout["speed_limit_mm_s"], trials):
        text += (f"; the plan file stores {stored['speed_limit_mm_s']:g} mm/s ({stored['trials']} trials "
                 f"per state, mu_s {stored['mu_s']:g})")
    return text


DRAWING_SUFFIXES = (".dxf", ".svg", ".png")


def check_drawing_path(path):
    """A drawing path: a known suffix and a folder that exists (or can be made)
    and is writable; a one-line :class:`PinfeedError` otherwise."""
    import os
    from pathlib import Path

    from pipeline.checks import check_out_path
    path = check_out_path(path, DRAWING_SUFFIXES)
    parent = next((p for p in Path(path).absolute().parents if p.exists()), Path("."))
    if not os.access(parent, os.W_OK | os.X_OK):
        raise PinfeedError(f"--out {path}: cannot write in {parent} (not writable); choose another path")
    return Path(path)


def write_drawing(layout: dict, path):
    """Write the feeder drawing of ``layout`` to ``path`` (.dxf, .svg or .png), atomically."""
    from pipeline.present.figures.feeder import draw_feeder, write_dxf
    path = check_drawing_path(path)
    if path.suffix.lower() == ".dxf":
        return write_dxf(layout, path)
    return draw_feeder(layout, path)


def layout_part(plan_result, config: dict, outputs: dict) -> str:
    """The workflow's layout stage: the first tight plan of fixed pins at the
    first planned friction, laid out and drawn; ``outputs`` maps ``json``,
    ``dxf``, ``svg`` and ``png`` to paths. A part with no such plan gets a JSON
    saying why and drawings of that note. Returns a one-line summary."""
    import time

    from pipeline.maps.io import write_json
    from pipeline.planning import as_plan_file
    start = time.perf_counter()
    plan_result = as_plan_file(plan_result)
    first_plans = plan_result.tight[0].plans if plan_result.tight else ()
    number = next((k for k, p in enumerate(first_plans, start=1) if not any(p.pin_speeds or [])), None)
    name = plan_result.name
    if number is None:
        note = f"{name}: no tight plan of fixed pins to lay out"
        write_json({"part": name, "plan": None, "note": note}, outputs["json"])
        _note_drawings(note, outputs)
        return note
    out = layout_stored(plan_result, config, number)
    out["method"]["seconds"] = round(time.perf_counter() - start, 1)
    for key in ("dxf", "svg", "png"):
        write_drawing(out, outputs[key])
    write_json(out, outputs["json"])
    return (f"{name}: plan {number} ({' '.join(out['plan']['pins'])}), pitch {out['pitch_mm']:.1f} mm, "
            f"belt {out['belt_speed_mm_s']} mm/s (limit {out['speed_limit_mm_s']:g}), throughput "
            f"{out['throughput_per_min']} parts/min, {out['method']['seconds']} s; warnings {out['warnings']}")


def _note_drawings(note: str, outputs: dict) -> None:
    import ezdxf

    from pipeline.maps.io import atomic_target
    from pipeline.present.figures import placeholder
    for key in ("svg", "png"):
        with atomic_target(outputs[key]) as tmp:
            placeholder(tmp + "." + key, note)
            import os
            os.replace(tmp + "." + key, tmp)
    doc = ezdxf.new("R2010")
    doc.layers.add("TITLE")
    doc.modelspace().add_text(note, height=3.5, dxfattribs={"layer": "TITLE"})
    with atomic_target(outputs["dxf"]) as tmp:
        doc.saveas(tmp)
