"""Compile the kernels before the work that needs them.

Numba compiles a kernel the first time it runs after an install or an edit
of ``kernels/`` (a minute or two on a 2-core machine) and keeps the
machine code in its cache (see ``kernels/_numba.py``); a later process loads
it in about a second. :func:`warm_kernels` runs every kernel a plan uses once,
on tiny inputs, so that this cost is paid in one known place:

* ``pinfeed plan`` calls it before its search. A search's first level then
  measures its real pace (the estimates of the levels after it use it), and
  when compiling takes a while a progress line says what is happening. A
  ``--time-limit`` counts from after it (see
  ``pipeline.workflow.commands._warm_up``).
* ``make run`` runs ``python -m pipeline.maps.warm`` first, so the workflow's
  jobs and the first plan of a drawing after it load the kernels instead of
  compiling them. The workflow's default parts are triangles: without this
  the kernels of a part with holes and many edges (its support table) would
  still be compiled by the first real drawing planned, some 15 s.

The part used is a 50 x 40 mm plate with 6 mm fillets flattened to 20
vertices and a round hole of 8: just enough edges for the support table
(``kernels.support_table.TABLE_MIN_EDGES``), few enough that building it
and rolling the part out take a fraction of a second.
"""
from __future__ import annotations

import math
import threading
import time

import numpy as np

from kernels.int_table import EMPTY, insert_keys, lookup_keys
from pipeline.maps.simulate import compute_map, dynamic_rollout, rollout, rollout_points
from pipeline.parts.part import Part

NOTICE_AFTER = 2.0  # seconds: loading cached kernels takes less; compiling them takes more
NOTICE = ("compiling the kernels: once after an install or an update of pinfeed, a minute or two on "
          "2 cores (later runs load them from the cache)")


def warm_part() -> Part:
    """The part the kernels are run on (see the module's docstring)."""
    pts = []
    for cx, cy, a0 in ((44.0, 6.0, -90), (44.0, 34.0, 0), (6.0, 34.0, 90), (6.0, 6.0, 180)):
        pts += [(cx + 6.0 * math.cos(math.radians(a0 + 22.5 * k)),
                 cy + 6.0 * math.sin(math.radians(a0 + 22.5 * k))) for k in range(5)]
    hole = [(12.0 + 3.0 * math.cos(-math.pi * k / 4), 20.0 + 3.0 * math.sin(-math.pi * k / 4)) for k in range(8)]
    return Part.from_vertices(pts, name="warm-up plate", holes=[hole])


def warm_kernels(progress=None, every: bool = False, notice_after: float = NOTICE_AFTER) -> float:
    """Compile (or load from the cache) every kernel a plan runs, and with
    ``every`` also those of single rollouts with their records and of maps
    (``pinfeed rollout``, ``map``, ``animate`` and the workflow's map
    shards); the seconds it took. ``progress`` (a function of one line) is
    told :data:`NOTICE` once the work has taken ``notice_after`` seconds,
    which only compiling does."""
    timer = None
    if progress is not None:
        timer = threading.Timer(notice_after, progress, args=(NOTICE,))
        timer.daemon = True
        timer.start()
    t0 = time.perf_counter()
    try:
        part = warm_part()
        _run_plan_kernels(part)
        if every:
            _run_other_kernels(part)
    finally:
        if timer is not None:
            timer.cancel()
            timer.join()  # a notice already on its way is printed before this returns
    return time.perf_counter() - t0


THETA, D = np.array([10.0, 100.0]), np.array([-0.3, 0.2])  # two tiny rollouts per call


def _run_plan_kernels(part: Part) -> None:
    """One tiny call of each kernel entry point a plan reaches: the part's
    preparation (support table) and resting states, and scattered points
    (the planner's trials; the dynamic model for moving pins' speed limits),
    and the table of the planner's memo of trial states. A part without
    holes is prepared by kernels of its own."""
    Part.from_vertices([(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)], name="warm-up triangle").prepared()
    part.stable_states()
    rollout_points(part, THETA, D, 0.2, 3.0, threads=1)
    rollout_points(part, THETA, D, 0.2, 3.0, model="dynamic", belt_speed=50.0, threads=1)
    slots, at = np.full(4, EMPTY, dtype=np.int64), np.zeros(4, dtype=np.int64)
    insert_keys(slots, at, np.array([7], dtype=np.int64), np.array([0], dtype=np.int64), 0)
    lookup_keys(slots, at, np.array([7], dtype=np.int64), np.zeros(1, dtype=np.int64))


def _run_other_kernels(part: Part) -> None:
    """A map (a static grid, in parallel) and single rollouts with their records."""
    compute_map(part, THETA, D, 0.2, 3.0, threads=1)
    rollout(part, 30.0, 0.2, 0.2, 3.0, trajectory=True)
    dynamic_rollout(part, 30.0, 0.2, 0.2, 3.0, belt_speed=50.0, trajectory=True)


if __name__ == "__main__":  # silent when the kernels are cached: the usual case
    took = warm_kernels(progress=lambda line: print(f"pinfeed: {line}", flush=True), every=True)
    if took > NOTICE_AFTER:
        print(f"pinfeed: kernels compiled in {took:.0f} s", flush=True)
