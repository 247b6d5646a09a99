"""Support families: every distribution the engineer believes a part may rest on.

A :class:`SupportFamily` is a finite list of :class:`~pipeline.parts.support.Support`
members that stands for a set of distributions. Plans made for a family must
orient the part for every member (``pinfeed plan --support-family``); maps
and reports compare the members with uniform pressure. How a family is
sampled and how its extremes are found is spec section 9
(``docs/explanation/spec-supports.md``); in short:

``tripods:N[:inset=F][:seed=S]``
    Any three points within the outline, at least ``F a`` from its edge
    (default ``F = 0.2``), that hold the centroid: ``N`` such tripods
    (default 12) drawn uniformly (points uniform over the inset region,
    triples kept when the centroid's barycentric weights are all at least
    ``MIN_LEG_WEIGHT``: statics puts the centre of pressure at the centre of
    mass, and a leg carrying almost nothing is a part about to tip).
    A part with holes: the legs stand on the material, at least ``F a``
    from every edge of it, the holes' rims as well as the outline (a rim is
    an edge whichever loop it belongs to); candidate points in a hole or
    nearer a hole's rim are dropped like those outside the outline.
``warp:AMP[:N][:seed=S]``
    Uniform pressure times ``1 + AMP q``: ``q`` a quadratic over the area
    (bowl ``x^2 + y^2``, saddles ``x^2 - y^2`` and ``2xy``) with its
    constant and linear parts projected out, so the centre of pressure stays
    at the centroid, scaled to ``max |q| = 1``; ``0 < AMP <= 1`` keeps the
    pressure >= 0. Members: the dome (centre-heavy) and the dish (rim-heavy)
    first, then ``N - 2`` random mixes (default ``N = 8``). Each member is
    a point support on ``WARP_FILL^2`` points per triangle of the outline
    (of the material, holes left out, for a part with holes:
    :func:`~pipeline.parts.support.filled_support`), so the modes, their
    projections and the centre of pressure are the material's.
``SPEC; SPEC; ...``
    An explicit list: each item a family or a single support
    (``uniform``, ``tripod``, ``rim:N``, ``points:"x,y,w ..."``, where a
    ``points`` item separates its points by spaces only).

The same text and part give the same members (seeded). The text itself,
item by item, is a :class:`FamilySpec`: change an item's option (the
tripods' inset) and write the text back.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.support import (UNIFORM, Support, barycentric, filled_support, material_distance,
                                    parse_support, point_support)

DEFAULT_TRIPODS = 12
DEFAULT_INSET = 0.2  # of a
DEFAULT_WARPS = 8
MIN_LEG_WEIGHT = 0.05  # a tripod leg must carry at least this share of the weight
WARP_FILL = 5  # points per triangle side of a warp member (filled_support)
MAX_MEMBERS = 256
_DRAWS = 200_000  # candidate points tried when sampling tripods
_SYNTAX = ('give "tripods:N[:inset=F][:seed=S]", "warp:AMP[:N][:seed=S]", a single support '
           '("uniform", "tripod", "rim:N", "points:x,y,w ...") or a list "SPEC; SPEC; ..."')


@dataclass(frozen=True)
class SupportFamily:
    """A finite family of supports of one part.

    Attributes
    ----------
    label : the text it was given as.
    members : the supports (:data:`~pipeline.parts.support.UNIFORM` for uniform pressure).
    extremes : indices of the members that move the maps most (found by
        ``pipeline.maps.support_spread``; empty until then): the planner's
        nominal paths follow them and the verification replays the corners
        of its perturbation box under each.
    """

    label: str
    members: tuple
    extremes: tuple = ()

    def __len__(self) -> int:
        return len(self.members)

    @property
    def labels(self) -> list[str]:
        """Each member's label, for outputs."""
        return [m.label for m in self.members]

    @property
    def kernel_supports(self) -> list:
        """Each member as ``simulate`` takes it (``None`` for uniform)."""
        return [None if m.is_uniform else m for m in self.members]

    @property
    def is_uniform(self) -> bool:
        """True for the family of uniform pressure alone (plans as without a family)."""
        return len(self.members) == 1 and self.members[0].is_uniform

    @property
    def representatives(self) -> tuple:
        """Indices of the members the nominal paths and corners use: the
        extremes, or every member while they are not known."""
        return tuple(self.extremes) or tuple(range(len(self.members)))

    def to_dict(self) -> dict:
        """Label, members and extremes as a JSON-ready dict."""
        return {"label": self.label, "members": [m.to_dict() for m in self.members],
                "extremes": [self.members[k].label for k in self.extremes]}


