"""Option groups and helpers the ``pinfeed`` verbs share, defined once.

* the part: ``--vertices`` (with ``--hole``) or a CAD ``--outline`` (with ``--layer``, ``--id``,
  ``--units``, ``--join-tol``, ``--flatten-tol``) and ``--name``
  (:func:`add_outline_args`, read back by :func:`part_from_args`);
* the physics of one pin: friction, pin radius, contact model, pin speed and
  support (:func:`add_physics`);
* the workflow's files: ``--config`` and ``--results`` (:func:`add_config_option`,
  :func:`add_results_option`, :func:`results_arg`);
* output: ``--json`` documents (:func:`add_json_option`, :func:`print_json`)
  and value lists (:func:`parse_values`); progress lines on stderr
  (:func:`progress_line`).
"""
from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

from pipeline.errors import PinfeedError

CONFIG_HELP = "workflow config YAML (default: the embedded one)"


def progress_line(message: str) -> None:
    """One progress line on stderr, indented (stdout holds the command's result)."""
    print(f"  ... {message}", file=sys.stderr, flush=True)


def print_json(obj, **kw):
    """One JSON document on stdout, newline-terminated (the ``--json`` outputs)."""
    json.dump(obj, sys.stdout, **kw)
    sys.stdout.write("\n")


def parse_values(text: str, what: str) -> numpy.ndarray:
    """``"a,b,c"`` or an inclusive range ``"start:stop:step"``: finite, distinct,
    at most ``checks.MAX_VALUES`` values (refused before anything is allocated)."""
    import numpy as np

    from pipeline.checks import check_grid_size, check_values, range_size
    bad = PinfeedError(f"{what} {text!r} is not a list 'a,b,c' or a range 'start:stop:step' "
                       f"of finite numbers with step > 0")
    try:
        if ":" in text:
            start, stop, step = (float(x) for x in text.split(":"))
        else:
            values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise bad from None
    if ":" in text:
        if not all(map(math.isfinite, (start, stop, step))) or step <= 0 or stop < start:
            raise bad
        n = range_size(start, stop, step)
        check_grid_size(n, f"{what} {text}")
        return np.round(start + step * np.arange(n), 10) + 0.0
    check_grid_size(len(values), what)
    return check_values(values, f"{what} {text!r}")


def part_from_args(args):
    """The part of ``--vertices`` (with its ``--hole`` loops) or ``--outline``
    (saying how many vertices and holes a CAD outline gave)."""
    from pipeline.parts.part import Part, parse_holes, parse_vertices
    if getattr(args, "outline", None):
        from pipeline.parts.outlines import read_outline
        out = read_outline(args.outline, layer=args.layer, id=args.id, flatten_tol=args.flatten_tol,
                           units=args.units, join_tol=args.join_tol)
        print(f"outline {out.describe()}", file=sys.stderr)
        for line in out.warnings():
            print(f"pinfeed: warning: {line}", file=sys.stderr)
        if getattr(args, "hole", None):
            raise PinfeedError("--hole goes with --vertices; an --outline file brings its own holes "
                               "(closed loops inside the outline)")
        name = args.name or re.sub(r"[^A-Za-z0-9_]", "_", Path(args.outline).stem) or "part"
        return Part.from_vertices(out.vertices, name=name, holes=out.holes)
    if any(getattr(args, k, None) is not None for k in ("layer", "id", "units", "join_tol")):
        raise PinfeedError("--layer, --id, --units and --join-tol apply to an --outline file")
    return Part.from_vertices(parse_vertices(args.vertices), name=args.name or "part",
                              holes=parse_holes(getattr(args, "hole", None)))


def plan_part_arg(args, config):
    """The part of ``--vertices``/``--outline``, else the config's or catalog's ``--part``."""
    from pipeline.workflow.commands import named_part
    if args.vertices or args.outline:
        return part_from_args(args)
    return named_part(config, args.part)


