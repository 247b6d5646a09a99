"""The worst-member search: the member of a family that lies farthest outside a plan's set.

A finite sample of a family does not contain the family's edge, and the edge
is where a plan breaks. This module searches a family's parameter space
(:mod:`pipeline.planning.family.member_spaces`) for the member whose final
orientations lie farthest outside the plan's set.

The *objective* of a member is the largest signed angular distance (degrees)
of its final orientations outside the plan's set, over the resting states'
nominal rollouts and every corner of the verification's perturbation box
(positive outside the set, negative inside: a member deep inside scores the
depth of its nearest final, so the optimiser is not lost on a plateau). A
jam scores ``JAM_SCORE``. Physics goes through the public rollout API
(``verify.replay``) only.

The search is a seeded multi-start Nelder-Mead (``scipy.optimize``) on the
raw parameters with a penalty outside the feasible set, started from the
space's geometric corners and from seeded random members. It stops as soon
as a member breaks the plan or the budget (rollout evaluations of one
member) is spent. A plan of many pins has many corners (``2**(3 + pins)``
per resting state); the search then scores members on at most
``SEARCH_CORNERS`` of them per state (:func:`coarse_rows`: the pins'
diagonal, then seeded random ones) and the member it ends with on all of
them. A member that breaks a plan on that subset breaks it on the full probe
too; one that only breaks it on corners left out is found only if it is the
member the search ends with.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from pipeline.config import schema_default
from pipeline.errors import PinfeedError
from pipeline.parts.support import Support
from pipeline.planning.claims.replay import replay
from pipeline.planning.claims.trials import corner_inputs
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import VerifySettings, nominal_friction
from pipeline.planning.family.member_spaces import MemberSpace
from pipeline.progress import Heartbeat

DEFAULT_BUDGET = schema_default("planner", "worst_member_budget")  # member evaluations per search
JAM_SCORE = 180.0  # deg: a jam is as far outside the set as anything can be
RANDOM_STARTS = 6  # seeded random members besides the geometric corners
RANDOM_SHARE = 0.5  # of the budget spent on the starts (corners, then seeded random members)
SEARCH_CORNERS = 64  # corners per resting state a member is scored on during the search
KERNEL_STEPS = ("ds_max", "tol")  # the kernel's step settings a replay takes
_PENALTY = 1.0e3


def kernel_steps(kernel) -> dict:
    """The kernel's step settings of ``kernel`` (``SearchSettings.kernel_settings``,
    or None) as a replay's keyword arguments: ``ds_max`` and ``tol`` where given."""
    return {k: v for k, v in (kernel or {}).items() if k in KERNEL_STEPS}


# --------------------------------------------------------------------------- the objective

def probe_inputs(part, mu_c, n_pins: int, verify: VerifySettings) -> tuple[tuple, np.ndarray]:
    """The probe's starts for plans of ``n_pins`` pins: every resting state of
    ``part`` at the middle friction, then at every corner of the perturbation
    box (``verify``'s perturbation); ``((theta, y_c, mu, offsets), each
    state's nominal row)``."""
    rows = []
    for theta, y_c in resting_states(part).values():
        rows.append((np.array([theta]), np.array([y_c]), np.array([nominal_friction(mu_c)]),
                     np.zeros((1, n_pins))))
        rows.append(corner_inputs(theta, y_c, mu_c, n_pins, verify.as_dict()))
    inputs = tuple(np.concatenate([r[k] for r in rows]) for k in range(4))
    sizes = np.array([r[0].size for r in rows])
    return inputs, np.concatenate([[0], np.cumsum(sizes)[:-1]])[0::2]


