"""Tight plans of given pin sequences: their carried sets by tight state
propagation (``propagate.py``).

Every initial resting state starts as its uncertainty box. A pin is allowed
for a state only if the whole d range of the box stays on one side of the
centroid (the pin never passes it on either side) and no jam is reachable;
``d_min <= |d| <= d_max`` (for a moving pin: the offset of the pin's path,
``|d| / sqrt(1 + v^2)``) sets the safety margin, and is a hard rule only with
``hard_limits``; a pin that the state misses leaves it as it is (that is
part of the propagation). A pin sequence is the same for every initial state.

``TightPlanner`` pushes one state set through one pin (``transition``, with
its stored outcomes and a cache); ``SequenceFollower`` (what
``TightPlanner.follow`` uses) carries the sets of one given sequence of fixed
or moving pins through those transitions and builds its ``TightPlan``; the
complete search (``complete.py``) chooses the sequences.

``TightPlan.rank_key`` orders propagated plans by (1) the number of final
orientation sets, counted modulo the part's rotational symmetry; (2) the
fraction of successful trials once verified; (3) fewest pins; (4) fewest
steps whose box straddles a jump; (5) the safety margin in d; (6) the total
width of the final sets. ``plan.py`` ranks verified plans by the
orientation verdict instead.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import merge_arcs, merge_modulo
from pipeline.planning.core.claim import Claim
from pipeline.planning.core.plan_records import Step
from pipeline.planning.core.settings import KernelSettings, as_kernel_settings
from pipeline.planning.tight.propagate import (UNRESOLVED, OutcomeLattice, StateSet, Tolerances, Uncertainty,
                        initial_state_sets, propagate)


@dataclass(frozen=True)
class Pin:
    """A candidate pin: label, height above the fence (mm), speed ratio v_pin / v_b."""
    label: str
    y: float
    v_pin: float = 0.0


@dataclass
class TightPlan:
    """A pin sequence with the sets it carries for every initial state."""
    pins: tuple
    pin_heights_mm: tuple
    pin_speeds: tuple
    final_sets: list  # merged final arcs [(start, width)] in [0, 360)
    n_sets: int  # counted modulo the part's rotational symmetry
    margin: float
    jumps: int  # steps whose box straddled a jump
    branches: dict  # initial-state label -> list of branches (each a list of plan_records.Step)
    initial: dict  # initial-state label -> StateSet
    sets_after: tuple = ()
    verification: dict | None = None  # filled in by verify
    carried: str = "propagated"  # how the carried sets were found: "propagated" or "sampled"
    claim: Claim | None = None  # the plan's one claim, set once it is verified on held-out trials

    @property
    def n_dynamic(self) -> int:
        """How many of the plan's pins move."""
        return sum(1 for v in self.pin_speeds if v != 0.0)

    def success_fraction(self) -> float:
        """Fraction of verification trials that ended in the predicted sets (0 if not verified)."""
        if not self.verification:
            return 0.0
        t = self.verification["trials"]
        return self.verification["successes"] / t if t else 0.0

    def rank_key(self):
        """Sort key, best first: fewer final sets, more successes, fewer pins and jumps, larger margin."""
        return (self.n_sets, -round(self.success_fraction(), 6), len(self.pins), self.jumps,
                -round(self.margin, 9), round(sum(w for _, w in self.final_sets), 6))

    def predicted_sets(self, label: str) -> list:
        """Final arcs predicted for one initial state."""
        return merge_arcs([br[-1].band.pair if br else self.initial[label].arc
                           for br in self.branches[label]])

    def to_dict(self) -> dict:
        """The plan as a JSON-ready dict (the stored plan format)."""
        return {
            "mode": "tight",
            "pins": list(self.pins), "pin_heights_mm": list(self.pin_heights_mm),
            "pin_speeds": list(self.pin_speeds),
            "n_final_sets": self.n_sets,
            "final_sets": [{"start": s, "width": w} for s, w in self.final_sets],
            "margin": self.margin if math.isfinite(self.margin) else None, "jump_steps": self.jumps,
            "sets_after_each_pin": list(self.sets_after),
            "n_dynamic_pins": self.n_dynamic,
            "initial_sets": {k: v.to_dict() for k, v in self.initial.items()},
            "initial_states": {label: [[st.to_dict() for st in br] for br in brs]
                               for label, brs in self.branches.items()},
            "carried_sets_kind": self.carried,
            "claim": None if self.claim is None else self.claim.to_dict(),
            "verification": self.verification,
        }


