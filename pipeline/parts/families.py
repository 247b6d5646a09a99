"""Part families: explicit outlines and parametric generators from the config.

Generated parts are named from their parameters (``rect_a0p4``,
``ngon6``...), so the same config always yields the same names and ids.
"""
from __future__ import annotations

import math

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part, PolygonError


def _num(x) -> str:
    """Name-safe number: 0.4 -> 0p4, -3 -> m3."""
    return f"{x:g}".replace("-", "m").replace(".", "p")


def _triangle_apex_grid(g):
    base = float(g.get("base", 60.0))
    for x in g["apex_x"]:
        for y in g["apex_y"]:
            yield f"tri_b{_num(base)}_x{_num(x)}_y{_num(y)}", [(0, 0), (base, 0), (x, y)]


def _rectangle(g):
    length = float(g.get("length", 60.0))
    for aspect in g["aspect"]:
        w = length * float(aspect)
        yield f"rect_l{_num(length)}_a{_num(aspect)}", [(0, 0), (length, 0), (length, w), (0, w)]


def _regular_ngon(g):
    radius = float(g.get("radius", 30.0))
    for n in g["n"]:
        ang = 2.0 * math.pi * np.arange(int(n)) / int(n)
        yield f"ngon{int(n)}_r{_num(radius)}", np.column_stack([radius * np.cos(ang), radius * np.sin(ang)])


def _l_shape(g):
    w, h = float(g.get("width", 60.0)), float(g.get("height", 40.0))
    for t in g["thickness"]:
        t = float(t)
        yield (f"L_w{_num(w)}_h{_num(h)}_t{_num(t)}",
               [(0, 0), (w, 0), (w, t), (t, t), (t, h), (0, h)])


def _explicit_loops(family: str, p: dict):
    """An explicit part's vertices and holes, or its CAD outline's
    (``outline: FILE``; the config loader has made a relative path absolute)."""
    if "outline" not in p:
        return p["vertices"], p.get("holes", [])
    from pipeline.parts.outlines import read_outline
    try:
        out = read_outline(p["outline"], layer=p.get("layer"), id=p.get("id"),
                           flatten_tol=p.get("flatten_tol", 0.05), units=p.get("units"),
                           join_tol=p.get("join_tol"))
    except PinfeedError as exc:
        raise PinfeedError(f"family {family}, part {p['name']}: {exc}") from None
    return out.vertices, out.holes


GENERATORS = {
    "triangle_apex_grid": (_triangle_apex_grid, ("apex_x", "apex_y")),
    "rectangle": (_rectangle, ("aspect",)),
    "regular_ngon": (_regular_ngon, ("n",)),
    "l_shape": (_l_shape, ("thickness",)),
}


def family_parts(name: str, spec: dict) -> list[Part]:
    """All parts of one family, validated; raises :class:`PinfeedError` naming the part."""
    outlines = [(p["name"], *_explicit_loops(name, p)) for p in spec.get("parts", [])]
    for g in spec.get("generators", []):
        kind = g.get("kind")
        if kind not in GENERATORS:
            raise PinfeedError(f"family {name}: unknown generator kind {kind!r}; "
                               f"choose one of {', '.join(GENERATORS)}")
        fn, required = GENERATORS[kind]
        missing = [k for k in required if k not in g]
        if missing:
            raise PinfeedError(f"family {name}: generator {kind} needs {', '.join(missing)}")
        outlines.extend((pname, verts, []) for pname, verts in fn(g))
    parts, seen = [], set()
    for pname, verts, holes in outlines:
        if pname in seen:
            raise PinfeedError(f"family {name}: two parts are named {pname!r}; give each a unique name")
        seen.add(pname)
        try:
            parts.append(Part.from_vertices(verts, name=pname, holes=holes))
        except PolygonError as exc:
            raise PinfeedError(f"family {name}, part {pname}: {exc}") from None
    if not parts:
        raise PinfeedError(f"family {name} has no parts; add 'parts' or 'generators'")
    return parts


# ---------------------------------------------------------------------- config parts by name


def config_part_id(config: dict, name: str) -> str:
    """The id of the config's part called ``name`` (the catalog may also hold
    older outlines under the same name), or ``name`` itself if the config
    has no such part."""
    for family, spec in config.get("families", {}).items():
        for part in family_parts(family, spec):
            if name in (part.name, part.id):
                return part.id
    return name


def config_part_source(config: dict, name: str) -> str | None:
    """The CAD outline file a config part was read from (None for vertices)."""
    for spec in config.get("families", {}).values():
        for p in spec.get("parts", []) if isinstance(spec, dict) else []:
            if isinstance(p, dict) and p.get("name") == name:
                return p.get("outline")
    return None