def coarse_rows(offsets: np.ndarray, nominal: np.ndarray, corners: int = SEARCH_CORNERS) -> np.ndarray:
    """The probe rows a search scores members on: per resting state its
    nominal row and at most ``corners`` of its corners, namely every corner
    whose pins are all offset the same way (the box's diagonal in the pins'
    offsets) and then seeded random ones; all rows when a state has no more.

    A member's objective on these rows is at most its objective on the full
    probe (a maximum over a subset), so a member that breaks a plan here
    breaks it on the full probe too."""
    rng = np.random.default_rng(17)
    ends = [*nominal[1:], offsets.shape[0]]
    picked = []
    for start, end in zip(nominal, ends):
        corner = np.arange(start + 1, end)
        picked.append([start])
        if corner.size <= corners:
            picked.append(corner)
            continue
        offs = offsets[corner]
        diagonal = corner[offs.min(axis=1) == offs.max(axis=1)][:corners]
        rest = np.setdiff1d(corner, diagonal)
        extra = rng.choice(rest, size=max(0, corners - diagonal.size), replace=False)
        picked.append(np.sort(np.concatenate([diagonal, extra])))
    return np.concatenate(picked).astype(int)


@dataclass
class PlanProbe:
    """What a member is scored on: a plan's pins and the trials that probe it
    (``verify``: the verification's trials, whose perturbation box it replays)."""

    part: object
    heights: tuple
    mu_c: object
    verify: VerifySettings
    pin_radius: float = 3.0
    model: str = "minpower"
    kernel: dict = field(default_factory=dict)
    speeds: tuple = ()
    inputs: tuple = field(init=False)
    nominal: np.ndarray = field(init=False)
    coarse: tuple | None = field(init=False)

    def __post_init__(self):
        self.inputs, self.nominal = probe_inputs(self.part, self.mu_c, len(self.heights), self.verify)
        rows = coarse_rows(self.inputs[3], self.nominal, SEARCH_CORNERS)
        self.coarse = None if rows.size == self.inputs[0].size else tuple(x[rows] for x in self.inputs)

    def finals(self, support: Support | None, inputs=None) -> tuple[np.ndarray, np.ndarray]:
        """``(theta_f, jammed)`` of every probe trial resting on ``support``."""
        th, yc, mu, offs = self.inputs if inputs is None else inputs
        speeds = list(self.speeds) or [0.0] * len(self.heights)
        tf, _, jam, _ = replay(self.part, list(self.heights), speeds, th, yc, mu, offs, self.pin_radius, self.model,
                               **kernel_steps(self.kernel), support=np.zeros(th.size, int), supports=[support])
        return tf, jam != ""


def outside(theta, arc: tuple, period: float = 360.0) -> np.ndarray:
    """Signed angular distance (deg) of each ``theta`` outside the arc
    ``(start, width)``: positive outside, minus the distance to the nearer
    end inside."""
    start, width = arc
    rel = np.mod(np.asarray(theta, float) - start, period)
    inside = rel <= width
    beyond = np.minimum(rel - width, period - rel)
    return np.where(inside, -np.minimum(rel, width - rel), beyond)


def score(probe: PlanProbe, support, arc, period: float, coarse: bool = False) -> tuple[float, np.ndarray]:
    """``(objective, finals)`` of one member (see the module docstring), on the
    full probe or (``coarse``) on its :func:`coarse_rows`."""
    rows = getattr(probe, "coarse", None) if coarse else None  # a probe without a subset: all rows
    tf, jam = probe.finals(support) if rows is None else probe.finals(support, rows)
    dist = np.where(jam, JAM_SCORE, outside(tf, arc, period))
    return float(dist.max()), tf


# --------------------------------------------------------------------------- the search

@dataclass
class WorstMember:
    """The member a search found farthest outside the set."""

    support: Support
    params: dict
    objective: float
    finals: np.ndarray
    evaluations: int
    source: str
    nominal: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    @property
    def breaks(self) -> bool:
        """True when some final lies outside the set."""
        return self.objective > 0.0

    def to_dict(self) -> dict:
        """JSON-ready: the member, its parameters, how far outside, its nominal finals."""
        return {"member": self.support.to_dict(), "parameters": self.params,
                "outside_deg": round(self.objective, 4), "breaks": self.breaks,
                "nominal_finals_deg": np.round(self.finals[self.nominal], 3).tolist(),
                "probe_finals": int(self.finals.size), "evaluations": self.evaluations,
                "found_by": self.source}


class _Stop(Exception):
    pass