@dataclass
class SearchStats:
    """Counters of the propagation: transitions, rollouts, nodes, time (s), pruning."""
    transitions: int = 0
    rollouts: int = 0
    nodes: int = 0
    seconds: float = 0.0
    pruned_branching: int = 0
    unresolved: int = 0


class TightPlanner:
    """The transitions of state sets through the pins, for one part under a
    stated uncertainty (:meth:`transition`); :meth:`follow` carries one pin
    sequence through them (:class:`SequenceFollower`).

    Parameters
    ----------
    part : the part.
    pins : static candidate pins ``{label: height_mm}``.
    mu_c : one friction value (widened by the verify stage's 2 sigma) or a
        range ``(lo, hi)`` that every plan must cover.
    moving : optional moving pins ``{label: (height_mm, v_pin)}``.
    lattices : optional ``{v_pin: OutcomeLattice}`` holding stored outcomes.
    kernel : the rollout kernel's step (a ``KernelSettings``; ``None``: its defaults).
    max_branches : a node whose state has more branches than this is dropped
        (reported in ``stats.pruned_branching``).
    belt_speed : belt speed in mm/s (the part in mm): plan with the dynamic
        model (``kernels.dynamic``) at that speed and belt friction ``mu_s``
        instead of the quasi-static ``model``; ``None`` (default) is
        quasi-static.
    mu_s : belt friction for ``belt_speed``.
    hard_limits : forbid pins whose d range leaves ``d_min <= |d| <= d_max``
        (the paper's rule). By default these limits only set the margin
        (negative inside them): the propagation itself sees what makes small
        or large ``|d|`` risky (a jump between turning ways, a grazing miss) and
        branches there, and verification replays every plan.
    """

    def __init__(self, part: Part, pins: dict, d_min: float, d_max: float, mu_c,
                 pin_radius: float, model: str = "minpower", uncertainty: Uncertainty = Uncertainty(),
                 tolerances: Tolerances = Tolerances(), moving: dict | None = None,
                 lattices: dict | None = None, kernel: KernelSettings | None = None, max_branches: int = 4,
                 hard_limits: bool = False, belt_speed: float | None = None, mu_s: float = 0.5):
        if not pins:
            raise PinfeedError("the planner needs at least one candidate pin")
        if belt_speed is not None:
            from pipeline.checks import check_belt
            check_belt(part, belt_speed, mu_s)
        self.belt_speed = None if belt_speed is None else float(belt_speed)
        self.mu_s = float(mu_s)
        self.part, self.model, self.pin_radius = part, model, float(pin_radius)
        self.d_min, self.d_max = float(d_min), float(d_max)
        self.mu_c, self.unc, self.tol = mu_c, uncertainty, tolerances
        self.pins = {lab: Pin(lab, float(y), 0.0) for lab, y in pins.items()}
        for lab, (y, v) in (moving or {}).items():
            self.pins[lab] = Pin(lab, float(y), float(v))
        kernel = as_kernel_settings(kernel)  # plans/plan.py still passes the kernel's dict
        self.lattices = dict(lattices or {})
        for v in {p.v_pin for p in self.pins.values()}:
            if v not in self.lattices:
                self.lattices[v] = OutcomeLattice(part, model, pin_radius, v,
                                                  kernel.ds_max, kernel.tol,
                                                  belt_speed=self.belt_speed, mu_s=self.mu_s)
        for v, lattice in self.lattices.items():
            if lattice.belt_speed != self.belt_speed or (
                    self.belt_speed is not None and lattice.mu_s != self.mu_s):
                raise PinfeedError(f"the stored outcomes at v_pin {v:g} are for another belt "
                                   f"(speed {lattice.belt_speed}, mu_s {lattice.mu_s:g}) than the "
                                   f"planner's ({self.belt_speed}, {self.mu_s:g})")
        self.max_branches = int(max_branches)
        self.hard_limits = bool(hard_limits)
        self.order = part.symmetry_order()
        self.stats = SearchStats()
        self._cache: dict = {}

    def initial_states(self) -> dict[str, StateSet]:
        """Initial state label -> the part's resting state set, with the planner's uncertainties."""
        return initial_state_sets(self.part, self.mu_c, self.unc)

    def transition(self, state: StateSet, label: str):
        """``(children, margin, d_lo, d_hi, jump)`` of ``state`` at pin ``label``,
        or ``None`` if the pin is forbidden for it."""
        key = (state, label)
        if key not in self._cache:
            self._cache[key] = self._transition(state, self.pins[label])
        return self._cache[key]

    def _transition(self, state: StateSet, pin: Pin):
        a, h = self.part.a, self.unc.pin_halfwidth
        d_lo, d_hi = contact_parameter(pin.y - h, state.y_hi, a), contact_parameter(pin.y + h, state.y_lo, a)
        shrink = 1.0 / math.sqrt(1.0 + pin.v_pin * pin.v_pin)
        near, far = shrink * min(abs(d_lo), abs(d_hi)), shrink * max(abs(d_lo), abs(d_hi))
        if d_lo < 0.0 < d_hi:
            return None  # the pin may pass on either side of the centroid: metastable
        if self.hard_limits and (near < self.d_min - 1e-12 or far > self.d_max + 1e-12):
            return None
        lattice = self.lattices[pin.v_pin]
        before = lattice.n_computed
        res = propagate(state, pin.y, self.part, lattice, h, self.tol)
        self.stats.transitions += 1
        self.stats.rollouts += lattice.n_computed - before
        if res is UNRESOLVED:
            self.stats.unresolved += 1
            return None
        if res is None:
            return None
        # A pin that misses the whole box is no risk, wherever it stands.
        margin = min(near - self.d_min, self.d_max - far) if res.touched else math.inf
        return res.children, margin, d_lo, d_hi, res.jump

    def follow(self, seq) -> TightPlan | None:
        """The tight plan of one given pin sequence (its carried sets, no search),
        or ``None`` if the propagation forbids one of its pins for some branch
        (a reachable jam, a pin passing a centroid on both sides, too many
        branches or jumps); see :class:`SequenceFollower`."""
        return SequenceFollower(self).follow(seq)


