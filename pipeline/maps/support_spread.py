"""How far a support family moves a part's configuration maps from uniform pressure.

:func:`family_spread` computes one map per member of a
:class:`~pipeline.parts.support_family.SupportFamily` on the same grid as
the uniform map and measures the shift of ``theta_f``, cell by cell:
``shift = wrap(theta_f(member) - theta_f(uniform))`` in (-180, 180] deg,
where both passages push the part (status ``ok``); a cell where a member
jams or misses while uniform does not (or the reverse) is counted as a
changed outcome instead.

The family's *extremes* (spec section 9) are the members that move the maps
most: the largest mean shift each way (the member that turns parts furthest
counter-clockwise and the one furthest clockwise, averaged over the grid)
and the largest root-mean-square shift. They draw the figure's outer maps
and the planner's nominal paths; the verification samples every member.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from kernels.rollout import OK

from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.progress import Heartbeat


@dataclass
class FamilySpread:
    """Maps of a family's members next to the uniform map.

    Attributes
    ----------
    uniform : the uniform map (dims ``d, theta_i``).
    maps : the members' maps stacked along ``support`` (member labels).
    shift : ``theta_f`` shift from uniform per member and cell (deg; NaN
        where either passage does not push the part).
    """

    uniform: xr.Dataset
    maps: xr.Dataset
    shift: xr.DataArray

    @property
    def flat_shift(self) -> np.ndarray:
        """The shift as ``(members, cells)``."""
        return self.shift.values.reshape(self.shift.sizes["support"], -1)

    @property
    def changed(self) -> np.ndarray:
        """Per cell (flat), whether some member's outcome (ok / miss / jammed) differs from uniform's."""
        return (self.maps["status"] != self.uniform["status"]).any("support").values.ravel()

    @property
    def extremes(self) -> tuple:
        """Indices of the extreme members (see the module docstring)."""
        return extreme_members(self.flat_shift)


def spread_numbers(shift: np.ndarray, changed: np.ndarray) -> dict:
    """The numbers a report shows for shifts ``(members, cells)`` and changed
    outcomes ``(cells,)``: over the cells where every member and uniform push
    the part, the largest shift of any member per cell (median, p90, max over
    cells, deg), and the share of cells whose outcome some member changes."""
    worst = np.abs(shift).max(axis=0)
    worst = worst[np.isfinite(worst)]

    def pct(q):
        return round(float(np.percentile(worst, q)), 2) if worst.size else None

    return {"cells": int(changed.size), "cells_compared": int(worst.size),
            "shift_median_deg": pct(50), "shift_p90_deg": pct(90), "shift_max_deg": pct(100),
            "outcome_changed_share": round(float(changed.mean()), 4)}


def _wrap(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def extreme_members(shift: np.ndarray) -> tuple:
    """Indices of the members with the largest mean shift each way and the
    largest RMS shift (``shift``: ``(members, cells)``, NaN ignored), without
    repeats, in that order."""
    counts = np.maximum(1, np.isfinite(shift).sum(axis=1))
    filled = np.nan_to_num(shift)
    mean = filled.sum(axis=1) / counts
    rms = np.sqrt((filled ** 2).sum(axis=1) / counts)
    out = []
    for k in (int(np.argmax(mean)), int(np.argmin(mean)), int(np.argmax(rms))):
        if k not in out:
            out.append(k)
    return tuple(out)


def family_spread(part: Part, family, theta_i, d, mu_c: float, pin_radius: float,
                  model: str = "minpower", threads: int | None = None) -> FamilySpread:
    """Maps of every member of ``family`` and of uniform pressure on the grid
    ``d x theta_i`` at one friction (model minpower), and their shifts; how
    many maps are done goes to the progress report of
    :func:`pipeline.progress.reporting`, if any."""
    maps = []
    with Heartbeat(f"maps of {family.label} at mu_c {mu_c:g}", len(family.kernel_supports) + 1, "map") as beat:
        for s in [None, *family.kernel_supports]:
            maps.append(simulate.compute_map(part, theta_i, d, mu_c, pin_radius, model, threads=threads,
                                             **({} if s is None else {"support": s})))
            beat.tick(len(maps))
    uniform, maps = maps[0], maps[1:]
    keep = ["theta_f", "dy", "status", "jam_reason"]
    stacked = xr.concat([m[keep].drop_attrs() for m in maps], dim="support")
    stacked = stacked.assign_coords(support=("support", family.labels, {"long_name": "support distribution"}))
    stacked.attrs = {k: v for k, v in uniform.attrs.items() if not k.startswith("support")}
    stacked.attrs["support_family"] = family.label
    both_ok = (stacked["status"] == OK) & (uniform["status"] == OK)
    shift = xr.DataArray(_wrap(stacked["theta_f"] - uniform["theta_f"]), dims=stacked["theta_f"].dims,
                         coords=stacked["theta_f"].coords).where(both_ok)
    shift.attrs = {"units": "degree", "long_name": "shift of the final orientation from uniform support"}
    return FamilySpread(uniform, stacked, shift)