def add_outline_args(p, required=True):
    """``--vertices`` or ``--outline FILE`` (with its choosers), and ``--name``."""
    g = p.add_mutually_exclusive_group(required=required)
    g.add_argument("--vertices", help='part outline "x0,y0 x1,y1 ..." (mm)')
    g.add_argument("--outline", metavar="FILE",
                   help="or a CAD outline: a .dxf or .svg file; its pieces are joined into closed loops "
                   "layer by layer; a loop inside no other (or inside a hole) is a part's outline, the loops "
                   "directly inside it its holes; the largest part is read, the others are named in a "
                   "warning (a drawing frame and construction lines are reported and left out)")
    p.add_argument("--hole", action="append", default=None, metavar="VERTICES",
                   help='a hole of a --vertices part, "x0,y0 x1,y1 ..." (mm, the outline\'s frame), '
                   "strictly inside the outline and apart from other holes; repeat for each hole")
    p.add_argument("--layer", default=None, metavar="NAME",
                   help="layer to read alone (a DXF layer, or an Inkscape layer's label in an SVG), when "
                   "the file holds several")
    p.add_argument("--id", default=None, help="the part to read: the SVG element id or DXF entity handle (an "
                   "INSERT's for its block) of a piece of it (outline or hole), or its label FILE#N as the "
                   "warning names it")
    p.add_argument("--units", default=None, choices=["mm", "cm", "m", "in"],
                   help="units of the outline file's coordinates, overriding the file's own "
                   "(DXF $INSUNITS, unitless: mm; SVG width/height over viewBox)")
    p.add_argument("--join-tol", dest="join_tol", type=float, default=None, metavar="TOL",
                   help="largest gap between piece ends that are joined, in the drawing's units "
                   "(default 1e-4 of the drawing's size)")
    p.add_argument("--flatten-tol", dest="flatten_tol", type=float, default=None, metavar="MM",
                   help="chordal tolerance for flattening arcs and curves, mm (default 0.05, or 1/2000 of "
                   "the drawing's diagonal when that is larger)")
    p.add_argument("--name", default=None, help="part name used in outputs (default: part, or the "
                   "outline file's name)")


def add_physics(p, d_required=True, belt=False):
    """The part (:func:`add_outline_args`) and the physics of one pin: friction, pin radius,
    contact model (with the belt's speed and friction when ``belt``), pin speed and support."""
    add_outline_args(p)
    p.add_argument("--mu-c", type=float, required=True, help="pin-part friction coefficient (>= 0)")
    p.add_argument("--pin-radius", type=float, required=True, help="pin radius (mm, > 0)")
    if belt:
        p.add_argument("--model", default="minpower",
                       choices=["minpower", "tip", "ellipsoid", "dynamic", "mujoco"],
                       help="contact model (default minpower); dynamic and mujoco need --belt-speed")
        p.add_argument("--belt-speed", dest="belt_speed", type=float, default=None,
                       help="belt speed, mm/s (models dynamic and mujoco)")
        p.add_argument("--mu-s", dest="mu_s", type=float, default=0.5,
                       help="belt-part friction coefficient (models dynamic and mujoco; default 0.5)")
    else:
        p.add_argument("--model", default="minpower", choices=["minpower", "tip", "ellipsoid"],
                       help="contact model (default minpower)")
    p.add_argument("--v-pin", type=float, default=0.0,
                   help="pin speed across the belt / belt speed (default 0: static pin)")
    p.add_argument("--support", default=None, metavar="SPEC",
                   help=f"where the part presses on the belt (model minpower{' or mujoco' if belt else ''}): "
                   "uniform (default), "
                   "points:\"x0,y0,w0 x1,y1,w1 ...\" (mm, part frame: centroid at the origin, "
                   "drawing axes; w defaults to 1), rim or rim:N (N points on the outline), "
                   "tripod (three hull vertices holding the centroid)")



def add_config_option(p) -> None:
    """``--config``: the workflow config YAML."""
    p.add_argument("--config", default=None, help=CONFIG_HELP)


def add_part_options(p) -> None:
    """The options that name a part and what it is planned at: ``--part`` or an
    outline, ``--config``, ``--catalog`` and ``--mu-c`` (``plan``, ``design``)."""
    p.add_argument("--part", default=None, help="part name or id from the config or catalog")
    add_outline_args(p, required=False)
    add_config_option(p)
    p.add_argument("--catalog", default=None, help="catalog folder (default: the config's)")
    p.add_argument("--mu-c", dest="mu_c", default=None,
                   help="friction the plan must work for: a value X or a range LO:HI (default: the config's)")


def add_results_option(p, holding: str = "plans/") -> None:
    """``--results``: the results folder holding ``holding``."""
    p.add_argument("--results", default=None, help=f"results folder holding {holding} "
                   "(default: the config's, RESULTS_DIR/NAME)")


def add_json_option(p, help_text: str = "print JSON instead of text") -> None:
    """``--json``: one JSON document on stdout instead of text (:func:`print_json`),
    with ``help_text`` saying what the document holds."""
    p.add_argument("--json", action="store_true", help=help_text)


def results_arg(args, config) -> Path:
    """The results folder of stored plans and sensing: --results, else the config's."""
    from pipeline.config import results_folder
    return Path(args.results) if args.results else results_folder(config)



def bands_option(text):
    """``--bands T,C`` -> (threshold T in deg, factor c), or None."""
    if text is None:
        return None
    vals = parse_values(text, "--bands")
    if vals.size != 2 or not (vals[0] > 0 and vals[1] >= 0):
        raise PinfeedError(f"--bands {text!r}: give the band threshold T (deg, > 0) and the factor c "
                           f"(>= 0), e.g. --bands 5,2")
    return float(vals[0]), float(vals[1])

