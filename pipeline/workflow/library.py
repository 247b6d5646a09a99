"""A parts library: a folder of CAD drawings in, every part's answer out.

The config key ``library`` lists drawings (files, folders, glob patterns;
``.dxf`` and ``.svg``). The workflow (``rules/library.smk``) then runs

- one ``library_read`` job per drawing: a record of its parts (label
  ``FILE#N``, size, holes) or of why it cannot be read, never a failure;
- one ``library_part`` job per part, whose only input is its own drawing: the
  tight planner under ``library.time_limit_s``, a thumbnail with the holes,
  and, when fixed pins orient the part, its feeder layout (and, with
  ``library.animate``, an animation), all in ``LIBRARY/parts/KEY/``. A part
  the planner refuses (too many vertices, a pin too large for it) or a
  planning step that fails writes its one-line reason there instead, so the
  other parts and the report go on;
- ``library`` (the target): ``RESULTS/library.html``, ``library.json`` and
  ``library.csv``, one row per part (:func:`library_rows`, drawn by
  :mod:`pipeline.present.library`).

Which parts a drawing holds is read when the workflow loads (a few hundredths
of a second a drawing), cached by the drawing's content in
``.snakemake/pinfeed-library/`` so that every job of a cluster run does not
read them all again. A drawing added later adds its own jobs only; a drawing
changed reruns its own.
"""
from __future__ import annotations

import glob
import hashlib
import json
import os
import re
from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.present.library import CLASS_TEXT, CLASSES  # noqa: F401  (the classes, named here too)

SUFFIXES = (".dxf", ".svg")
READER_KEYS = ("layer", "flatten_tol", "units", "join_tol")
CACHE = Path(".snakemake") / "pinfeed-library"
# ---------------------------------------------------------------- which drawings, which parts


def library_files(paths) -> list[Path]:
    """The drawings ``paths`` name: a file as it is, a folder's ``.dxf`` and
    ``.svg`` files (not its subfolders), a glob pattern's matches (``**``
    included), in sorted order without repeats. Files of other kinds are left
    out; a library that names no drawing at all is a one-line error."""
    found = []
    for entry in paths:
        p = Path(entry)
        if p.is_dir():
            found += [f for f in sorted(p.iterdir()) if f.is_file() and f.suffix.lower() in SUFFIXES]
        elif p.is_file():
            found.append(p)
        else:
            found += [Path(f) for f in sorted(glob.glob(str(entry), recursive=True))
                      if Path(f).is_file() and Path(f).suffix.lower() in SUFFIXES]
    seen, out = set(), []
    for f in found:
        key = f.resolve()
        if key not in seen:
            seen.add(key)
            out.append(f)
    if not out:
        raise PinfeedError(f"config error at library/paths: {', '.join(map(str, paths))} name no .dxf or "
                           f".svg drawing; give files, folders or glob patterns of drawings")
    return out


def safe_name(text: str) -> str:
    """``text`` in file-name-safe characters (letters, digits, ``_ . -``)."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", text).lstrip(".-") or "drawing"


def drawing_ids(files) -> dict:
    """``{id: path}``: each drawing's id is its file name, or, where two share a
    name, its path below their common folder (``/`` as ``__``)."""
    files = [Path(f) for f in files]
    names = [f.name for f in files]
    dup = {n for n in names if names.count(n) > 1}
    common = Path(*Path(files[0]).resolve().parts[:1]) if files else Path("/")
    if dup:
        import os
        common = Path(os.path.commonpath([str(f.resolve().parent) for f in files]))
    out = {}
    for f in files:
        ident = f.name if f.name not in dup else "__".join(f.resolve().relative_to(common).parts)
        out[safe_name(ident)] = f
    return out


def part_key(drawing_id: str, label: str) -> str:
    """The file key of the part labelled ``FILE#N`` of drawing ``drawing_id``: ``ID-N``."""
    return f"{drawing_id}-{label.rsplit('#', 1)[1]}"


