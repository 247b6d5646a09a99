"""``pinfeed design``: the smallest outline change that lets fixed pins orient a part.

Thin over :func:`pipeline.workflow.design.design_command`: it reads the part
and the options, prints the outline's edges (the numbers ``--keep-edges``
takes) and one line per change tried on stderr, and the outcome on stdout.
"""
from __future__ import annotations

import sys

from pipeline.cli.options import add_part_options, parse_values, plan_part_arg, progress_line
from pipeline.errors import PinfeedError


def cmd_design(args) -> None:
    """``pinfeed design``: search, draw and store the smallest change; print the outcome."""
    from pipeline.config import load_config
    from pipeline.planning import ccw_outline, edge_lengths
    from pipeline.workflow.commands import planner_settings
    from pipeline.workflow.design import design_command, design_paths
    pins = parse_values(args.pins, "--pins") if args.pins else None
    config = planner_settings(load_config(args.config), catalog=args.catalog, mu_c=args.mu_c, depth=args.depth,
                              model=args.model, speeds=[], dynamic_depth=0, pins=pins,
                              belt_speed=args.belt_speed, mu_s=args.mu_s, tolerance=args.tolerance)
    config["design"].update(design_overrides(args))
    part = plan_part_arg(args, config)
    outline, holes = _drawing_outline(args, part)
    paths = design_paths(config, part.name, args.out, args.figure_format)  # checked before any work
    xy = ccw_outline(outline)
    for k, (p, length) in enumerate(zip(xy, edge_lengths(xy))):
        q = xy[(k + 1) % len(xy)]
        print(f"  edge {k}: ({p[0]:.4g}, {p[1]:.4g}) to ({q[0]:.4g}, {q[1]:.4g}) mm, {length:.4g} mm long; "
              f"corner {k} at its start", file=sys.stderr)
    result = design_command(outline, holes, part.name, config, keep_edges=keep_edges_arg(args.keep_edges),
                            paths=paths, progress=progress_line)
    print_design(result, paths)


def _drawing_outline(args, part):
    """The outline and holes in the drawing's frame (an --outline file's or
    --vertices'), else the named part's (its own frame)."""
    if getattr(args, "outline", None):
        from pipeline.parts.outlines import read_outline
        out = read_outline(args.outline, layer=args.layer, id=args.id, flatten_tol=args.flatten_tol,
                           units=args.units, join_tol=args.join_tol)
        return out.vertices, out.holes
    if getattr(args, "vertices", None):
        from pipeline.parts.part import parse_holes, parse_vertices
        return parse_vertices(args.vertices), parse_holes(args.hole)
    return part.vertices, list(part.holes)


def design_overrides(args) -> dict:
    """The ``design`` settings the options give (fractions of a; checked)."""
    out = {}
    if args.kinds is not None:
        out["kinds"] = [k.strip() for k in args.kinds.split(",") if k.strip()]
    if args.chamfer is not None:
        out["chamfer"] = [positive(v, "--chamfer") for v in parse_values(args.chamfer, "--chamfer")]
    for key in ("notch", "tab"):
        text = getattr(args, key)
        if text is not None:
            out[key] = size_pairs(text, f"--{key}")
    if args.positions is not None:
        out["positions"] = [float(v) for v in parse_values(args.positions, "--positions")]
        if not all(0 < v < 1 for v in out["positions"]):
            raise PinfeedError(f"--positions {args.positions!r}: give fractions of an edge inside (0, 1)")
    if args.min_wall is not None:
        out["min_wall_mm"] = args.min_wall
    if args.max_change is not None:
        out["max_change"] = args.max_change
    if args.depth is not None:
        out["depth"] = args.depth
    return out


def positive(value, what: str) -> float:
    """``value`` as a float, or a one-line error unless it is > 0."""
    if not value > 0:
        raise PinfeedError(f"{what}: sizes are fractions of a and must be > 0, got {value:g}")
    return float(value)


def size_pairs(text: str, what: str) -> list:
    """``"W:H,W:H"`` (fractions of a) -> ``[[W, H], ...]``, each > 0."""
    pairs = []
    for token in text.split(","):
        try:
            w, h = (float(x) for x in token.split(":"))
        except ValueError:
            raise PinfeedError(f"{what} {text!r}: give sizes as 'WIDTH:DEPTH,...' in fractions of a, "
                               f"e.g. 0.1:0.05,0.2:0.1") from None
        pairs.append([positive(w, what), positive(h, what)])
    return pairs


def keep_edges_arg(text) -> tuple:
    """``--keep-edges 0,2`` -> ``(0, 2)``; a one-line error for anything but edge numbers."""
    if not text:
        return ()
    try:
        return tuple(int(k) for k in text.split(",") if k.strip())
    except ValueError:
        raise PinfeedError(f"--keep-edges {text!r}: give edge numbers 'k,k,...' (pinfeed design lists "
                           f"them)") from None


