"""``pinfeed catalog index|list|show|query|plot``: the map database.

Each verb opens the catalog folder (``--catalog``), warns on one line about
shards it cannot serve, and prints a table or, with ``--json``, one document.
"""
from __future__ import annotations

import sys

from pipeline.cli.options import add_json_option, bands_option, parse_values, print_json
from pipeline.errors import PinfeedError


def _catalog(args):
    """The catalog of ``--catalog``, warning about the shards it does not serve."""
    from pipeline.maps.catalog import RECOMPUTE, Catalog
    cat = Catalog.open(args.catalog)
    for problem in cat.problems:
        print(f"pinfeed: warning: {problem} (not served; {RECOMPUTE})", file=sys.stderr)
    return cat


def cmd_catalog_index(args):
    """``pinfeed catalog index``: rebuild the catalog index from the shards on disk."""
    from pipeline.maps.catalog import Catalog
    cat = Catalog.rebuild(args.catalog)
    print(f"indexed {len(cat.entries)} shards under {args.catalog}")
    for problem in cat.problems:
        print(f"pinfeed: warning: {problem}", file=sys.stderr)


def cmd_catalog_list(args):
    """``pinfeed catalog list``: one row per stored part (or JSON)."""
    rows = _catalog(args).parts()
    if args.json:
        print_json(rows, indent=1)
        return
    print(f"{'family':<18} {'part':<28} {'models':<22} {'mu_c':<18} {'v_pin/v_b':<16} {'d x theta_i':<12} "
          f"supports")
    for r in rows:
        print(f"{r['family']:<18} {r['part_id']:<28} {','.join(r['models']):<22} "
              f"{','.join(f'{m:g}' for m in r['mu_c']):<18} "
              f"{','.join(f'{v:g}' for v in r['v_pin']):<16} {r['n_d']} x {r['n_theta']:<8} "
              f"{'; '.join(r['supports'])}")


def cmd_catalog_show(args):
    """``pinfeed catalog show``: a part's stored shards and provenance."""
    cat = _catalog(args)
    entries = cat.entries_for(args.part)
    if args.support is not None:
        entries = cat.entries_on(args.part, args.support)
    e0 = entries[0]
    info = {k: e0[k] for k in ("family", "part_id", "part_name", "part_vertices", "pin_radius",
                               "d", "theta_step", "config_hash", "pinfeed_version", "git_commit")}
    if e0.get("part_holes"):
        info["part_holes"] = e0["part_holes"]
    info["shards"] = [dict({k: e[k] for k in ("model", "mu_c", "file", "sha256", "created")},
                           v_pin=e.get("v_pin", 0.0), support=e.get("support", "uniform"))
                      for e in sorted(entries, key=lambda e: (e["model"], e["mu_c"], e.get("v_pin", 0.0),
                                                              e.get("support_key", "")))]
    if args.json:
        print_json(info, indent=1)
        return
    print(f"part {info['part_id']} (family {info['family']})")
    print("vertices (body frame, mm): " + " ".join(f"{x:.3f},{y:.3f}" for x, y in info["part_vertices"]))
    for k, hole in enumerate(info.get("part_holes", []), start=1):
        print(f"hole {k} (body frame, mm): " + " ".join(f"{x:.3f},{y:.3f}" for x, y in hole))
    print(f"pin radius {info['pin_radius']:g} mm; theta step {info['theta_step']:g} deg; "
          f"d = {', '.join(f'{d:g}' for d in info['d'])}")
    print(f"made by pinfeed {info['pinfeed_version']} ({info['git_commit']}), config {info['config_hash']}")
    for sh in info["shards"]:
        print(f"  {sh['model']:<10} mu_c={sh['mu_c']:<6g} v_pin/v_b={sh['v_pin']:<5g} {sh['file']}  "
              f"{sh['created']}" + ("" if sh["support"] == "uniform" else f"  support {sh['support']}"))


def _query(args):
    """The stored maps a query or plot asks for (``--part``, ``--model``, ``--mu-c``, ``--d`` ...)."""
    cat = _catalog(args)
    d = parse_values(args.d, "--d") if args.d is not None else None
    ds = cat.query(args.part, model=args.model, mu_c=args.mu_c, d=d, method=args.method,
                   v_pin=args.v_pin, support=args.support)
    if getattr(args, "theta_i", None) is not None:
        ds = ds.sel(theta_i=parse_values(args.theta_i, "--theta-i"), method="nearest")
    return ds


