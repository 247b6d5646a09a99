"""Bands, kernels, COM intervals and adjusted bands of one configuration map (spec section 5).

Everything is on the circle: theta_f values are grouped around 0/360, a band
may wrap through 360 (or cover the whole circle), and a band kernel K_j
(``Band.kernel_arcs``; "kernel" alone means a Numba kernel) may be several
separate arcs of theta_i. Arcs are ``(start, width)`` in degrees: the set
``start + [0, width]`` taken modulo 360.

- B_j: sort the ``ok`` theta_f values around the circle; neighbours at most
  ``T`` apart share a group; B_j runs from the group's first to its last value.
- K_j: the theta_i whose theta_f falls in group j, as arcs of consecutive grid
  points (a grid covering the whole circle joins across 0/360).
- COM_j: [min, max] of dy over K_j.
- Adjusted band: m_j +- c sigma_j with the circular mean m_j and circular
  standard deviation sigma_j = sqrt(-2 ln R) of the group's theta_f.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from kernels.rollout import OK

from pipeline.planning.core.arcs import format_arc, format_arcs, in_arc  # noqa: F401 (re-exported for older callers)


@dataclass
class Band:
    """One band B_j of a map: its arc of theta_f, adjusted band, COM interval and kernel K_j.

    Angles in degrees (arcs ``start + [0, width]`` modulo 360), ``com_*`` in
    the part's length unit; ``kernel_arcs`` is K_j, ``members`` its grid indices.
    """
    start: float
    width: float
    mean: float
    sigma: float
    adj_start: float
    adj_width: float
    com_min: float
    com_max: float
    n: int
    kernel_arcs: list = field(default_factory=list)  # K_j: [(start, width)] arcs of theta_i
    members: list = field(default_factory=list)  # theta_i grid indices

    @property
    def wraps(self) -> bool:
        """Whether the band runs through 360 degrees."""
        return self.start + self.width >= 360.0

    def to_dict(self) -> dict:
        """The band as a JSON-ready dict; K_j is stored under the key ``"kernel"`` (file format)."""
        return {("kernel" if k == "kernel_arcs" else k): v for k, v in asdict(self).items()}


def circular_mean_std(deg) -> tuple[float, float]:
    """Circular mean (degrees, [0, 360)) and circular standard deviation ``sqrt(-2 ln R)`` (degrees) of ``deg``."""
    rad = np.radians(np.asarray(deg, float))
    c, s = np.cos(rad).mean(), np.sin(rad).mean()
    r = math.hypot(c, s)
    mean = math.degrees(math.atan2(s, c)) % 360.0
    if r >= 1.0 - 4.0 * np.finfo(float).eps * max(1, len(rad)):
        return mean, 0.0  # identical angles: R is 1 up to rounding
    sigma = math.degrees(math.sqrt(-2.0 * math.log(r))) if r > 0 else 180.0
    return mean, sigma


def _grid_arcs(theta_i, idx) -> list[tuple[float, float]]:
    """Arcs of consecutive grid points among ``idx`` (sorted indices into ``theta_i``)."""
    if len(idx) == 0:
        return []
    step = float(np.median(np.diff(theta_i))) if len(theta_i) > 1 else 360.0
    full = len(theta_i) * step >= 360.0 - 1e-9
    runs = [[idx[0], idx[0]]]
    for k in idx[1:]:
        if k == runs[-1][1] + 1:
            runs[-1][1] = k
        else:
            runs.append([k, k])
    n = len(theta_i)
    if full and len(runs) > 1 and runs[0][0] == 0 and runs[-1][1] == n - 1:
        runs[0][0] = runs[-1][0] - n  # join across 0/360
        runs.pop()
    if full and len(runs) == 1 and runs[0][1] - runs[0][0] + 1 == n:
        return [(float(theta_i[0]) % 360.0, 360.0)]
    arcs = []
    for a, b in runs:
        start = float(theta_i[a % n]) % 360.0
        arcs.append((start, (b - a) * step))
    return arcs


def extract_bands(theta_i, theta_f, dy, status, threshold_T: float, factor_c: float) -> list[Band]:
    """Bands of one map; see the module doc. Non-``ok`` samples are left out."""
    theta_i = np.asarray(theta_i, float)
    theta_f = np.asarray(theta_f, float) % 360.0
    dy = np.asarray(dy, float)
    ok = np.flatnonzero(np.asarray(status) == OK)
    if ok.size == 0:
        return []
    order = ok[np.argsort(theta_f[ok], kind="stable")]
    vals = theta_f[order]
    gaps = np.diff(np.append(vals, vals[0] + 360.0))  # gap after each value, circularly
    cuts = np.flatnonzero(gaps > threshold_T)
    if cuts.size == 0:
        groups = [(order, True)]
    else:
        groups = []
        for k, cut in enumerate(cuts):
            nxt = cuts[(k + 1) % cuts.size]
            if nxt > cut:
                members = order[cut + 1: nxt + 1]
            else:  # wraps through the end of the sorted list
                members = np.concatenate([order[cut + 1:], order[: nxt + 1]])
            groups.append((members, False))
    bands = []
    for members, whole in groups:
        f = theta_f[members]
        if whole:
            start, width = 0.0, 360.0
        else:
            start = float(f[0])
            width = float((f[-1] - f[0]) % 360.0)
        mean, sigma = circular_mean_std(f)
        half = min(180.0, factor_c * sigma)
        idx = np.sort(members)
        bands.append(Band(start=start, width=width, mean=mean, sigma=sigma,
                          adj_start=(mean - half) % 360.0, adj_width=2.0 * half,
                          com_min=float(dy[idx].min()), com_max=float(dy[idx].max()),
                          n=int(idx.size), kernel_arcs=_grid_arcs(theta_i, idx),
                          members=[int(i) for i in idx]))
    bands.sort(key=lambda b: b.start)
    return bands


def band_lookup(bands: list[Band], n_theta: int) -> np.ndarray:
    """Band index of every theta_i grid point (-1 where no band: miss, jam...)."""
    out = np.full(n_theta, -1, dtype=int)
    for j, b in enumerate(bands):
        out[b.members] = j
    return out