def print_design(result: dict, paths: dict) -> None:
    """The outcome for people: the change and its plan, or why there is none."""
    name = result["part"]["name"]
    depth = result["planner"]["depth"]
    tried = result["tried"]
    if result["outcome"] == "already orients":
        print(f"{name}: fixed pins already orient it as drawn ({result['original']['summary']}); no change needed")
    elif result["outcome"] == "changed":
        c = result["chosen"]
        print(f"{name}: no fixed-pin plan of up to {depth} pins orients it as drawn")
        print(f"smallest change that makes one: {c['description']}, {c['area_mm2']:.4g} mm^2 "
              f"({c['share']:.2%} of the area; change {len(tried)} of those tried in order)")
        rec = c["plan"][0]["recommended"]
        print(f"plan: {' '.join(rec['pins'])} at {', '.join(f'{y:g}' for y in rec['pin_heights_mm'])} mm")
        print(f"held-out verdict: {_held_out(rec)}")
    else:
        shares = [t["share"] for t in tried]
        span = f", {min(shares):.2%} to {max(shares):.2%} of the area" if shares else ""
        print(f"{name}: no change within the limits makes a fixed-pin plan of up to {depth} pins "
              f"(tried {len(tried)} changes{span}; {len(result['refused'])} refused by the limits)")
    print(f"wrote {paths['json']}, {paths['dxf']} (layers ORIGINAL, MODIFIED) and {paths['figure']}")


def _held_out(rec: dict) -> str:
    from pipeline.planning import describe_claim
    return describe_claim(rec["verification"]["orientation"])


def add_design_command(sub) -> None:
    """``design``: the smallest chamfer, notch or tab that lets fixed pins orient a part."""
    p = sub.add_parser("design", help="design for feeding: the smallest chamfer, notch or tab that lets "
                       "fixed pins orient a part they do not")
    add_part_options(p)
    p.add_argument("--model", default=None, choices=["minpower", "tip", "ellipsoid"],
                   help="quasi-static contact model (default: the config's planner.model)")
    p.add_argument("--depth", type=int, default=None, help="largest number of fixed pins (>= 1; default: "
                   "design.depth, else planner.depth)")
    p.add_argument("--pins", default=None, help="candidate pin heights, mm: 'a,b,c' or 'start:stop:step' "
                   "(default: the config's planner.pins)")
    p.add_argument("--tolerance", type=float, default=None, metavar="DEG",
                   help="full width (deg) the final orientation set may have (default: planner.tolerance_deg)")
    p.add_argument("--belt-speed", dest="belt_speed", type=float, default=None, metavar="MM_S",
                   help="plan with the dynamic model at this belt speed, mm/s (default: quasi-static)")
    p.add_argument("--mu-s", dest="mu_s", type=float, default=None, help="belt friction with --belt-speed")
    p.add_argument("--kinds", default=None, help="changes to try: 'chamfer,notch,tab' (default: design.kinds)")
    p.add_argument("--chamfer", default=None, metavar="SIZES",
                   help="chamfer legs, fractions of a: 'a,b,c' (default: design.chamfer, 0.05,0.1,0.15,0.2)")
    p.add_argument("--notch", default=None, metavar="W:H,...",
                   help="notch width:depth pairs, fractions of a (default: design.notch, 0.1:0.05,0.2:0.1)")
    p.add_argument("--tab", default=None, metavar="W:H,...",
                   help="tab width:depth pairs, fractions of a (default: design.tab, 0.1:0.05,0.2:0.1)")
    p.add_argument("--positions", default=None, metavar="FRACTIONS",
                   help="where notches and tabs are centred along an edge, fractions of its length "
                   "(default: design.positions, 0.5)")
    p.add_argument("--keep-edges", dest="keep_edges", default=None, metavar="K,K",
                   help="edges that must not change, numbered as the command lists them (edge k runs "
                   "from corner k to corner k+1, counter-clockwise)")
    p.add_argument("--min-wall", dest="min_wall", type=float, default=None, metavar="MM",
                   help="least material left behind each new edge, mm (default: design.min_wall_mm, 1)")
    p.add_argument("--max-change", dest="max_change", type=float, default=None, metavar="FRACTION",
                   help="largest area removed or added, a fraction of the part's area (default: "
                   "design.max_change, 0.1)")
    p.add_argument("--out", default=None, metavar="DIR", help="folder of the design's JSON, DXF and figure "
                   "(default: RESULTS/designs/)")
    p.add_argument("--figure-format", dest="figure_format", default="png", choices=["png", "svg"],
                   help="the before/after figure's format (default png)")
    p.set_defaults(func=cmd_design)
