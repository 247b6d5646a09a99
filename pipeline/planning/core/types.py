"""Typed records of a stored plan file (``RESULTS/plans/NAME.json``).

The planners (``search.TightPlan.to_dict``, ``paper.Plan.to_dict``) and the
writers (``workflow.plan.plan_part``, ``pinfeed plan``) still build plain
dicts; these records read such a dict and write it back unchanged:
``Record.from_dict(d).to_dict() == d`` for every plan file the current code
writes, and ``Record.from_dict(r.to_dict()) == r``. Keys a record does not
know are kept in its ``extra`` and written back as they were, so a file with
more keys still round-trips.

The shape of the file is checked by the JSON schema ``plan.schema.json``
next to this module (package data): :func:`validate_plan_dict`,
:func:`validate_plan_file` and :func:`load_plan` raise a one-line
:class:`~pipeline.errors.PinfeedError` that names the file and how to make
it again.

Units: angles in degrees (orientations in [0, 360)), heights and positions
in mm, ``d`` (pin offset from the centroid over the part's radius ``a``)
dimensionless, friction ``mu_c`` dimensionless, belt speed in mm/s, pin
speeds as the ratio v_pin / v_belt.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from pipeline.checks import schema_problem
from pipeline.errors import PinfeedError
from pipeline.planning.core.settings import Friction

SCHEMA_PATH = Path(__file__).resolve().parent / "plan.schema.json"


def _extra(d: dict, known) -> dict:
    """The keys of ``d`` a record does not model, kept as they are."""
    return {k: v for k, v in d.items() if k not in known}


def _pair(values) -> tuple:
    """A stored ``[lo, hi]`` as a tuple."""
    return (values[0], values[1])


def _friction_in(value):
    """Stored friction (a number or ``[lo, hi]``) -> a number or ``(lo, hi)``."""
    return tuple(value) if isinstance(value, list) else value


def _friction_out(value):
    """A friction as stored: a number or ``[lo, hi]``."""
    return list(value) if isinstance(value, tuple) else value


@dataclass(frozen=True)
class Arc:
    """An arc of orientations: ``start`` in [0, 360) and ``width`` >= 0, degrees
    (stored as ``{"start", "width"}``)."""
    start: float
    width: float

    @classmethod
    def from_dict(cls, d: dict) -> "Arc":
        """The record of a stored dict (as read from the plan file)."""
        return cls(d["start"], d["width"])

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        return {"start": self.start, "width": self.width}

    @property
    def pair(self) -> tuple:
        """``(start, width)``, the form ``arcs.format_arcs`` and ``merge_arcs`` take."""
        return (self.start, self.width)


@dataclass(frozen=True)
class State:
    """A set of states the tight planner carries (``propagate.StateSet``):
    orientations ``arc`` (deg), centroid heights ``y_c = (lo, hi)`` in mm and
    friction ``mu_c = (lo, hi)``. Stored as ``{"arc", "y_c": [lo, hi],
    "mu_c": [lo, hi]}``."""
    arc: Arc
    y_c: tuple
    mu_c: tuple
    extra: dict = field(default_factory=dict)

    KEYS = ("arc", "y_c", "mu_c")

    @classmethod
    def from_dict(cls, d: dict) -> "State":
        """The record of a stored dict (as read from the plan file)."""
        return cls(Arc.from_dict(d["arc"]), _pair(d["y_c"]), _pair(d["mu_c"]), _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        return {"arc": self.arc.to_dict(), "y_c": list(self.y_c), "mu_c": list(self.mu_c), **self.extra}


@dataclass(frozen=True)
class RestingState:
    """A nominal initial resting state: orientation ``theta`` (deg) and centroid
    height ``y_c`` (mm) above the fence. Stored as ``{"theta", "y_c"}``."""
    theta: float
    y_c: float

    @classmethod
    def from_dict(cls, d: dict) -> "RestingState":
        """The record of a stored dict (as read from the plan file)."""
        return cls(d["theta"], d["y_c"])

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        return {"theta": self.theta, "y_c": self.y_c}


@dataclass(frozen=True)
class Step:
    """What one pin did to one branch of one initial state.

    ``pin``: its label; ``y_pin``: its height (mm); ``v_pin``: its speed
    ratio (0 for a fixed pin); ``d_range = (lo, hi)``: the offsets ``d`` the
    branch meets it at (dimensionless); ``band``: orientations after it
    (deg); ``com_interval = (lo, hi)``: centroid heights after it (mm);
    ``carried``: the whole carried :class:`State` (tight planner only,
    ``None`` in a paper-mode plan, whose steps lack the key)."""
    pin: str
    y_pin: float
    v_pin: float | None
    d_range: tuple
    band: Arc
    com_interval: tuple
    carried: State | None = None
    extra: dict = field(default_factory=dict)

    KEYS = ("pin", "y_pin", "v_pin", "d_range", "band", "com_interval", "carried")

    @classmethod
    def from_dict(cls, d: dict) -> "Step":
        """The record of a stored dict (as read from the plan file)."""
        carried = d.get("carried")
        return cls(d["pin"], d["y_pin"], d.get("v_pin"), _pair(d["d_range"]), Arc.from_dict(d["band"]),
                   _pair(d["com_interval"]), State.from_dict(carried) if carried is not None else None,
                   _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        out = {"pin": self.pin, "y_pin": self.y_pin}
        if self.v_pin is not None:
            out["v_pin"] = self.v_pin
        out.update({"d_range": list(self.d_range), "band": self.band.to_dict(),
                    "com_interval": list(self.com_interval)})
        if self.carried is not None:
            out["carried"] = self.carried.to_dict()
        return {**out, **self.extra}


@dataclass(frozen=True)
class VerificationRow:
    """Replayed trials of one initial state: ``trials``, ``successes``,
    ``failures`` (counts) and ``reasons`` (failure reason -> count)."""
    state: str
    trials: int
    successes: int
    failures: int
    reasons: dict
    extra: dict = field(default_factory=dict)

    KEYS = ("state", "trials", "successes", "failures", "reasons")

    @classmethod
    def from_dict(cls, d: dict) -> "VerificationRow":
        """The record of a stored dict (as read from the plan file)."""
        return cls(d["state"], d["trials"], d["successes"], d["failures"], dict(d["reasons"]),
                   _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        return {"state": self.state, "trials": self.trials, "successes": self.successes,
                "failures": self.failures, "reasons": dict(self.reasons), **self.extra}


@dataclass(frozen=True)
class Verification:
    """Perturbed full rollouts of a plan (``verify.verify_plan``): total
    ``trials``, ``successes`` and ``failures`` (counts), one
    :class:`VerificationRow` per initial state, the ``model`` replayed with
    (``"dynamic"`` at a belt speed; None in files verified before the model was
    recorded) and, for the dynamic model only, the belt speed (mm/s) and belt
    friction ``mu_s``."""
    trials: int
    successes: int
    failures: int
    rows: tuple
    model: str | None = None
    belt_speed: float | None = None
    mu_s: float | None = None
    extra: dict = field(default_factory=dict)

    KEYS = ("trials", "successes", "failures", "rows", "model", "belt_speed", "mu_s")

    @classmethod
    def from_dict(cls, d: dict) -> "Verification":
        """The record of a stored dict (as read from the plan file)."""
        return cls(d["trials"], d["successes"], d["failures"],
                   tuple(VerificationRow.from_dict(r) for r in d["rows"]), d.get("model"),
                   d.get("belt_speed"), d.get("mu_s"), _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        out = {"trials": self.trials, "successes": self.successes, "failures": self.failures,
               "rows": [r.to_dict() for r in self.rows]}
        if self.model is not None:  # older files have no model
            out["model"] = self.model
        if self.belt_speed is not None:
            out["belt_speed"] = self.belt_speed
        if self.mu_s is not None:
            out["mu_s"] = self.mu_s
        return {**out, **self.extra}

    @property
    def success_fraction(self) -> float:
        """successes / trials (0 without trials)."""
        return self.successes / self.trials if self.trials else 0.0


def _branches_in(d: dict) -> dict:
    """Stored branches (label -> lists of step dicts) as tuples of :class:`Step`."""
    return {label: tuple(tuple(Step.from_dict(s) for s in br) for br in brs) for label, brs in d.items()}


def _branches_out(branches: dict) -> dict:
    """Branches of :class:`Step` as stored."""
    return {label: [[s.to_dict() for s in br] for br in brs] for label, brs in branches.items()}


@dataclass(frozen=True)
class Plan:
    """One pin sequence and what it does.

    ``pins``: pin labels in belt order; ``final_sets``: the merged final
    orientation arcs (deg), ``n_final_sets`` of them counted modulo the part's
    symmetry; ``margin``: safety margin in d (dimensionless; ``None`` when the
    plan touches nothing); ``sets_after_each_pin``: set counts after each pin;
    ``n_dynamic_pins``: how many pins move; ``branches``: initial-state label
    -> its branches, each a tuple of :class:`Step` (stored under the key
    ``initial_states``).

    Tight plans (``mode == "tight"``) also store ``pin_heights_mm`` (mm),
    ``pin_speeds`` (v_pin / v_belt), ``jump_steps`` (steps whose box straddled
    a jump), ``initial_sets`` (label -> starting :class:`State`) and
    ``verification``; a paper-mode plan has none of these keys (``None``
    here), its heights are the file's ``pins`` table. Only ``pins`` and
    ``final_sets`` are required: an older or hand-made plan may lack the rest
    (``None``; then not written back)."""
    pins: tuple
    final_sets: tuple
    n_final_sets: int | None = None
    margin: float | None = None
    sets_after_each_pin: tuple | None = None
    n_dynamic_pins: int | None = None
    branches: dict | None = None
    mode: str | None = None
    pin_heights_mm: tuple | None = None
    pin_speeds: tuple | None = None
    jump_steps: int | None = None
    initial_sets: dict | None = None
    verification: Verification | None = None
    extra: dict = field(default_factory=dict)

    KEYS = ("mode", "pins", "pin_heights_mm", "pin_speeds", "n_final_sets", "final_sets", "margin",
            "jump_steps", "sets_after_each_pin", "n_dynamic_pins", "initial_sets", "initial_states",
            "verification")

    @classmethod
    def from_dict(cls, d: dict) -> "Plan":
        """The record of a stored dict (as read from the plan file)."""
        opt = lambda k: tuple(d[k]) if d.get(k) is not None else None  # noqa: E731
        ver = d.get("verification")
        sets = d.get("initial_sets")
        branches = d.get("initial_states")
        return cls(tuple(d["pins"]), tuple(Arc.from_dict(s) for s in d["final_sets"]), d.get("n_final_sets"),
                   d.get("margin"), opt("sets_after_each_pin"), d.get("n_dynamic_pins"),
                   _branches_in(branches) if branches is not None else None, d.get("mode"), opt("pin_heights_mm"),
                   opt("pin_speeds"), d.get("jump_steps"),
                   {k: State.from_dict(v) for k, v in sets.items()} if sets is not None else None,
                   Verification.from_dict(ver) if ver is not None else None, _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        out = {} if self.mode is None else {"mode": self.mode}
        out["pins"] = list(self.pins)
        for key in ("pin_heights_mm", "pin_speeds"):
            if getattr(self, key) is not None:
                out[key] = list(getattr(self, key))
        if self.n_final_sets is not None:
            out["n_final_sets"] = self.n_final_sets
        out["final_sets"] = [s.to_dict() for s in self.final_sets]
        if self.n_final_sets is not None or self.margin is not None:  # the planners always write it
            out["margin"] = self.margin
        if self.jump_steps is not None:
            out["jump_steps"] = self.jump_steps
        if self.sets_after_each_pin is not None:
            out["sets_after_each_pin"] = list(self.sets_after_each_pin)
        if self.n_dynamic_pins is not None:
            out["n_dynamic_pins"] = self.n_dynamic_pins
        if self.initial_sets is not None:
            out["initial_sets"] = {k: v.to_dict() for k, v in self.initial_sets.items()}
        if self.branches is not None:
            out["initial_states"] = _branches_out(self.branches)
        if self.mode is not None or self.verification is not None:  # a tight plan always has the key
            out["verification"] = self.verification.to_dict() if self.verification else None
        return {**out, **self.extra}

    @property
    def final_arcs(self) -> list:
        """``final_sets`` as ``(start, width)`` pairs (deg)."""
        return [s.pair for s in self.final_sets]

    def heights(self, table: dict | None = None) -> list:
        """Pin heights in mm: the plan's own (tight) or looked up in ``table``
        (paper mode: the file's ``pins``, label -> mm)."""
        if self.pin_heights_mm is not None:
            return list(self.pin_heights_mm)
        return [table[p] for p in self.pins]


def _plan_or_none(d):
    """A stored plan (or null) as a :class:`Plan` (or ``None``)."""
    return Plan.from_dict(d) if d is not None else None


@dataclass(frozen=True)
class TightEntry:
    """The tight planner's plans at one friction (an item of the file's ``tight``).

    ``mu_c``: the friction planned for, a value or ``(lo, hi)``;
    ``friction``: its text (``0.15`` or ``0.1:0.3``); ``belt_speed`` (mm/s)
    and ``mu_s`` (``None`` when quasi-static); ``mechanics``: what the plans
    were computed with; ``symmetry_order``: the part's rotational symmetry;
    ``depth``, ``complete_depth``, ``beam``: search settings; ``plans``:
    verified plans best first; ``rejected``: plans that failed verification;
    ``recommended``: the best plan or ``None`` (then ``warning`` says why);
    ``stats``: search statistics (``seconds`` in s, counts otherwise);
    ``initial_states``: label -> :class:`RestingState`."""
    mu_c: object
    friction: str
    plans: tuple
    initial_states: dict | None = None
    recommended: Plan | None = None
    warning: str | None = None
    belt_speed: float | None = None
    mu_s: float | None = None
    mechanics: str | None = None
    symmetry_order: int | None = None
    depth: int | None = None
    complete_depth: int | None = None
    beam: int | None = None
    rejected: tuple | None = None
    stats: dict | None = None
    extra: dict = field(default_factory=dict)

    KEYS = ("mu_c", "friction", "belt_speed", "mu_s", "mechanics", "symmetry_order", "depth",
            "complete_depth", "beam", "plans", "rejected", "recommended", "warning", "stats",
            "initial_states")
    NULLABLE = ("belt_speed", "mu_s", "recommended", "warning")  # always written, maybe null

    @property
    def planned_friction(self) -> Friction:
        """The friction planned for, as a :class:`~pipeline.planning.core.settings.Friction`."""
        return Friction.parse(self.mu_c)

    @classmethod
    def from_dict(cls, d: dict) -> "TightEntry":
        """The record of a stored dict (as read from the plan file)."""
        rejected, states = d.get("rejected"), d.get("initial_states")
        return cls(_friction_in(d["mu_c"]), d["friction"], tuple(Plan.from_dict(p) for p in d["plans"]),
                   {k: RestingState.from_dict(v) for k, v in states.items()} if states is not None else None,
                   _plan_or_none(d.get("recommended")), d.get("warning"), d.get("belt_speed"),
                   d.get("mu_s"), d.get("mechanics"), d.get("symmetry_order"), d.get("depth"),
                   d.get("complete_depth"), d.get("beam"),
                   tuple(Plan.from_dict(p) for p in rejected) if rejected is not None else None,
                   d.get("stats"), _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        values = {"mu_c": _friction_out(self.mu_c), "friction": self.friction,
                  "belt_speed": self.belt_speed, "mu_s": self.mu_s, "mechanics": self.mechanics,
                  "symmetry_order": self.symmetry_order, "depth": self.depth,
                  "complete_depth": self.complete_depth, "beam": self.beam,
                  "plans": [p.to_dict() for p in self.plans],
                  "rejected": [p.to_dict() for p in self.rejected] if self.rejected is not None else None,
                  "recommended": self.recommended.to_dict() if self.recommended else None,
                  "warning": self.warning, "stats": self.stats,
                  "initial_states": ({k: v.to_dict() for k, v in self.initial_states.items()}
                                     if self.initial_states is not None else None)}
        out = {k: v for k, v in values.items() if v is not None or k in self.NULLABLE}
        return {**out, **self.extra}

    @property
    def resting_states(self) -> dict:
        """label -> ``(theta_deg, y_c_mm)``, as ``verify.verify_plan`` takes them."""
        return {k: (s.theta, s.y_c) for k, s in self.initial_states.items()}


@dataclass(frozen=True)
class PlanFile:
    """A stored plan file: the ``part`` (its ``to_dict``: name, id, vertices in
    mm, ...) and ``model``; the tight planner's entries at every planned
    friction (``tight``, first = ``planner.mu_c``); and, when paper mode ran
    (``plans`` is not ``None``): its friction ``mu_c``, pin table ``pins``
    (label -> height, mm), ``pin_speeds`` (label -> v_pin / v_belt),
    ranked ``plans``, ``best_static`` (best fixed-pin plan or ``None``) and
    nominal ``initial_states``. Every other key (provenance, search settings,
    ``selection``, ``coverage``, ...) is kept in ``extra``."""
    part: dict
    model: str | None = None
    tight: tuple | None = None
    plans: tuple | None = None
    best_static: Plan | None = None
    pins: dict | None = None
    pin_speeds: dict | None = None
    mu_c: object = None
    initial_states: dict | None = None
    extra: dict = field(default_factory=dict)

    KEYS = ("part", "model", "tight", "plans", "best_static", "pins", "pin_speeds", "mu_c", "initial_states")

    @classmethod
    def from_dict(cls, d: dict) -> "PlanFile":
        """The record of a stored dict (as read from the plan file)."""
        tight, plans, states = d.get("tight"), d.get("plans"), d.get("initial_states")
        return cls(d["part"], d.get("model"),
                   tuple(TightEntry.from_dict(t) for t in tight) if tight is not None else None,
                   tuple(Plan.from_dict(p) for p in plans) if plans is not None else None,
                   _plan_or_none(d.get("best_static")), d.get("pins"), d.get("pin_speeds"),
                   _friction_in(d["mu_c"]) if "mu_c" in d else None,
                   {k: RestingState.from_dict(v) for k, v in states.items()} if states is not None else None,
                   _extra(d, cls.KEYS))

    def to_dict(self) -> dict:
        """The stored dict: the keys and values this record was read from."""
        out = {"part": self.part}
        if self.model is not None:
            out["model"] = self.model
        if self.mu_c is not None:
            out["mu_c"] = _friction_out(self.mu_c)
        for key in ("pins", "pin_speeds"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.plans is not None:  # paper mode writes best_static, maybe null
            out["best_static"] = self.best_static.to_dict() if self.best_static else None
            out["plans"] = [p.to_dict() for p in self.plans]
        if self.initial_states is not None:
            out["initial_states"] = {k: v.to_dict() for k, v in self.initial_states.items()}
        if self.tight is not None:
            out["tight"] = [t.to_dict() for t in self.tight]
        return {**out, **self.extra}

    @property
    def name(self) -> str:
        """The part's name."""
        return self.part["name"]


def as_plan_file(result) -> PlanFile:
    """``result`` as a :class:`PlanFile`: a record is returned as it is, a stored
    plan dict (as read from the file) is read with :meth:`PlanFile.from_dict`.
    The one place where a consumer turns a plan dict into records."""
    return result if isinstance(result, PlanFile) else PlanFile.from_dict(result)


# ---------------------------------------------------------------------- schema


@lru_cache(maxsize=1)
def plan_schema() -> dict:
    """The JSON schema of a stored plan file (``plan.schema.json``)."""
    return json.loads(SCHEMA_PATH.read_text())


def regenerate_hint(data, source) -> str:
    """How to make a plan file again: the workflow, or ``pinfeed plan`` for its part."""
    part = data.get("part") if isinstance(data, dict) else None
    name = part.get("name") if isinstance(part, dict) else None
    return (f"re-run the workflow ('make run') or 'pinfeed plan --part {name or 'NAME'} "
            f"--out {source if source != 'the plan' else 'FILE'}'")


def validate_plan_dict(data, source="the plan") -> dict:
    """``data`` if it has the shape of a stored plan file, else a one-line
    :class:`PinfeedError` naming ``source`` (the file), where it is wrong and
    how to make it again."""
    problem = schema_problem(data, plan_schema())
    if problem is not None:
        raise PinfeedError(f"{source} is not a pinfeed plan file ({problem}); "
                           f"delete it and make it again: {regenerate_hint(data, source)}")
    return data


def validate_plan_file(path) -> dict:
    """The stored plan file at ``path`` as a dict, checked (:func:`validate_plan_dict`);
    a missing or corrupt file is a one-line :class:`PinfeedError` too."""
    from pipeline.maps.io import read_json
    return validate_plan_dict(read_json(path), str(path))


def load_plan(path) -> PlanFile:
    """The stored plan file at ``path``, checked, as a :class:`PlanFile`."""
    return PlanFile.from_dict(validate_plan_file(path))
