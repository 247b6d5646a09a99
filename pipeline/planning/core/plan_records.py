"""Typed records of one plan in a stored plan file (``RESULTS/plans/NAME.json``).

An arc of orientations (:class:`Arc`), a carried set of states
(:class:`State`), a nominal resting state (:class:`RestingState`), what one
pin did to one branch (:class:`Step`), the replayed trials
(:class:`VerificationRow`, :class:`Verification`) and one pin sequence with
all it does (:class:`Plan`). The file-level records that hold them, and the
file's schema, are in :mod:`pipeline.planning.core.types`.

The planner builds these records itself (``plans/entry.py``) and the steps
after the search (family certificate, nearest "yes", speed limits, shape
tolerance) take them and add to them; a plan is turned into a dict only at
the edge, to be written or printed. A field a stored dict may lack has the
default :data:`ABSENT` (falsy), told apart from a stored ``null`` (``None``).

Each record reads a stored dict and writes it back unchanged:
``Record.from_dict(d).to_dict() == d`` for every plan the current code
writes, and ``Record.from_dict(r.to_dict()) == r``. Keys a record does not
know are kept in its ``extra`` (:func:`unmodelled_keys`) and written back as
they were, so a file with more keys still round-trips.

Units: angles in degrees (orientations in [0, 360)), heights and positions
in mm, ``d`` (pin offset from the centroid over the part's radius ``a``)
dimensionless, belt speed in mm/s, pin speeds as the ratio v_pin / v_belt.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from pipeline.planning.core.claim import Claim


class _Absent:
    """The value of a record's field whose key the stored dict does not have
    (``None`` is a stored ``null``). Falsy; one object, also after pickling."""
    __slots__ = ()

    def __bool__(self) -> bool:
        return False

    def __repr__(self) -> str:
        return "ABSENT"

    def __reduce__(self):
        return "ABSENT"


ABSENT = _Absent()


def optional_keys(d: dict, keys) -> dict:
    """``{key: d[key]}`` for ``keys``, :data:`ABSENT` where ``d`` lacks the key: a record's optional fields."""
    return {k: d.get(k, ABSENT) for k in keys}


def present(values: dict) -> dict:
    """``values`` less the :data:`ABSENT` ones: what a record writes back."""
    return {k: v for k, v in values.items() if v is not ABSENT}


def unmodelled_keys(d: dict, known) -> dict:
    """The keys of ``d`` a record does not model (not in ``known``), kept as
    they are: the record's ``extra``, written back unchanged."""
    return {k: v for k, v in d.items() if k not in known}