@dataclass(frozen=True)
class FamilyItem:
    """One item of a family text as written: its ``kind`` (``tripods``,
    ``warp``, ``rim``, ...) and the ``:``-separated ``fields`` after it
    (``tripods:12:inset=0.3`` is ``("tripods", ("12", "inset=0.3"))``)."""

    kind: str
    fields: tuple = ()

    @classmethod
    def parse(cls, text: str) -> "FamilyItem":
        """The item ``text`` (stripped) split at its colons; nothing is checked."""
        kind, *fields = text.strip().split(":")
        return cls(kind, tuple(fields))

    def is_kind(self, kind: str) -> bool:
        """Whether the item is of ``kind`` (``"tripods"``)."""
        return self.kind.strip() == kind

    def option(self, key: str, default=None):
        """The value of the item's option ``key=value`` as the family parser
        reads it (stripped; the last one given), else ``default``."""
        _, opts = _options(list(self.fields), self.format())
        return opts.get(key, default)

    def with_option(self, key: str, value: str) -> "FamilyItem":
        """The item with its option ``key`` set to ``value`` (text): any
        ``key=...`` field dropped, ``key=value`` added last."""
        kept = tuple(f for f in self.fields if not ("=" in f and f.partition("=")[0].strip() == key))
        return FamilyItem(self.kind, kept + (f"{key}={value}",))

    def format(self) -> str:
        """The item's text."""
        return ":".join((self.kind,) + self.fields)


@dataclass(frozen=True)
class FamilySpec:
    """A family text parsed into its items (``SPEC; SPEC; ...``), each as
    written: a value to change (an option of the tripods, say) and write
    back as text (:meth:`format`), items left alone as they were. It checks
    nothing; :func:`parse_support_family` draws the members and says what is
    wrong with a text."""

    items: tuple

    @classmethod
    def parse(cls, text: str) -> "FamilySpec":
        """The items of the family ``text``."""
        return cls(tuple(FamilyItem.parse(item) for item in str(text).split(";")))

    def first(self, kind: str) -> FamilyItem | None:
        """The first item of ``kind`` (None: there is none)."""
        return next((item for item in self.items if item.is_kind(kind)), None)

    def with_option(self, kind: str, key: str, value: str) -> "FamilySpec":
        """The family with option ``key`` of every item of ``kind`` set to ``value`` (text)."""
        return FamilySpec(tuple(item.with_option(key, value) if item.is_kind(kind) else item
                                for item in self.items))

    def format(self) -> str:
        """The family text: the items, stripped, joined by ``;``."""
        return ";".join(item.format() for item in self.items)


def _options(fields: list[str], text: str) -> tuple[list[str], dict]:
    """Split ``a:b:key=v`` fields into positional values and ``key=value`` options."""
    pos, opts = [], {}
    for f in fields:
        f = f.strip()
        if "=" in f:
            k, _, v = f.partition("=")
            opts[k.strip()] = v.strip()
        elif f:
            pos.append(f)
    return pos, opts


def _number(value: str, what: str, text: str, kind=float):
    try:
        return kind(value)
    except ValueError:
        raise PinfeedError(f"support family {text!r}: {what} must be a number, got {value!r}; "
                           f"{_SYNTAX}") from None


def _seed(opts: dict, text: str) -> int:
    return _number(opts.pop("seed", "0"), "seed", text, int)


def _no_extra(opts: dict, text: str) -> None:
    if opts:
        raise PinfeedError(f"support family {text!r}: unknown option(s) {', '.join(sorted(opts))}; "
                           f"{_SYNTAX}")


def _count(value: str, what: str, text: str) -> int:
    n = _number(value, what, text, int)
    if n < 1:
        raise PinfeedError(f"support family {text!r} is empty ({what} = {n}); give at least one member")
    if n > MAX_MEMBERS:
        raise PinfeedError(f"support family {text!r} has {n} members, more than the limit of "
                           f"{MAX_MEMBERS} (plans replay every member)")
    return n


def sample_tripods(part, n: int, inset: float = DEFAULT_INSET, seed: int = 0) -> list[Support]:
    """``n`` tripods of points at least ``inset * a`` inside the outline (and
    that far from any hole's rim) that hold the centroid (weights by
    statics); see the module docstring."""
    if not 0.0 <= inset < 1.0:
        raise PinfeedError(f"tripod inset {inset:g} must be in [0, 1) (a share of a)")
    verts = np.asarray(part.vertices, dtype=np.float64)
    rng = np.random.default_rng([int(seed), 25])
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    xy = rng.uniform(lo, hi, (_DRAWS, 2))
    on, dist = material_distance(part, xy)  # a solid part: inside the outline, its edge
    pool = xy[on & (dist >= inset * part.a)]
    if pool.shape[0] < 3:
        holed = bool(getattr(part, "holes", ()))
        where = "the material" if holed else "the outline"
        edges = "its edges (the outline and the holes' rims)" if holed else "its edge"
        raise PinfeedError(f"no point of {where} lies {inset:g} a ({inset * part.a:.3g} mm) from "
                           f"{edges}; lower the inset (tripods:N:inset=F)")
    out = []
    for _ in range(200 * n):
        tri = pool[rng.choice(pool.shape[0], 3, replace=False)]
        (ux, uy), (vx, vy) = tri[1] - tri[0], tri[2] - tri[0]
        if abs(ux * vy - uy * vx) < 1e-9 * part.a ** 2:  # twice the area: three points in a line
            continue
        lam = barycentric(*tri)
        if np.all(lam >= MIN_LEG_WEIGHT):
            out.append(point_support(part, tri, lam, kind="points",
                                     label=f"tripod {len(out) + 1}/{n}"))
            if len(out) == n:
                return out
    raise PinfeedError(f"could not find {n} tripods {inset:g} a inside the outline that hold the "
                       f"centroid (the inset region is too narrow); lower the inset")


