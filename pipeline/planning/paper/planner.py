"""The fixed-pins planner (spec section 6; the paper's section II.D).

An uncertain state is an arc of orientations and an interval of centroid
heights ``y_c`` above the fence. A global pin at height ``y_k`` meets it over
the contact-parameter range ``d = (y_k - y_c) / a``; it is allowed only if the
whole range keeps ``d_min <= |d| <= d_max`` on one side (no metastable
contacts) and lies within the stored maps. The maps used are every stored d
in the range plus the stored values bracketing it; the orientations used are
the theta_i grid points covering the arc plus one grid step either side. Each
point's outcome is the adjusted band its theta_f falls in (children: the
adjusted-band arcs hit, merged where they overlap); a ``miss`` leaves the
state as it was; a ``jammed`` outcome forbids the pin. A child's centroid
interval adds the range of dy over the grid points the state covers
(``com="covered"``, default) or, literally as spec section 6 says, the COM
interval of the whole band kernel K_j of each band hit (``com="kernel"``); K_j
often spans 100+ degrees of theta_i whose dy spread tens of millimetres, so
the literal rule makes nearly every second pin metastable.

``Planner`` answers the transitions of one state at one pin;
``SequenceSearch`` (what ``Planner.search`` runs) searches the pin
sequences. The search is complete up to ``depth``: every pin sequence is tried, and
sequences that reach a joint state (the states of all initial states) already
reached are merged. Plans are ranked by the number of final orientation sets
(clusters of overlapping final arcs over all branches of all initial
states), then by the safety margin (the smallest distance of any d from the
forbidden ranges), then by fewest pins, then by the total width of the final
sets.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from kernels.rollout import JAMMED, MISS, TRUNCATED

from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog, entry_part
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import arc_within, in_arc, merge_arcs  # noqa: F401 (merge_arcs: re-exported)
from pipeline.planning.core.plan_records import Step
from pipeline.planning.paper.bands import band_lookup, extract_bands
from pipeline.planning.core.settings import PlannerSettings, candidate_pins


@dataclass(frozen=True)


class State:
    """An orientation arc (degrees) and centroid interval (mm) a part may be in."""
    arc: tuple  # (start, width), degrees
    y_lo: float
    y_hi: float
    history: tuple = field(default=(), compare=False, hash=False)

    def key(self):
        """Rounded ``(start, width, y_lo, y_hi)``: states equal up to rounding share a key."""
        return (round(self.arc[0], 6), round(self.arc[1], 6), round(self.y_lo, 6), round(self.y_hi, 6))


@dataclass


class MapData:
    """One stored map (one d) with its bands, as the planner needs it."""
    d: float
    theta_i: np.ndarray
    theta_f: np.ndarray
    status: np.ndarray
    dy: np.ndarray
    bands: list
    lookup: np.ndarray


@dataclass


class Plan:
    """A paper-planner pin sequence with its final orientation sets and margin."""
    pins: tuple  # labels in order
    n_sets: int
    final_sets: list  # [(start, width)] merged final arcs
    margin: float
    branches: dict  # initial-state label -> list of step lists (plan_records.Step, one list per branch)
    sets_after: tuple = ()  # number of orientation sets after each pin (what each pin adds)
    n_dynamic: int = 0  # how many of the pins (the last ones) move

    def rank_key(self):
        """Sort key, best first: fewer final sets, larger margin, fewer pins, narrower sets."""
        return (self.n_sets, -round(self.margin, 9), len(self.pins),
                round(sum(w for _, w in self.final_sets), 6))

    def to_dict(self) -> dict:
        """The plan as a JSON-ready dict (the stored plan format)."""
        return {
            "pins": list(self.pins), "n_final_sets": self.n_sets,
            "final_sets": [{"start": s, "width": w} for s, w in self.final_sets],
            "margin": self.margin,
            "sets_after_each_pin": list(self.sets_after),
            "n_dynamic_pins": self.n_dynamic,
            "initial_states": {
                label: [[st.to_dict() for st in branch] for branch in branches]
                for label, branches in self.branches.items()},
        }


def load_maps(ds, threshold_T: float, factor_c: float) -> list[MapData]:
    """MapData for every d of a map set (dims ``(d, theta_i)``), sorted by d: the
    bands (:func:`~pipeline.planning.paper.bands.extract_bands`) of each map with its
    arrays and band lookup. The one reader of a map set's bands: the planner
    and the bands stage (``workflow.plan.shard_bands``) both call it."""
    out = []
    theta_i = np.asarray(ds["theta_i"].values, float)
    for d in sorted(float(x) for x in ds["d"].values):
        sub = ds.sel(d=d)
        tf, dy, st = sub["theta_f"].values, sub["dy"].values, sub["status"].values
        bands = extract_bands(theta_i, tf, dy, st, threshold_T, factor_c)
        out.append(MapData(d, theta_i, np.asarray(tf), np.asarray(st), np.asarray(dy), bands,
                           band_lookup(bands, theta_i.size)))
    return out


class Planner:
    """Global pins for one part, from its stored maps: the transitions of
    uncertain states through the pins (:meth:`transition`, by map lookup);
    :meth:`search` runs the breadth-first search over pin sequences
    (:class:`SequenceSearch`) on them.

    ``pins`` maps labels to heights (mm above the fence) of static pins.
    ``dynamic`` optionally adds moving pins: a dict ``label -> (y, v_pin)``
    (``y`` the pin's height when the part's centroid, had the part not been
    pushed, would pass the pin's station; ``v_pin`` the speed ratio
    v_pin / v_b) with ``dynamic_maps`` ``{v_pin: [MapData]}`` the maps stored
    at each speed. ``d_min``/``d_max`` and the margin apply to the offset of
    the pin's path from the centroid, ``|d| / sqrt(1 + v^2)`` for a moving pin.
    """

    def __init__(self, part: Part, maps: list[MapData], pins: dict, d_min: float, d_max: float,
                 com: str = "covered", coverage: str = "bracket", dynamic: dict | None = None,
                 dynamic_maps: dict | None = None):
        if not maps:
            raise PinfeedError("the planner needs at least one stored map")
        self.part = part
        self.maps = {0.0: maps}
        self.d_values = {0.0: np.array([m.d for m in maps])}
        self.pins = dict(pins)
        self.speeds = {label: 0.0 for label in self.pins}
        for label, (y, v) in (dynamic or {}).items():
            v = float(v)
            if v not in (dynamic_maps or {}):
                raise PinfeedError(f"dynamic pin {label} moves at v_pin/v_b = {v:g} but no maps "
                                   f"are stored at that speed; add it to sweep.v_pin")
            self.pins[label] = float(y)
            self.speeds[label] = v
        for v, vmaps in (dynamic_maps or {}).items():
            self.maps[float(v)] = vmaps
            self.d_values[float(v)] = np.array([m.d for m in vmaps])
        self.d_min, self.d_max = d_min, d_max
        self.com = com
        if coverage not in ("bracket", "nearest"):
            raise PinfeedError(f"unknown coverage {coverage!r}; use bracket or nearest")
        self.coverage = coverage
        self._cache = {}

    @property
    def static_labels(self) -> list[str]:
        """Labels of the static pins."""
        return [k for k, v in self.speeds.items() if v == 0.0]

    @property
    def dynamic_labels(self) -> list[str]:
        """Labels of the moving pins."""
        return [k for k, v in self.speeds.items() if v != 0.0]

    def initial_states(self) -> dict:
        """Resting states against the fence: label -> State (exact theta and y_c)."""
        states = {}
        for k, (theta, yc) in enumerate(self.part.stable_states(), start=1):
            states[f"state {k}"] = State((float(theta), 0.0), float(yc), float(yc))
        return states

    def _maps_for(self, d_lo, d_hi, v_pin=0.0):
        d_values, maps = self.d_values[v_pin], self.maps[v_pin]
        if d_lo < d_values[0] - 1e-9 or d_hi > d_values[-1] + 1e-9:
            return None
        if self.coverage == "nearest":
            lo = int(np.argmin(np.abs(d_values - d_lo)))
            hi = int(np.argmin(np.abs(d_values - d_hi)))
        else:
            lo = np.flatnonzero(d_values <= d_lo + 1e-9).max()
            hi = np.flatnonzero(d_values >= d_hi - 1e-9).min()
        return maps[lo: hi + 1]

    def transition(self, state: State, label: str):
        """Children of ``state`` at pin ``label`` and the step's margin, or None if forbidden."""
        key = (state.key(), label)
        if key not in self._cache:
            self._cache[key] = self._transition(state, label)
        result = self._cache[key]
        if result is None:
            return None
        children, margin, d_lo, d_hi = result
        y_pin, v_pin = self.pins[label], self.speeds[label]
        out = [State(arc, ylo, yhi,
                     state.history + (Step.reaching(label, y_pin, v_pin, (d_lo, d_hi), arc, (ylo, yhi)),))
               for arc, ylo, yhi in children]
        return out, margin

    def _transition(self, state: State, label: str):
        a = self.part.a
        y_pin, v_pin = self.pins[label], self.speeds[label]
        d_lo, d_hi = contact_parameter(y_pin, state.y_hi, a), contact_parameter(y_pin, state.y_lo, a)
        # The limits apply to the offset of the pin's path from the centroid,
        # perpendicular to the pin's motion relative to the belt (-1, v): for a
        # moving pin that is d / sqrt(1 + v^2) (see tests/kernels/test_dynamic.py).
        shrink = 1.0 / math.sqrt(1.0 + v_pin * v_pin)
        near, far = shrink * min(abs(d_lo), abs(d_hi)), shrink * max(abs(d_lo), abs(d_hi))
        if d_lo < 0.0 < d_hi or near < self.d_min - 1e-12 or far > self.d_max + 1e-12:
            return None
        maps = self._maps_for(d_lo, d_hi, v_pin)
        if maps is None:
            return None
        margin = min(near - self.d_min, self.d_max - far)
        hits = []  # (arc, com_min, com_max)
        for m in maps:
            step = float(np.median(np.diff(m.theta_i))) if m.theta_i.size > 1 else 360.0
            s, w = state.arc
            pad = step if self.coverage == "bracket" else 0.5 * step
            cover = np.flatnonzero(in_arc(m.theta_i, (s - pad) % 360.0, min(360.0, w + 2 * pad)))
            for i in cover:
                st = m.status[i]
                if st == JAMMED or st == TRUNCATED:
                    return None
                if st == MISS:
                    hits.append((state.arc, 0.0, 0.0))
                    continue
                b = m.bands[m.lookup[i]]
                if self.com == "kernel":
                    hits.append(((b.adj_start, b.adj_width), b.com_min, b.com_max))
                else:
                    hits.append(((b.adj_start, b.adj_width), m.dy[i], m.dy[i]))
        children = []
        for arc in merge_arcs([h[0] for h in hits]):
            inside = [h for h in hits if arc_within(h[0], arc)]
            children.append((arc, state.y_lo + min(h[1] for h in inside),
                             state.y_hi + max(h[2] for h in inside)))
        return children, margin, d_lo, d_hi

    def search(self, depth: int, keep: int = 10, dynamic_depth: int = 0,
               dynamic_beam: int = 50) -> list[Plan]:
        """The ``keep`` best plans, best first (:meth:`SequenceSearch.run`).

        Static pins: every sequence up to ``depth`` (complete; sequences that
        reach a joint state already reached are merged). Dynamic pins come
        after the static ones: up to ``dynamic_depth`` of them, appended to
        the ``dynamic_beam`` best plans of the previous level (a beam search:
        complete for one dynamic pin after the beam's plans, not beyond).
        """
        return SequenceSearch(self).run(depth, keep, dynamic_depth, dynamic_beam)