def part_name(drawing_id: str, label: str) -> str:
    """The part's name in its plan file (letters, digits, underscore)."""
    stem = re.sub(r"[^A-Za-z0-9_]", "_", drawing_id.rsplit(".", 1)[0])
    return f"{stem}_{label.rsplit('#', 1)[1]}"


def reader_options(lib: dict) -> dict:
    """The CAD reader's options of the library (``layer``, ``flatten_tol``, ...)."""
    return {k: lib.get(k) for k in READER_KEYS}


def read_drawing(path, options: dict):
    """``(sheet or None, error or None)``: every part of the drawing, the
    unreadable ones listed in ``sheet.refused``; a drawing that cannot be read
    at all gives its one-line reason instead."""
    from pipeline.parts.outlines import read_sheet
    try:
        return read_sheet(path, strict=False, **options), None
    except PinfeedError as exc:
        return None, str(exc).splitlines()[0]
    except Exception as exc:  # noqa: BLE001  a library reader must not stop the others
        return None, f"{path}: cannot be read ({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"


def _cached_labels(path: Path, options: dict, cache: Path) -> list[str]:
    """The labels of the readable parts of ``path``, cached by content and options."""
    digest = hashlib.sha256(path.read_bytes() + json.dumps(options, sort_keys=True).encode()).hexdigest()[:24]
    stored = cache / f"{digest}.json"
    if stored.is_file():
        try:
            return json.loads(stored.read_text())["labels"]
        except (ValueError, KeyError):
            pass
    sheet, _ = read_drawing(path, options)
    labels = [o.label for o in sheet.parts] if sheet else []
    try:
        cache.mkdir(parents=True, exist_ok=True)
        tmp = stored.with_suffix(f".{digest[:6]}.tmp")
        tmp.write_text(json.dumps({"file": str(path), "labels": labels}))
        tmp.replace(stored)
    except OSError:
        pass  # a read-only folder: read again next time
    return labels


def library_plan(config: dict, cache: Path = CACHE) -> dict:
    """What the workflow runs for ``config["library"]``: ``{"drawings": {id:
    path}, "parts": {key: {"drawing", "label", "name"}}}`` (empty without a
    library)."""
    lib = config.get("library")
    if not lib:
        return {"drawings": {}, "parts": {}}
    drawings = drawing_ids(library_files(lib["paths"]))
    options = reader_options(lib)
    parts = {}
    for ident, path in drawings.items():
        for label in _cached_labels(Path(path), options, Path(cache)):
            parts[part_key(ident, label)] = {"drawing": ident, "label": label, "name": part_name(ident, label)}
    return {"drawings": {k: str(v) for k, v in drawings.items()}, "parts": parts}


def drawing_lookup(plan: dict):
    """The input function of the library's jobs: the drawing a job reads (by
    its ``drawing`` wildcard, or its part's ``key``)."""
    def drawing(wildcards):
        if "key" in wildcards.keys():
            return plan["drawings"][plan["parts"][wildcards.key]["drawing"]]
        return plan["drawings"][wildcards.drawing]
    return drawing


def part_runtime(config: dict):
    """The ``runtime`` resource of a part's job (minutes, for a cluster): its
    time limit, the steps after it (speed limits, layout) and Python's start;
    doubled on each retry."""
    limit = (config.get("library") or {}).get("time_limit_s")

    def runtime(wildcards, attempt):
        return (120 if limit is None else int(3 + 3 * float(limit) / 60)) * attempt
    return runtime


# ---------------------------------------------------------------- the jobs


def write_read_record(drawing_id: str, path, lib: dict, out) -> dict:
    """Rule ``library_read``: :func:`read_record`, written to ``out``."""
    from pipeline.maps.io import write_json
    rec = read_record(drawing_id, path, lib)
    write_json(rec, out)
    return rec