def _pair(values) -> tuple:
    """A stored ``[lo, hi]`` as a tuple."""
    return (values[0], values[1])


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
    def of_set(cls, state_set) -> "State":
        """The record of a ``tight.propagate.StateSet`` (read by its fields
        ``start``, ``width``, ``y_lo``, ``y_hi``, ``mu_lo`` and ``mu_hi``)."""
        return cls(Arc(state_set.start, state_set.width), (state_set.y_lo, state_set.y_hi),
                   (state_set.mu_lo, state_set.mu_hi))

    @classmethod
    def from_dict(cls, d: dict) -> "State":
        """The record of a stored dict (as read from the plan file)."""
        return cls(Arc.from_dict(d["arc"]), _pair(d["y_c"]), _pair(d["mu_c"]), unmodelled_keys(d, cls.KEYS))

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
    """What one pin did to one branch of one initial state: the one step
    record, built by both planners (:meth:`carried_by` in the tight planner,
    :meth:`reaching` in the paper-mode planner) and read back from a stored
    plan (:meth:`from_dict`).

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
    def carried_by(cls, pin: str, y_pin: float, v_pin: float, d_range, after) -> "Step":
        """A tight planner's step: ``after`` is the state set carried after the
        pin (a ``tight.propagate.StateSet``, read by its fields ``start``,
        ``width``, ``y_lo``, ``y_hi``, ``mu_lo`` and ``mu_hi``); its arc is the
        step's band, its centroid heights the step's COM interval."""
        carried = State.of_set(after)
        return cls(pin, y_pin, v_pin, tuple(d_range), carried.arc, carried.y_c, carried)

    @classmethod
    def reaching(cls, pin: str, y_pin: float, v_pin: float, d_range, arc, com_interval) -> "Step":
        """A paper-mode planner's step: the orientation ``arc`` ``(start, width)``
        (deg) and the ``com_interval`` ``(lo, hi)`` (mm) it reaches; it carries
        no state set."""
        return cls(pin, y_pin, v_pin, tuple(d_range), Arc(arc[0], arc[1]), tuple(com_interval))

    @classmethod
    def from_dict(cls, d: dict) -> "Step":
        """The record of a stored dict (as read from the plan file)."""
        carried = d.get("carried")
        return cls(d["pin"], d["y_pin"], d.get("v_pin"), _pair(d["d_range"]), Arc.from_dict(d["band"]),
                   _pair(d["com_interval"]), State.from_dict(carried) if carried is not None else None,
                   unmodelled_keys(d, cls.KEYS))

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
                   unmodelled_keys(d, cls.KEYS))

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
    friction ``mu_s``.

    A tight plan's held-out verification also has: ``held_out`` (True) and
    its ``seed``; ``orientation``, the verdict of ``orient.judge`` on those
    trials; ``truncation_sigma``, where the perturbations were cut;
    ``selection``, the verdict on the trials that chose the plan; with a
    support family, ``support_family`` (the members drawn) and
    ``family_check`` (the worst-member check); for the recommended plan,
    ``untruncated`` (its replay on untruncated normals). :data:`ABSENT` when
    the stored dict lacks the key."""
    trials: int
    successes: int
    failures: int
    rows: tuple
    model: str | None = None
    belt_speed: float | None = None
    mu_s: float | None = None
    held_out: bool | None = ABSENT
    seed: int | None = ABSENT
    orientation: dict | None = ABSENT
    truncation_sigma: float | None = ABSENT
    selection: dict | None = ABSENT
    support_family: dict | None = ABSENT
    family_check: dict | None = ABSENT
    untruncated: dict | None = ABSENT
    extra: dict = field(default_factory=dict)

    OPTIONAL = ("held_out", "seed", "orientation", "truncation_sigma", "selection", "support_family",
                "family_check", "untruncated")
    KEYS = ("trials", "successes", "failures", "rows", "model", "belt_speed", "mu_s", *OPTIONAL)

    @classmethod
    def from_dict(cls, d: dict) -> "Verification":
        """The record of a stored dict (as read from the plan file)."""
        return cls(d["trials"], d["successes"], d["failures"],
                   tuple(VerificationRow.from_dict(r) for r in d["rows"]), d.get("model"),
                   d.get("belt_speed"), d.get("mu_s"), **optional_keys(d, cls.OPTIONAL),
                   extra=unmodelled_keys(d, cls.KEYS))

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
        out.update(present({k: getattr(self, k) for k in self.OPTIONAL}))
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
    (``None``; then not written back).

    A verified tight plan also has its one ``claim``
    (:class:`~pipeline.planning.core.claim.Claim`, ``None`` before it is
    verified), ``carried_sets_kind`` (how its carried sets were found:
    ``"propagated"`` or ``"sampled"``) and, once the steps after the search
    add them, ``speed_limit`` (``pinfeed speed``'s record) and, for a
    support family, ``family_certificate``. :data:`ABSENT` when the stored
    dict lacks the key (a file written before claims kept the carried sets'
    kind as a string ``claim``: it stays in ``extra``)."""
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
    carried_sets_kind: str = ABSENT
    claim: Claim | None = ABSENT
    speed_limit: dict = ABSENT
    family_certificate: dict = ABSENT
    extra: dict = field(default_factory=dict)

    OPTIONAL = ("carried_sets_kind", "claim", "speed_limit", "family_certificate")
    KEYS = ("mode", "pins", "pin_heights_mm", "pin_speeds", "n_final_sets", "final_sets", "margin",
            "jump_steps", "sets_after_each_pin", "n_dynamic_pins", "initial_sets", "initial_states",
            "verification", *OPTIONAL)

    @classmethod
    def from_dict(cls, d: dict) -> "Plan":
        """The record of a stored dict (as read from the plan file)."""
        opt = lambda k: tuple(d[k]) if d.get(k) is not None else None  # noqa: E731
        ver = d.get("verification")
        sets = d.get("initial_sets")
        branches = d.get("initial_states")
        optional, extra = optional_keys(d, cls.OPTIONAL), unmodelled_keys(d, cls.KEYS)
        if isinstance(optional["claim"], str):  # an older file: the carried sets' kind
            extra["claim"], optional["claim"] = optional["claim"], ABSENT
        elif optional["claim"]:
            optional["claim"] = Claim.from_dict(optional["claim"])
        return cls(tuple(d["pins"]), tuple(Arc.from_dict(s) for s in d["final_sets"]), d.get("n_final_sets"),
                   d.get("margin"), opt("sets_after_each_pin"), d.get("n_dynamic_pins"),
                   _branches_in(branches) if branches is not None else None, d.get("mode"), opt("pin_heights_mm"),
                   opt("pin_speeds"), d.get("jump_steps"),
                   {k: State.from_dict(v) for k, v in sets.items()} if sets is not None else None,
                   Verification.from_dict(ver) if ver is not None else None, **optional, extra=extra)

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
        optional = present({k: getattr(self, k) for k in self.OPTIONAL})
        if optional.get("claim"):
            optional["claim"] = self.claim.to_dict()
        return {**out, **optional, **self.extra}

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