class SequenceFollower:
    """One pin sequence followed through a planner's transitions, and the
    :class:`TightPlan` it ends in.

    The joint state holds, for every initial state (in order), its branches:
    each a state set with the steps that led to it. A pin moves every branch
    through :meth:`TightPlanner.transition`; it is forbidden for the whole
    sequence when it is forbidden for one branch, or when an initial state
    ends with more than the planner's ``max_branches`` branches (counted in
    its ``stats.pruned_branching``).

    Parameters
    ----------
    planner : the :class:`TightPlanner` whose pins, transitions and symmetry are used.
    """

    def __init__(self, planner: TightPlanner):
        self.planner = planner

    def follow(self, seq) -> TightPlan | None:
        """The tight plan of the pin sequence ``seq`` (labels), or ``None`` if
        one of its pins is forbidden for some branch."""
        starts = self.planner.initial_states()
        node = self._root(starts)
        for label in seq:
            node = self._step(node, label)
            if node is None:
                return None
        return self._plan(node, starts)

    @staticmethod
    def _root(starts):
        return ((), tuple(((st, ()),) for st in starts.values()), math.inf, 0, ())

    def _step(self, node, label):
        """``node`` followed by pin ``label`` (``None`` if forbidden)."""
        seq, joint, margin, jumps, sets_after = node
        child = self._apply(joint, label)
        if child is None:
            return None
        new_joint, step_margin, step_jumps = child
        return (seq + (label,), new_joint, min(margin, step_margin), jumps + step_jumps,
                sets_after + (self._count_sets(new_joint),))

    def _apply(self, joint, label):
        """The joint state after pin ``label``, or None if forbidden for a branch."""
        planner = self.planner
        pin = planner.pins[label]
        new_joint, margin, jumps = [], math.inf, 0
        for branches in joint:
            children = {}
            for state, history in branches:
                res = planner.transition(state, label)
                if res is None:
                    return None
                kids, m, d_lo, d_hi, jump = res
                margin, jumps = min(margin, m), jumps + int(jump)
                for kid in kids:
                    step = Step.carried_by(label, pin.y, pin.v_pin, (d_lo, d_hi), kid)
                    children.setdefault(kid, history + (step,))
            if len(children) > planner.max_branches:
                planner.stats.pruned_branching += 1
                return None
            new_joint.append(tuple(sorted(children.items())))
        return tuple(new_joint), margin, jumps

    def _count_sets(self, joint) -> int:
        return len(merge_modulo([st.arc for branches in joint for st, _ in branches], self.planner.order))

    def _plan(self, node, starts) -> TightPlan:
        seq, joint, margin, jumps, sets_after = node
        finals = merge_arcs([st.arc for branches in joint for st, _ in branches])
        branches = {label: [list(history) for _, history in brs]
                    for label, brs in zip(starts, joint)}
        pins = [self.planner.pins[p] for p in seq]
        return TightPlan(seq, tuple(p.y for p in pins), tuple(p.v_pin for p in pins), finals,
                         self._count_sets(joint), float(margin), int(jumps), branches,
                         dict(starts), sets_after)