def read_record(drawing_id: str, path, lib: dict) -> dict:
    """Rule ``library_read``: the drawing's parts (label, key, size, vertices,
    holes), the parts refused with their reasons, what was left out, or the
    reason the drawing cannot be read."""
    from pipeline.provenance import provenance_attrs
    sheet, error = read_drawing(path, reader_options(lib))
    rec = {"drawing": drawing_id, "file": str(path), "error": error, "parts": [], "refused": [],
           "left_out": [], **provenance_attrs()}
    if sheet is None:
        return rec
    rec["units"] = {"name": sheet.units.name, "source": sheet.units.source}
    rec["left_out"] = list(sheet.left_out)
    for o in sheet.parts:
        w, h = o.size_mm[:2]
        rec["parts"].append({"label": o.label, "key": part_key(drawing_id, o.label),
                             "name": part_name(drawing_id, o.label), "width_mm": round(float(w), 3),
                             "height_mm": round(float(h), 3), "vertices": int(len(o.vertices)),
                             "holes": len(o.holes)})
    rec["refused"] = [{"label": label, "reason": reason} for label, reason in sheet.refused]
    return rec


def library_settings(config: dict) -> dict:
    """The config the library's parts are planned with: the planner's own,
    under ``library.time_limit_s`` (tight planner only), at ``planner.mu_c``
    alone: the answer is the plan for that friction range, so the extra
    frictions of ``planner.frictions`` (``pinfeed plan --mu-c`` drops them
    too) would only share its time limit."""
    from pipeline.workflow.commands import planner_settings
    lib = config["library"]
    return planner_settings(config, time_limit=lib.get("time_limit_s"), mu_c=str(config["planner"]["mu_c"]))


def plan_library_part(config: dict, drawing_path, label: str, name: str, out_dir) -> dict:
    """Rule ``library_part``: plan one part of the library into ``out_dir``
    (``part.json`` always; ``plan.json``, ``part.svg``, ``layout.*`` and
    ``animation.gif`` when made). Never raises for the part's own reasons:
    a refusal or a failed step is recorded with its one-line reason."""
    import time
    import traceback

    from pipeline.maps.io import write_json
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    lib = config["library"]
    start = time.perf_counter()
    rec = {"label": label, "name": name, "file": str(drawing_path), "status": "planned", "reason": None,
           "files": {}, "notes": []}
    try:
        sheet, error = read_drawing(drawing_path, reader_options(lib))
        if sheet is None:
            raise PinfeedError(error)
        outline = next((o for o in sheet.parts if o.label == label), None)
        if outline is None:
            raise PinfeedError(f"{drawing_path} no longer holds a readable part {label}; run the workflow again")
        part = outline.part(name)
        rec.update(width_mm=round(float(outline.size_mm[0]), 3), height_mm=round(float(outline.size_mm[1]), 3),
                   vertices=int(len(outline.vertices)), holes=len(outline.holes),
                   resting_states=int(len(part.stable_states())))
        from pipeline.present.library import draw_thumbnail
        draw_thumbnail(part, out / "part.svg")
        rec["files"]["thumbnail"] = "part.svg"
        from pipeline.workflow.commands import plan_command
        settings = library_settings(config)
        result = plan_command(part, settings, "tight", progress=lambda line: print(line, flush=True))
        write_json(result, out / "plan.json")
        rec["files"]["plan"] = "plan.json"
        states = ((result.get("tight") or [{}])[0] or {}).get("initial_states")
        if states:
            rec["resting_states"] = len(states)
        _extras(result, settings, lib, out, rec)
    except PinfeedError as exc:
        rec.update(status="refused", reason=str(exc).splitlines()[0])
        print(f"pinfeed: refused: {rec['reason']}", flush=True)
    except Exception as exc:  # noqa: BLE001  one part's failure must not stop the library
        traceback.print_exc()
        rec.update(status="failed", reason=f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
                   " (traceback in the job's log)")
    rec["seconds"] = round(time.perf_counter() - start, 1)
    write_json(rec, out / "part.json")
    return rec


