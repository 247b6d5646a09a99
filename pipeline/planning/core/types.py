"""Typed records of a stored plan file (``RESULTS/plans/NAME.json``).

The file-level records: the tight planner's plans at one friction
(:class:`TightEntry`) and the whole file (:class:`PlanFile`); the records
of one plan they hold (:class:`~pipeline.planning.core.plan_records.Plan`
and its parts) are in :mod:`pipeline.planning.core.plan_records`.

The tight planner returns a :class:`TightEntry` per friction, and the steps
after it (family certificate, nearest "yes", speed limits on the
:class:`PlanFile`, shape tolerance) take the records and add to them; the
writers (``workflow.plan.plan_part``, ``pinfeed plan``) turn them into
dicts only at the edge. (The paper-mode planner's ``paper.Plan.to_dict``
still builds dicts.) A field a stored dict may lack defaults to
:data:`~pipeline.planning.core.plan_records.ABSENT`. The records read a
stored dict and write it back unchanged:
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
from pipeline.planning.core.plan_records import ABSENT, Plan, RestingState, optional_keys, present, unmodelled_keys
from pipeline.planning.core.settings import Friction

SCHEMA_PATH = Path(__file__).resolve().parent / "plan.schema.json"


def _friction_in(value):
    """Stored friction (a number or ``[lo, hi]``) -> a number or ``(lo, hi)``."""
    return tuple(value) if isinstance(value, list) else value


def _friction_out(value):
    """A friction as stored: a number or ``[lo, hi]``."""
    return list(value) if isinstance(value, tuple) else value


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
    ``initial_states``: label -> :class:`RestingState`.

    Written by the tight planner (:data:`ABSENT` in older files):
    ``tolerance_deg`` and ``required`` (the claim's rule), ``orients``,
    ``needs_no_pin``, ``pins_used`` (label -> height, mm), the searches'
    records ``fixed_pin_search`` and ``moving_pin_search``; with a support
    family ``support_family``, ``family_certificate`` (``None``: no plan
    holds for it) and ``family_worst_member``; ``nearest_yes`` when nothing
    orients; under a time limit ``time_limit_s``, ``complete`` and
    ``unsearched``; ``shape_tolerance`` when it was asked for. These
    records are written once, by the step that makes them, and read only at
    the edge (the command line, the report)."""
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
    tolerance_deg: float = ABSENT
    required: float = ABSENT
    orients: bool = ABSENT
    needs_no_pin: bool = ABSENT
    pins_used: dict = ABSENT
    fixed_pin_search: dict = ABSENT
    moving_pin_search: dict | None = ABSENT
    support_family: dict = ABSENT
    family_certificate: dict | None = ABSENT
    family_worst_member: dict = ABSENT
    nearest_yes: dict = ABSENT
    time_limit_s: float = ABSENT
    complete: bool = ABSENT
    unsearched: list = ABSENT
    shape_tolerance: dict = ABSENT
    extra: dict = field(default_factory=dict)

    OPTIONAL = ("tolerance_deg", "required", "orients", "needs_no_pin", "pins_used", "fixed_pin_search",
                "moving_pin_search", "support_family", "family_certificate", "family_worst_member",
                "nearest_yes", "time_limit_s", "complete", "unsearched", "shape_tolerance")
    KEYS = ("mu_c", "friction", "belt_speed", "mu_s", "mechanics", "symmetry_order", "depth",
            "complete_depth", "beam", "plans", "rejected", "recommended", "warning", "stats",
            "initial_states", *OPTIONAL)
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
                   d.get("stats"), **optional_keys(d, cls.OPTIONAL), extra=unmodelled_keys(d, cls.KEYS))

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
        out.update(present({k: getattr(self, k) for k in self.OPTIONAL}))
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
                   unmodelled_keys(d, cls.KEYS))

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