class SequenceSearch:
    """The breadth-first search over pin sequences through a planner's
    transitions.

    A node is a pin sequence with its joint state (for every initial state,
    in order, the states its branches may be in), its margin and the number
    of orientation sets after each pin. Each level follows every node of the
    previous one by every pin (:meth:`Planner.transition`); a joint state
    reached before is not expanded again.

    Parameters
    ----------
    planner : the :class:`Planner` whose pins and transitions are searched.
    """

    def __init__(self, planner: Planner):
        self.planner = planner

    def run(self, depth: int, keep: int = 10, dynamic_depth: int = 0, dynamic_beam: int = 50) -> list[Plan]:
        """The ``keep`` best plans, best first: every static sequence up to
        ``depth``, then up to ``dynamic_depth`` moving pins after the
        ``dynamic_beam`` best nodes of the previous level (:meth:`Planner.search`)."""
        planner = self.planner
        starts = planner.initial_states()
        labels = list(starts)
        root = ((), tuple((starts[lab],) for lab in labels), math.inf, ())
        seen = {self._joint_key(root[1])}
        nodes, frontier = [], [root]
        for _ in range(depth):
            frontier = self._expand(frontier, planner.static_labels, seen)
            nodes.extend(frontier)
        if dynamic_depth and planner.dynamic_labels:
            beam = [root] + nodes
            for _ in range(dynamic_depth):
                beam.sort(key=lambda node: self._node_rank(node))
                grown = self._expand(beam[:dynamic_beam], planner.dynamic_labels, seen)
                nodes.extend(grown)
                beam = grown
        plans = [self._plan(node, labels) for node in nodes]
        plans.sort(key=Plan.rank_key)
        return plans[:keep]

    def _expand(self, frontier, pin_labels, seen):
        """Every node of ``frontier`` followed by every pin in ``pin_labels``."""
        out = []
        for seq, joint, margin, sets_after in frontier:
            for pin in pin_labels:
                new_joint, new_margin = [], margin
                for branch_states in joint:
                    children = []
                    for st in branch_states:
                        res = self.planner.transition(st, pin)
                        if res is None:
                            break
                        children.extend(res[0])
                        new_margin = min(new_margin, res[1])
                    else:
                        new_joint.append(_dedupe(children))
                        continue
                    break
                if len(new_joint) != len(joint):
                    continue  # the pin is forbidden for some branch
                key = self._joint_key(new_joint)
                if key in seen:
                    continue
                seen.add(key)
                n_sets = len(merge_arcs([st.arc for states in new_joint for st in states]))
                out.append((seq + (pin,), tuple(new_joint), new_margin, sets_after + (n_sets,)))
        return out

    @staticmethod
    def _node_rank(node):
        seq, joint, margin, sets_after = node
        n_sets = sets_after[-1] if sets_after else len(joint)
        return (n_sets, -round(margin, 9) if math.isfinite(margin) else 0.0, len(seq))

    @staticmethod
    def _joint_key(joint):
        return tuple(tuple(sorted(st.key() for st in states)) for states in joint)

    def _plan(self, node, labels) -> Plan:
        seq, joint, margin, sets_after = node
        finals = merge_arcs([st.arc for states in joint for st in states])
        branches = {label: [list(st.history) for st in states] for label, states in zip(labels, joint)}
        n_dynamic = sum(1 for p in seq if self.planner.speeds[p] != 0.0)
        return Plan(seq, len(finals), finals, float(margin), branches, sets_after, n_dynamic)