def _extras(result: dict, config: dict, lib: dict, out: Path, rec: dict) -> None:
    """The layout (fixed pins that orient the part) and, with ``library.animate``,
    an animation of the recommended plan; a failure is a note, not an error."""
    entry = (result.get("tight") or [{}])[0] or {}
    plan = entry.get("recommended")
    fixed = bool(plan) and not (plan.get("n_dynamic_pins") or 0)
    if lib.get("layout", True) and fixed and entry.get("orients"):
        try:
            from pipeline.workflow.layout import layout_part
            layout_part(result, config, {k: out / f"layout.{k}" for k in ("json", "dxf", "svg", "png")})
            rec["files"].update(layout="layout.svg", layout_json="layout.json")
        except Exception as exc:  # noqa: BLE001
            rec["notes"].append(f"layout not made: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}")
    if lib.get("animate", False) and plan:
        try:
            from pipeline.workflow.commands import animate_stored
            animate_stored(result, config, out / "animation.gif")
            rec["files"]["animation"] = "animation.gif"
        except Exception as exc:  # noqa: BLE001
            rec["notes"].append(f"animation not made: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}")


# ---------------------------------------------------------------- rows


def answer(plan_result: dict | None) -> dict:
    """The answer class of a plan file and what goes with it: ``class`` (one of
    :data:`CLASSES` but ``not readable``), ``text``, pins, the claim's set and
    width, ``complete``, the nearest "yes"."""
    from pipeline.workflow.atlas import atlas_row
    row = atlas_row(plan_result)
    entry = (plan_result.get("tight") or [{}])[0] or {}
    complete = bool(entry.get("complete", True))
    plan = entry.get("recommended")
    verdict = ((plan or {}).get("verification") or {}).get("orientation") or {}
    if row["outcome"] == "no pin needed":
        verdict = (entry.get("fixed_pin_search") or {}).get("resting") or {}
    nearest = [f"{a['axis']}: {a['statement']}" for a in (entry.get("nearest_yes") or {}).get("axes", [])
               if a.get("found")]
    if row["outcome"] in ("fixed pins", "no pin needed"):
        cls = "fixed pins"
        n = row["fixed_pins"] or 0
        text = "orients with no pin (its resting states)" if n == 0 else \
            f"orients with {n} fixed pin{'s' if n != 1 else ''}"
    elif row["outcome"] == "moving pins":
        cls, text = "moving pins", f"needs moving pins ({row['fixed_pins']} fixed + {row['moving_pins']} moving)"
    elif not complete:
        cls = "not decided"
        fixed = entry.get("fixed_pin_search") or {}
        if fixed.get("complete"):
            text = (f"not decided: no plan of up to {fixed.get('depth')} fixed pins orients it (searched in "
                    "full); the time limit cut the moving pins' search")
        else:
            upto = fixed.get("complete_to_pins") or 0
            text = ("not decided: the time limit cut the fixed-pin search"
                    + (f" (complete up to {upto} pin{'s' if upto != 1 else ''})" if upto else ""))
        if row["plan"]:
            text += f"; best so far: {row['plan']}, {row.get('sets')} sets"
    elif row["outcome"] == "sensor":
        cls, text = "sensor", f"needs the sensor: {row['plan']} ends in {row.get('sets')} sets"
    else:
        cls = "no"
        text = "no: " + ("; ".join(nearest) if nearest else "no nearest \"yes\" found")
    if cls not in ("fixed pins", "moving pins"):
        verdict = {}  # no claim: no set, no width
    s = verdict.get("set") or {}
    return {"class": cls, "text": text, "fixed_pins": row["fixed_pins"], "moving_pins": row["moving_pins"],
            "plan": row["plan"], "set_start_deg": s.get("start"), "width_deg": verdict.get("width_deg"),
            "share_lower_bound": verdict.get("share_lower_bound"), "sets": row.get("sets"),
            "complete": complete, "nearest_yes": "; ".join(nearest) or None,
            "tolerance_deg": entry.get("tolerance_deg"),
            "planning_seconds": row.get("planning_seconds")}


# ---------------------------------------------------------------- the library's rows


def _row(**values) -> dict:
    from pipeline.present.library import COLUMNS
    return {k: values.get(k) for k in COLUMNS}


