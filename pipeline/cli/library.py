"""``pinfeed library``: a folder of drawings in, every part's answer out.

Writes a workflow config with a ``library`` section (the drawings, the CAD
reader's options, the time limit each part's planning may take) next to the
library's results and runs the workflow's ``library`` target on it, as
``make run`` runs the default config: one job per drawing and one per part,
going on past a part that fails, then ``RESULTS/library.html``,
``library.json`` and ``library.csv``. Run again after adding drawings, it
plans only the new ones.
"""
from __future__ import annotations

from pathlib import Path

from pipeline.errors import PinfeedError


def library_config(args) -> dict:
    """The workflow config of ``pinfeed library``'s arguments: the base config
    (``--config``, default the embedded one) with the ``library`` section, the
    name and the results folder; the drawings as absolute paths."""
    import yaml

    from pipeline.config import DEFAULT_CONFIG
    base = Path(args.config) if args.config else DEFAULT_CONFIG
    if not base.is_file():
        raise PinfeedError(f"no config file at {base}; pass an existing YAML file")
    cfg = yaml.safe_load(base.read_text()) or {}
    for key in ("catalog_dir", "results_dir"):  # the base config's folders, as seen from here
        if key in cfg and args.config and not Path(cfg[key]).is_absolute():
            cfg[key] = str(base.resolve().parent / cfg[key])
    cfg["name"] = args.name
    if args.results_dir:
        cfg["results_dir"] = args.results_dir
    paths = []
    for p in args.drawings:
        if not p.strip():
            raise PinfeedError("an empty drawing path; give DXF or SVG files, folders or glob patterns")
        paths.append(str(Path(p).resolve()) if not any(c in p for c in "*?[") else str(Path.cwd() / p))
    cfg["library"] = {"paths": paths, "layer": args.layer, "flatten_tol": args.flatten_tol, "units": args.units,
                      "join_tol": args.join_tol, "time_limit_s": args.time_limit, "layout": not args.no_layout,
                      "animate": args.animate}
    if args.depth is not None:
        if args.depth < 1:
            raise PinfeedError(f"--depth must be at least 1 (the largest number of pins), got {args.depth}")
        cfg.setdefault("planner", {})["depth"] = args.depth
    return cfg


def cmd_library(args) -> None:
    """Write the library's config, check it, and run the workflow's ``library`` target."""
    import yaml

    from pipeline.config import results_folder, validate_config
    from pipeline.workflow.library import library_plan
    if args.time_limit is not None and not args.time_limit > 0:
        raise PinfeedError(f"--time-limit must be a number of seconds above 0, got {args.time_limit:g}")
    cfg = library_config(args)
    checked = validate_config(cfg, name=args.name)  # a bad option: one line, before any job
    plan = library_plan(checked)
    out = results_folder(checked)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "library.yaml"
    path.write_text("# written by pinfeed library; run again with the same arguments, or:\n"
                    f"#   snakemake --cores all --configfile {path} library\n" + yaml.safe_dump(cfg, sort_keys=False))
    print(f"pinfeed: {len(plan['drawings'])} drawing(s), {len(plan['parts'])} readable part(s); "
          f"config {path}", flush=True)
    import os
    import sys

    from pipeline.maps.warm import warm_kernels
    from pipeline.workflow.runner import run
    snakefile = Path(__file__).resolve().parents[2] / "Snakefile"
    if not snakefile.is_file():
        raise PinfeedError(f"no Snakefile at {snakefile}: pinfeed library runs the workflow of a source "
                           "checkout (pip install -e .)")
    # the Snakemake of this environment, as make run finds it
    os.environ["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"
    snake = ["-s", str(snakefile), "--cores", str(args.cores), "--configfile", str(path),
             "--rerun-incomplete", "--keep-going"]
    if args.dry_run:
        snake.append("--dry-run")
    else:  # compiled once here, not by each job at once (a first run after an install)
        warm_kernels(lambda line: print(f"pinfeed: {line}", flush=True))
    code = run([*snake, "library"])
    if code:
        raise SystemExit(code)


def add_library_command(sub) -> None:
    """``library``: plan every part of a folder of drawings (the workflow's ``library`` target)."""
    p = sub.add_parser("library", help="plan every part of a folder of drawings: one row per part in "
                       "RESULTS/library.html, .json and .csv (the workflow's library target)",
                       description="Plan every part of a library of DXF and SVG drawings with the workflow: "
                       "one job per drawing and one per part (a sheet of several parts gives several, "
                       "labelled FILE#N), each part's planning under a time limit; a drawing or part that "
                       "cannot be read or planned is listed with its reason and the others go on. Running "
                       "it again after adding drawings plans only the new ones.")
    p.add_argument("drawings", nargs="+", metavar="DRAWINGS",
                   help="DXF or SVG files, folders (their .dxf and .svg files) or quoted glob patterns "
                   "(the shell's wildcards, matched below the folder too with a double star)")
    p.add_argument("--name", default="library", help="the library's name: results go to RESULTS_DIR/NAME/ "
                   "(default: library)")
    p.add_argument("--results-dir", dest="results_dir", default=None,
                   help="folder of the results (default: the config's results_dir, results)")
    p.add_argument("--config", default=None, help="base workflow config YAML whose planner, verify and "
                   "layout settings the parts are planned with (default: the embedded one)")
    p.add_argument("--time-limit", dest="time_limit", type=float, default=60.0, metavar="S",
                   help="seconds each part's planning may take (library.time_limit_s; default 60); a part "
                   "the limit cut without a verified plan is 'not decided'")
    p.add_argument("--depth", type=int, default=None, help="largest number of pins (default: the "
                   "config's planner.depth)")
    p.add_argument("--layer", default=None, help="read this layer alone in every drawing (a DXF layer or "
                   "an Inkscape layer's label)")
    p.add_argument("--flatten-tol", dest="flatten_tol", type=float, default=None, metavar="MM",
                   help="chordal tolerance for arcs and curves, mm (default 0.05)")
    p.add_argument("--units", default=None, choices=["mm", "cm", "m", "in"],
                   help="units of the drawings' coordinates (default: each file's own)")
    p.add_argument("--join-tol", dest="join_tol", type=float, default=None,
                   help="largest gap between piece ends joined into a loop, drawing units")
    p.add_argument("--no-layout", dest="no_layout", action="store_true",
                   help="do not lay out the feeders of the parts fixed pins orient")
    p.add_argument("--animate", action="store_true", help="also animate each part's recommended plan (slower)")
    p.add_argument("--cores", default="all", help="cores Snakemake may use (default: all)")
    p.add_argument("--dry-run", "-n", dest="dry_run", action="store_true",
                   help="print the jobs that would run (Snakemake's dry run) and run none")
    p.set_defaults(func=cmd_library)