def warp_modes(points: np.ndarray, weights: np.ndarray, a: float) -> np.ndarray:
    """The three quadratic warp modes ``(3, K)`` on quadrature ``points``: bowl,
    saddle, twisted saddle, each with its weighted projection on ``1, x, y``
    removed (so ``1 + q`` keeps the centre of pressure) and scaled to
    ``max |q| = 1``."""
    x, y = points[:, 0] / a, points[:, 1] / a
    basis = np.column_stack([np.ones_like(x), x, y])
    sw = np.sqrt(weights)
    modes = []
    for q in (x * x + y * y, x * x - y * y, 2 * x * y):
        coef, *_ = np.linalg.lstsq(basis * sw[:, None], q * sw, rcond=None)
        r = q - basis @ coef
        modes.append(r / np.max(np.abs(r)))
    return np.array(modes)


def sample_warps(part, amplitude: float, n: int = DEFAULT_WARPS, seed: int = 0) -> list[Support]:
    """``n`` warped pressures ``1 + amplitude * q`` (dome, dish, then random
    mixes of the three modes); see the module docstring."""
    if not 0.0 < amplitude <= 1.0:
        raise PinfeedError(f"warp amplitude {amplitude:g} must be in (0, 1] (pressure 1 +- AMP "
                           f"stays >= 0)")
    base = filled_support(part, WARP_FILL)
    modes = warp_modes(base.points, base.weights, part.a)
    rng = np.random.default_rng([int(seed), 26])
    mixes = [np.array([-1.0, 0, 0]), np.array([1.0, 0, 0])]
    mixes += [c / np.linalg.norm(c) for c in rng.normal(size=(max(0, n - 2), 3))]
    out = []
    for k, c in enumerate(mixes[:n]):
        q = c @ modes
        q = q / np.max(np.abs(q))
        name = ("dome", "dish")[k] if k < 2 else f"mix {k - 1}"
        out.append(point_support(part, base.points, base.weights * (1.0 + amplitude * q),
                                 kind="points", label=f"warp {name} {amplitude:g}"))
    return out


def _item(text: str, part) -> list[Support]:
    kind, _, rest = text.partition(":")
    kind = kind.strip()
    if kind == "tripods":
        pos, opts = _options(rest.split(":"), text)
        n = _count(pos[0], "N", text) if pos else DEFAULT_TRIPODS
        inset = _number(opts.pop("inset", str(DEFAULT_INSET)), "inset", text)
        seed = _seed(opts, text)
        _no_extra(opts, text)
        if len(pos) > 1:
            raise PinfeedError(f"support family {text!r}: too many fields; {_SYNTAX}")
        return sample_tripods(part, n, inset, seed)
    if kind == "warp":
        pos, opts = _options(rest.split(":"), text)
        if not pos:
            raise PinfeedError(f"support family {text!r} needs an amplitude: warp:AMP; {_SYNTAX}")
        amp = _number(pos[0], "AMP", text)
        n = _count(pos[1], "N", text) if len(pos) > 1 else DEFAULT_WARPS
        seed = _seed(opts, text)
        _no_extra(opts, text)
        if len(pos) > 2:
            raise PinfeedError(f"support family {text!r}: too many fields; {_SYNTAX}")
        return sample_warps(part, amp, n, seed)
    try:
        return [parse_support(text, part)]
    except PinfeedError as err:
        if str(err).startswith("unknown support"):
            raise PinfeedError(f"unknown support family {text!r}; {_SYNTAX}") from None
        raise


def parse_support_family(text: str | None, part) -> SupportFamily:
    """The family ``text`` names for ``part`` (see the module docstring).

    Raises
    ------
    PinfeedError
        One line: an empty family, an unknown kind, a bad number, a member
        outside the outline or in a hole (from
        :func:`~pipeline.parts.support.point_support`).
    """
    if text is None or not str(text).strip():
        raise PinfeedError(f"the support family is empty; {_SYNTAX}")
    members = []
    for item in str(text).split(";"):
        if not item.strip():
            raise PinfeedError(f"support family {text!r} has an empty item (two ';' in a row?); {_SYNTAX}")
        members.extend(_item(item.strip(), part))
    if len(members) > MAX_MEMBERS:
        raise PinfeedError(f"support family {text!r} has {len(members)} members, more than the "
                           f"limit of {MAX_MEMBERS} (plans replay every member)")
    return SupportFamily(str(text).strip(), tuple(members))


def single(support: Support = UNIFORM) -> SupportFamily:
    """The family of one support (uniform by default): plans as before."""
    return SupportFamily(support.label, (support,))