def cmd_catalog_query(args):
    """``pinfeed catalog query``: outcomes of one part at the asked mu_c, d and theta_i."""
    from pipeline.maps.simulate import status_names
    ds = _query(args).load()
    rows = []
    for mu in ds["mu_c"].values:
        for d in ds["d"].values:
            sub = ds.sel(mu_c=mu, d=d)
            for k, th in enumerate(sub["theta_i"].values):
                rows.append({"mu_c": float(mu), "d": float(d), "theta_i": float(th),
                             "status": str(status_names(sub["status"].values[k])),
                             "theta_f": float(sub["theta_f"].values[k]), "dy": float(sub["dy"].values[k])})
    if args.json:
        print_json({"part": ds.attrs.get("part_id"), "model": args.model, "v_pin": args.v_pin,
                     "support": str(ds["support"].values), "selection": ds.attrs["selection"], "rows": rows})
        return
    print(f"selection: {ds.attrs['selection']}")
    print(f"{'mu_c':>6} {'d':>6} {'theta_i':>8} {'status':>9} {'theta_f':>9} {'dy (mm)':>9}")
    for r in rows:
        print(f"{r['mu_c']:6g} {r['d']:6g} {r['theta_i']:8.2f} {r['status']:>9} {r['theta_f']:9.3f} {r['dy']:9.3f}")


def cmd_catalog_plot(args):
    """``pinfeed catalog plot``: draw one part's stored map at one friction."""
    from pipeline.checks import IMAGE_SUFFIXES, check_out_path
    from pipeline.present.figures.maps import plot_map
    check_out_path(args.out, IMAGE_SUFFIXES)
    ds = _query(args)
    if ds.sizes["mu_c"] != 1:
        raise PinfeedError("plot one friction at a time: give --mu-c")
    sub = ds.isel(mu_c=0).load()
    sub.attrs["mu_c"] = float(ds["mu_c"].values[0])
    print(f"selection: {ds.attrs['selection']}")
    print(f"wrote {plot_map(sub, args.out, bands=bands_option(args.bands))}")


def add_catalog_commands(sub) -> None:
    """``catalog index|list|show|query|plot``: the map database."""
    cat = sub.add_parser("catalog", help="the map database: list, show, query, plot, index")
    csub = cat.add_subparsers(dest="catalog_command", required=True)

    def catalog_parser(name, help_text, func):
        q = csub.add_parser(name, help=help_text)
        q.add_argument("--catalog", default="catalog", help="catalog folder (default: catalog)")
        q.set_defaults(func=func)
        return q

    catalog_parser("index", "rebuild the index from the shards on disk", cmd_catalog_index)
    q = catalog_parser("list", "list the parts stored", cmd_catalog_list)
    add_json_option(q, "print the parts as a JSON list instead of a table")
    q = catalog_parser("show", "everything stored about one part", cmd_catalog_show)
    q.add_argument("part", help="part name or id")
    q.add_argument("--support", default=None, metavar="SPEC",
                   help="only the shards of this support (its text or file key); default: every support")
    add_json_option(q, "print the part and its shards as JSON instead of text")
    for name, func, help_text in (("query", cmd_catalog_query, "maps of one part, model, friction, d"),
                                  ("plot", cmd_catalog_plot, "draw stored maps like the paper's Table 1")):
        q = catalog_parser(name, help_text, func)
        q.add_argument("--part", required=True, help="part name or id")
        q.add_argument("--model", default="minpower", choices=["minpower", "tip", "ellipsoid"],
                       help="contact model of the maps (default minpower)")
        q.add_argument("--mu-c", type=float, default=None, help="friction (nearest/bracketing stored value)")
        q.add_argument("--d", default=None, help="contact parameter(s): 'a,b' or 'start:stop:step'")
        q.add_argument("--method", default="nearest", choices=["nearest", "bracket"],
                       help="how to pick stored mu_c and d values (default nearest)")
        q.add_argument("--v-pin", dest="v_pin", type=float, default=0.0,
                       help="pin speed ratio v_pin/v_b of the maps (stored exactly; default 0, static)")
        q.add_argument("--support", default="uniform", metavar="SPEC",
                       help="support distribution of the maps (sweep.supports; stored exactly): its "
                            "text ('tripod', 'rim:64', 'points:...') or file key; default uniform")
        if name == "query":
            q.add_argument("--theta-i", default=None,
                           help="only these initial orientations (nearest stored)")
            add_json_option(q, "print the selection and its rows as JSON instead of a table")
        else:
            q.add_argument("--out", required=True, help="image file (.png, .pdf, .svg)")
            q.add_argument("--bands", default=None, metavar="T,C",
                           help="also draw the bands: threshold T (deg) and factor c, e.g. 5,2")