def _dedupe(states):
    out, keys = [], set()
    for st in states:
        if st.key() not in keys:
            keys.add(st.key())
            out.append(st)
    return out


# ---------------------------------------------------------------------- a catalog part's planner


def catalog_part(cat: Catalog, name: str) -> Part:
    """The :class:`Part` stored in the catalog under ``name`` (id or name)."""
    e = cat.entries_for(name)[0]
    return entry_part(e)


def build_planner(cat: Catalog, name: str, settings: PlannerSettings, dynamic: bool = True):
    """The planner of one catalog part (``name``: its id or catalog name):
    static maps at the nominal value of ``settings.friction``, plus
    (``dynamic``) the maps of every moving-pin speed of the search settings."""
    search, bc = settings.search, settings.bands
    part = catalog_part(cat, name)
    ds = cat.query(name, model=search.model, mu_c=settings.friction.nominal)
    selection = ds.attrs["selection"]
    mu_used = float(ds["mu_c"][0])
    maps = load_maps(ds.isel(mu_c=0).load(), bc.threshold_T, bc.factor_c)
    static = candidate_pins(part, search.pins)
    speeds = list(search.dynamic_speeds) if dynamic else []
    dynamic_maps = {}
    for v in speeds:
        dv = cat.query(name, model=search.model, mu_c=mu_used, v_pin=v)
        if float(dv["mu_c"][0]) != mu_used:
            raise PinfeedError(f"{name}: the maps at v_pin/v_b = {v:g} have no mu_c = {mu_used:g} (the "
                               f"static maps' friction); add it to the sweep or re-run the workflow")
        dv = dv.isel(mu_c=0).load()
        dynamic_maps[v] = load_maps(dv, bc.threshold_T, bc.factor_c)
    moving = {dynamic_label(label, v): (y, v) for label, y in static.items() for v in speeds}
    planner = Planner(part, maps, static, search.d_min, search.d_max,
                      coverage=search.coverage, dynamic=moving,
                      dynamic_maps=dynamic_maps)
    return part, planner, mu_used, selection


def dynamic_label(static_label: str, v_pin: float) -> str:
    """Label of a moving pin: its static label and speed ratio, e.g. ``P23v-2``."""
    return f"{static_label}v{v_pin:+g}"


def paper_depth(search) -> int:
    """Depth of the paper-mode planner: ``paper_depth`` of the search settings,
    at most its ``depth`` (the sensor planner reads the stored tight plans instead)."""
    return int(min(search.depth, search.paper_depth))