def library_rows(records, part_dirs, base, logs: dict | None = None) -> list[dict]:
    """One row per part (and per unreadable drawing or part) from the drawings'
    read records and the parts' folders (``{key: folder}``); paths in the rows
    are relative to ``base`` (the page's folder). ``logs``: key -> a part job's log."""
    rows = []
    for rec in sorted(records, key=lambda r: r["drawing"]):
        name = Path(rec["file"]).name
        if rec.get("error"):
            rows.append(_row(label=name, drawing=rec["drawing"], key=rec["drawing"], **{"class": "not readable"},
                             answer=f"not readable: {rec['error']}", reason=rec["error"]))
            continue
        for part in rec["parts"]:
            folder = Path(part_dirs.get(part["key"], ""))
            rows.append(_part_row(rec, part, folder, base, (logs or {}).get(part["key"]), answer))
        for ref in rec["refused"]:
            rows.append(_row(label=ref["label"], drawing=rec["drawing"], key=part_key_of(rec, ref["label"]),
                             **{"class": "not readable"}, answer=f"not readable: {ref['reason']}",
                             reason=ref["reason"]))
    rows.sort(key=lambda r: (r["drawing"], int(r["label"].rsplit("#", 1)[1]) if "#" in r["label"] else -1))
    return rows


def part_key_of(rec: dict, label: str) -> str:
    """The row key of a refused part (``ID-N``), or of a drawing not read at all (its id)."""
    return part_key(rec["drawing"], label) if "#" in label else rec["drawing"]


def _part_row(rec, part, folder: Path, base, log, answer) -> dict:
    def rel(name):
        return os.path.relpath(folder / name, base) if name else None
    info = {}
    if (folder / "part.json").is_file():
        info = json.loads((folder / "part.json").read_text())
    files = info.get("files") or {}
    common = dict(label=part["label"], drawing=rec["drawing"], key=part["key"],
                  width_mm=part["width_mm"], height_mm=part["height_mm"], vertices=part["vertices"],
                  holes=part["holes"], resting_states=info.get("resting_states"),
                  thumbnail=rel(files.get("thumbnail")), plan_file=rel(files.get("plan")),
                  layout=rel(files.get("layout")), animation=rel(files.get("animation")),
                  log=os.path.relpath(log, base) if log and Path(log).is_file() else None,
                  planning_seconds=info.get("seconds"))
    if not info:
        return _row(**common, **{"class": "not readable"}, answer="not planned: its job left no record",
                    reason="its job left no record (see its log)")
    if info["status"] != "planned":
        what = "refused by the planner" if info["status"] == "refused" else "planning failed"
        return _row(**common, **{"class": "not readable"}, answer=f"not readable ({what}): {info['reason']}",
                    reason=info["reason"])
    plan = json.loads((folder / "plan.json").read_text())
    ans = answer(plan)
    cut = not ans["complete"] and ans["class"] != "not decided"  # "not decided" says so itself
    text = ans["text"] + (" [search not complete: time limit]" if cut else "")
    return _row(**common, **{"class": ans["class"]}, answer=text,
                **{k: ans[k] for k in ("fixed_pins", "moving_pins", "plan", "set_start_deg", "width_deg",
                                       "share_lower_bound", "sets", "complete", "nearest_yes")})


def library_report(config: dict, record_paths, part_dirs: dict, outputs: dict, logs: dict | None = None) -> dict:
    """Rule ``library``: the rows of every part (:func:`pipeline.present.library.library_rows`)
    written as ``outputs["html"]``, ``["json"]`` and ``["csv"]``."""
    from pipeline.present.library import write_library
    from pipeline.provenance import provenance_attrs
    if not config.get("library"):
        raise PinfeedError("this config has no parts library: add the key library (paths: the drawings), "
                           "or run 'pinfeed library DRAWINGS'")
    records = [json.loads(Path(p).read_text()) for p in record_paths]
    base = Path(outputs["html"]).parent
    rows = library_rows(records, part_dirs, base, logs)
    pc = config["planner"]
    meta = {"name": config.get("name"), "time_limit_s": config["library"].get("time_limit_s"),
            "tolerance_deg": pc.get("tolerance_deg"), "depth": pc.get("depth"), "mu_c": pc.get("mu_c"),
            "drawings": len(records), **provenance_attrs()}
    return write_library(rows, outputs["html"], outputs["json"], outputs["csv"], meta)