def check_budget(budget) -> int:
    """The search budget as an int >= 1, or a one-line :class:`PinfeedError`."""
    try:
        n = int(budget)
    except (TypeError, ValueError):
        n = 0
    if n < 1:
        raise PinfeedError(f"a search with no budget: planner.worst_member_budget is {budget!r}; "
                           f"give the number of member evaluations, at least 1 (e.g. {DEFAULT_BUDGET})")
    return n


def search_worst_member(probe: PlanProbe, space: MemberSpace, arc: tuple, period: float = 360.0,
                        budget: int = DEFAULT_BUDGET, seed: int = 0,
                        stop_when_broken: bool = True, beat: Heartbeat | None = None) -> WorstMember:
    """The member of ``space`` whose probe finals lie farthest outside ``arc``
    (``(start, width)`` degrees) within ``budget`` member evaluations.

    Every fixed member is scored; then, for each continuous space, its
    geometric corners and ``RANDOM_STARTS`` seeded random members are scored
    and Nelder-Mead runs from the highest-scoring starts until the budget is
    spent (the budget is shared between the spaces). ``beat`` (a
    :class:`~pipeline.progress.Heartbeat` counting evaluations) is ticked
    after each one."""
    budget = check_budget(budget)
    best = {"obj": -np.inf}
    used = [0]
    beat = (beat or Heartbeat("", budget)).start()

    def keep(obj, tf, support, params, source):
        beat.tick(used[0])
        if obj > best["obj"]:
            best.update(obj=obj, tf=tf, support=support, params=params, source=source)

    for m in space.fixed:
        obj, tf = score(probe, None if m.is_uniform else m, arc, period, coarse=True)
        used[0] += 1
        keep(obj, tf, m, {"member": m.label}, "listed member")
    rng = np.random.default_rng([int(seed), 33])
    share = max(1, (budget - used[0]) // max(1, len(space.spaces)))
    for space_k in space.spaces:
        _search_space(probe, space_k, arc, period, share, rng, keep, used, stop_when_broken, best)
        if stop_when_broken and best["obj"] > 0:
            break
    if best["obj"] == -np.inf:
        raise PinfeedError(f"support family {space.label!r} has no member to search")
    if getattr(probe, "coarse", None) is not None:  # the member found, on the full probe (only higher)
        member = None if getattr(best["support"], "is_uniform", False) else best["support"]
        best["obj"], best["tf"] = score(probe, member, arc, period)
    beat.finish(used[0], "a member breaks the plan" if best["obj"] > 0 else "")
    return WorstMember(best["support"], best["params"], float(best["obj"]), best["tf"], used[0],
                       best["source"], probe.nominal)


def _search_space(probe, space, arc, period, budget, rng, keep, used, stop_when_broken, best):
    """Multi-start Nelder-Mead over one continuous space (see :func:`search_worst_member`)."""
    spent = [0]

    def f(x, source):
        bad = space.violation(x)
        if bad > 0:
            return _PENALTY + bad
        if spent[0] >= budget:
            raise _Stop
        spent[0] += 1
        used[0] += 1
        support = space.member(x, f"worst {space.kind} member")
        obj, tf = score(probe, support, arc, period, coarse=True)
        keep(obj, tf, support, space.params(x), source)
        if stop_when_broken and obj > 0:
            raise _Stop
        return -obj

    starts = [(x, "geometric corner") for x in space.corners()]
    n_random = max(RANDOM_STARTS, int(RANDOM_SHARE * budget) - len(starts))
    starts += [(x, "random start") for x in space.random(rng, n_random)]
    try:
        values = [f(x, src) for x, src in starts]
        for i in np.argsort(values):
            x0, src = starts[i]
            step = 0.05 * probe.part.a if space.kind == "tripods" else 0.2
            simplex = np.vstack([x0, x0 + step * np.eye(space.size)])
            minimize(f, x0, args=(f"Nelder-Mead from a {src}",), method="Nelder-Mead",
                     options={"initial_simplex": simplex, "maxfev": max(10, budget // 4),
                              "xatol": 1e-3, "fatol": 1e-3})
    except _Stop:
        pass
