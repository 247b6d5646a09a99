"""The map database: an index of every shard under ``catalog/``, checked against disk.

The index (``catalog/index.json``) is rebuilt from the shards' own
attributes, never edited by hand, and written atomically. Opening a catalog
checks each entry against its file: entries whose files are gone or changed
are reported in :attr:`Catalog.problems` and never served; a re-index drops
them. Foreign or corrupt ``.h5`` files are reported by name.

Queries return lazy (dask-backed) xarray objects::

    cat = Catalog.open("catalog")
    ds = cat.query(part="asym_triangle", model="minpower", mu_c=0.2, d=0.3)
    ds.attrs["selection"]   # e.g. "mu_c 0.2 -> nearest stored 0.15; d 0.3 -> 0.3"
    moving = cat.query("asym_triangle", mu_c=0.15, v_pin=-2)   # a dynamic pin's maps
    tripod = cat.query("asym_triangle", mu_c=0.15, support="tripod")
    cube = cat.cube("paper_triangles")   # dims (part, model, mu_c, v_pin[, support], d, theta_i)

Shards written before dynamic pins existed have no ``v_pin`` attribute and
count as static pins (v_pin = 0); shards without a ``support`` attribute are
uniform pressure. A query serves one support (default uniform), named by
its text (``tripod``, ``rim:64``, ``points:...``) or its file key
(``pipeline.parts.support.support_key``).

Integrity: each entry records the shard's SHA-256, size and modification
time. Opening a catalog (``catalog list/show``, every query) compares size and
time with the disk and re-hashes only the shards whose time changed, so a
shard overwritten with same-size garbage is flagged without hashing the whole
catalog; serving a shard always checks its hash (once per opened catalog).
The index itself is checked against :data:`INDEX_SCHEMA`; a malformed one is
refused with the command that rebuilds it.
"""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np
import xarray as xr

from pipeline.checks import schema_problem
from pipeline.errors import PinfeedError
from pipeline.maps.io import write_json
from pipeline.parts.part import Part
from pipeline.parts.support import support_key

INDEX_NAME = "index.json"
# The planner's refinement shards (pipeline.planning.tight.store) live under
# ROOT/refine/PART_ID/...: listed by the index apart from the maps.
REFINE_FOLDER = "refine"
INDEX_VERSION = 1
RECOMPUTE = ("recompute it with 'make run' (snakemake) or 'pinfeed sweep --config CONFIG', "
             "which re-indexes the catalog")

_NUM = {"type": "number"}
_STR = {"type": "string"}
INDEX_SCHEMA = {
    "type": "object",
    "required": ["index_version", "entries"],
    "properties": {
        "index_version": {"const": INDEX_VERSION},
        "problems": {"type": "array", "items": _STR},
        "entries": {"type": "array", "items": {
            "type": "object",
            "required": ["file", "sha256", "size", "family", "part_id", "part_name", "part_vertices",
                         "model", "mu_c", "pin_radius", "d", "theta_step", "n_theta"],
            "properties": {
                # Relative, inside the catalog, an .h5 file.
                "file": {"type": "string", "pattern": r"^(?!/)(?!.*(^|/)\.\.(/|$)).+\.h5$"},
                "sha256": {"type": "string", "pattern": "^[0-9a-f]{64}$"},
                "size": {"type": "integer", "minimum": 0},
                "mtime_ns": {"type": "integer"},
                "family": _STR, "part_id": _STR, "part_name": _STR, "model": _STR,
                "part_vertices": {"type": "array", "minItems": 3,
                                  "items": {"type": "array", "minItems": 2, "maxItems": 2, "items": _NUM}},
                "part_holes": {"type": "array", "items": {
                    "type": "array", "minItems": 3,
                    "items": {"type": "array", "minItems": 2, "maxItems": 2, "items": _NUM}}},
                "mu_c": _NUM, "pin_radius": _NUM, "v_pin": _NUM, "theta_step": _NUM,
                "support": _STR, "support_key": _STR,
                "d": {"type": "array", "items": _NUM},
                "n_theta": {"type": "integer", "minimum": 1},
            },
        }},
    },
}


def entry_part(entry: dict) -> Part:
    """The :class:`~pipeline.parts.part.Part` an index entry describes (its
    outline and, for a part with holes, ``part_holes``)."""
    return Part.from_vertices(entry["part_vertices"], name=entry["part_name"],
                              holes=entry.get("part_holes") or ())


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def entry_from_file(root: Path, path: Path) -> dict:
    """Index entry from a shard's own attributes; raises PinfeedError for foreign/corrupt files."""
    try:
        ds = xr.open_dataset(path, engine="h5netcdf", phony_dims="sort")
    except Exception as exc:
        raise PinfeedError(f"{path}: cannot read as HDF5 (corrupt or not a map file): "
                           f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    with ds:
        attrs = dict(ds.attrs)
        if ("catalog_schema_version" not in attrs or "part_id" not in attrs
                or "d" not in ds.coords or "theta_i" not in ds.coords):
            raise PinfeedError(f"{path}: foreign file, not a pinfeed shard (no catalog attributes)")
        d = [float(x) for x in ds["d"].values]
        n_theta = int(ds.sizes["theta_i"])
    try:
        return _entry(root, path, attrs, d, n_theta)
    except PinfeedError:
        raise
    except (KeyError, ValueError, TypeError) as exc:
        raise PinfeedError(f"{path}: damaged attributes ({type(exc).__name__}: "
                           f"{str(exc).splitlines()[0][:120] if str(exc) else 'unreadable'}); "
                           f"delete the shard and rerun the sweep") from None


def _check_support_attrs(path: Path, attrs: dict) -> str:
    """The shard's support (its ``support`` attribute, uniform if absent), checked
    against its file name (``_support=KEY``, none for uniform) and, for a point
    support, its points and weights; a mismatch is a damaged shard."""
    support = str(attrs.get("support", "uniform"))
    named = re.search(r"_support=([A-Za-z0-9-]+)$", path.stem)
    named = named.group(1) if named else ""
    if _support_key(support) != named:
        raise PinfeedError(f"{path}: damaged support attribute {support[:60]!r}: the file name says "
                           f"{'support ' + named if named else 'uniform'}; delete the shard and rerun "
                           f"the sweep")
    if named:
        pts = np.asarray(attrs.get("support_points", []), float).ravel()
        wts = np.asarray(attrs.get("support_weights", []), float).ravel()
        if (str(attrs.get("model")) != "minpower" or "support_kind" not in attrs or not len(wts)
                or pts.size != 2 * wts.size or not np.all(np.isfinite(pts)) or not np.all(np.isfinite(wts))
                or np.any(wts <= 0)):
            raise PinfeedError(f"{path}: damaged support attributes (support {support[:60]!r} needs model "
                               f"minpower, support_kind and matching finite support_points and positive "
                               f"support_weights); delete the shard and rerun the sweep")
    return support


def _entry(root: Path, path: Path, attrs: dict, d: list, n_theta: int) -> dict:
    """The index entry of a readable shard (see :func:`entry_from_file`)."""
    support = _check_support_attrs(path, attrs)
    verts = np.asarray(attrs["part_vertices"], float).reshape(-1, 2).tolist()
    holes = {"part_holes": [h.tolist() for h in Part.holes_from_attrs(attrs)]} if "part_holes" in attrs else {}
    return {
        "file": path.relative_to(root).as_posix(),
        "sha256": _sha256(path),
        "size": path.stat().st_size,
        "mtime_ns": path.stat().st_mtime_ns,
        "family": str(attrs["family"]),
        "part_id": str(attrs["part_id"]),
        "part_name": str(attrs["part_name"]),
        "part_vertices": verts,
        **holes,
        "model": str(attrs["model"]),
        "mu_c": float(attrs["mu_c"]),
        "pin_radius": float(attrs["pin_radius"]),
        "v_pin": float(attrs.get("v_pin", 0.0)),
        "belt_speed": float(attrs.get("belt_speed", 0.0)),
        "support": support,
        "support_key": _support_key(support),
        "mu_s": float(attrs.get("mu_s", 0.5)),
        "d": d,
        "theta_step": float(attrs["theta_step"]),
        "n_theta": n_theta,
        "config_hash": str(attrs["config_hash"]),
        "pinfeed_version": str(attrs["pinfeed_version"]),
        "git_commit": str(attrs.get("git_commit", "unknown")),
        "created": str(attrs.get("created", "")),
        "schema_version": int(attrs["catalog_schema_version"]),
    }


def read_index(index: Path, root: Path) -> dict:
    """The index as a dict, checked against :data:`INDEX_SCHEMA`."""
    hint = f"rebuild it with 'pinfeed catalog index --catalog {root}'"
    try:
        with open(index) as fh:
            data = json.load(fh)
    except (json.JSONDecodeError, UnicodeDecodeError):
        raise PinfeedError(f"{index} is corrupt; {hint}") from None
    except OSError as exc:
        raise PinfeedError(f"cannot read {index}: {exc.strerror}; check its permissions") from None
    problem = schema_problem(data, INDEX_SCHEMA)
    if problem is not None:
        raise PinfeedError(f"{index} is not a pinfeed catalog index ({problem}); {hint}")
    return data


def disk_problem(path: Path, e: dict) -> str | None:
    """Why an index entry no longer matches its file, or None. Cheap: the file is
    hashed only when its modification time differs from the indexed one."""
    if not path.is_file():
        return f"{path}: listed in the index but gone from disk"
    st = path.stat()
    if st.st_size != e["size"]:
        return f"{path}: changed since it was indexed (size)"
    if st.st_mtime_ns != e.get("mtime_ns") and _sha256(path) != e["sha256"]:
        return f"{path}: changed since it was indexed (checksum)"
    return None


def refinement_fields(relative_path) -> dict:
    """What a refinement file's path (relative to the catalog) says it holds:
    ``part_id``, ``model``, ``v_pin``, ``belt_speed`` (``None``: quasi-static)
    and ``mu_s``, for the catalog index."""
    parts = Path(relative_path).parts
    fields = dict(item.split("=", 1) for item in
                  Path(relative_path).stem.replace("_belt=", "|belt=").replace("_mu_s=", "|mu_s=").split("|")
                  if "=" in item)
    try:
        return {"part_id": parts[1], "model": parts[2], "v_pin": float(fields["v_pin"]),
                "belt_speed": float(fields["belt"]) if "belt" in fields else None,
                "mu_s": float(fields["mu_s"]) if "mu_s" in fields else None}
    except (IndexError, KeyError, ValueError):
        return {}  # not named by lattice_path: listed by file only


def damaged_shard(root: Path, problem: str, entry: dict | None = None) -> dict:
    """What a damaged shard held, for naming it to a command that would have
    used it: from its index entry, else from its path (``shard_path``'s
    ``FAMILY/PART_ID/MODEL/mu_c=M[_v_pin=V][_belt=S_mu_s=X].h5``)."""
    if entry is not None:
        return {"file": entry["file"], "problem": problem, "family": entry["family"],
                "part_id": entry["part_id"], "part_name": entry["part_name"], "model": entry["model"],
                "mu_c": entry["mu_c"], "v_pin": entry.get("v_pin", 0.0),
                "belt_speed": entry.get("belt_speed", 0.0), "support_key": entry.get("support_key", "")}
    file = problem.split(".h5: ", 1)[0] + ".h5" if ".h5: " in problem else ""
    try:
        rel = Path(file).resolve().relative_to(Path(root).resolve())
    except (ValueError, OSError):
        rel = Path(file)
    parts = rel.parts
    tag = dict(re.findall(r"(mu_c|v_pin|belt)=(-?[0-9.eE+-]+?)(?=_[a-z]|$)", rel.stem))
    support = re.search(r"_support=([A-Za-z0-9-]+)$", rel.stem)
    known = len(parts) == 4
    part_id = parts[1] if known else None
    return {"file": rel.as_posix(), "problem": problem, "family": parts[0] if known else None,
            "part_id": part_id, "part_name": part_id.rsplit("-", 1)[0] if part_id else None,
            "model": parts[2] if known else None,
            "mu_c": float(tag["mu_c"]) if "mu_c" in tag else None,
            "v_pin": float(tag.get("v_pin", 0.0)), "belt_speed": float(tag.get("belt", 0.0)),
            "support_key": support.group(1) if support else ""}


class Catalog:
    """An opened catalog: verified entries plus the problems found on disk."""

    def __init__(self, root: Path, entries: list[dict], problems: list[str], damaged: list[dict] | None = None):
        self.root = Path(root)
        self.entries = entries
        self.problems = problems
        # shards not served, with what they held: named by the commands that would use them
        self.damaged = damaged if damaged is not None else [damaged_shard(self.root, p) for p in problems]
        self._verified = set()  # files whose checksum was checked when served

    # ------------------------------------------------------------------ building

    @classmethod
    def rebuild(cls, root="catalog") -> "Catalog":
        """Scan every shard under ``root``, write a fresh index atomically."""
        root = Path(root)
        if not root.is_dir():
            raise PinfeedError(f"no catalog folder at {root}; run the workflow ('make run') first")
        shards, refinements = [], []
        for path in sorted(root.rglob("*.h5")):
            if path.name.startswith("."):
                continue  # an unfinished atomic write
            if path.relative_to(root).parts[0] == REFINE_FOLDER:
                # the planner's on-demand rollouts (pipeline.planning.tight.store), not maps
                rel = path.relative_to(root)
                refinements.append({"file": rel.as_posix(), **refinement_fields(rel),
                                    "sha256": _sha256(path)})
                continue
            shards.append(path)
        cat = cls.of_files(root, shards)
        write_json({"index_version": INDEX_VERSION, "entries": cat.entries, "problems": cat.problems,
                    "refinements": refinements}, root / INDEX_NAME)
        return cat

    @classmethod
    def of_files(cls, root, paths) -> "Catalog":
        """A catalog of the shard files ``paths`` (under ``root``) alone, each read
        from its own attributes without the index: what a workflow job that
        declares the shards it reads sees, whatever else the folder holds. A
        file that is not a readable shard is a problem, as in :meth:`rebuild`."""
        root = Path(root)
        entries, problems = [], []
        for path in paths:
            try:
                entries.append(entry_from_file(root, Path(path)))
            except PinfeedError as exc:
                problems.append(str(exc))
        return cls(root, entries, problems)

    @classmethod
    def open(cls, root="catalog") -> "Catalog":
        """Read the index and check it against the files on disk (size and presence;
        contents are checksummed when an entry is served)."""
        root = Path(root)
        index = root / INDEX_NAME
        if not index.is_file():
            raise PinfeedError(f"no catalog index at {index}; run the workflow ('make run') "
                               f"or 'pinfeed catalog index --catalog {root}'")
        data = read_index(index, root)
        entries, problems = [], list(data.get("problems", []))
        damaged = [damaged_shard(root, p) for p in problems]
        for e in data["entries"]:
            problem = disk_problem(root / e["file"], e)
            if problem:
                problems.append(problem)
                damaged.append(damaged_shard(root, problem, e))
            else:
                entries.append(e)
        return cls(root, entries, problems, damaged)

    # ------------------------------------------------------------------ queries

    def parts(self) -> list[dict]:
        """One row per part: family, id, name, models and frictions stored."""
        rows = {}
        for e in self.entries:
            r = rows.setdefault(e["part_id"], {"family": e["family"], "part_id": e["part_id"],
                                               "part_name": e["part_name"], "n_vertices": len(e["part_vertices"]),
                                               "models": set(), "mu_c": set(), "v_pin": set(),
                                               "supports": set(), "n_d": len(e["d"]), "n_theta": e["n_theta"]})
            r["models"].add(e["model"])
            r["mu_c"].add(e["mu_c"])
            r["v_pin"].add(e.get("v_pin", 0.0))
            r["supports"].add(e.get("support", "uniform"))
        return [dict(r, models=sorted(r["models"]), mu_c=sorted(r["mu_c"]), v_pin=sorted(r["v_pin"]),
                     supports=sorted(r["supports"], key=lambda s: (s != "uniform", s)))
                for r in rows.values()]

    def entries_for(self, part: str) -> list[dict]:
        """The index entries of one part, by id or name.

        Raises :class:`PinfeedError` when the part is unknown, stored in
        several families or its name matches several parts.
        """
        found = [e for e in self.entries if part in (e["part_id"], e["part_name"])]
        if not found:
            _refuse_damaged(self.damaged_of(part), part)
            known = sorted({e["part_name"] for e in self.entries})
            raise PinfeedError(f"unknown part {part!r}; known parts: {', '.join(known) or 'none'} "
                               f"('pinfeed catalog list' shows them)")
        ids = sorted({e["part_id"] for e in found})
        families = sorted({e["family"] for e in found})
        if len(families) > 1:
            raise PinfeedError(f"part {part!r} is stored in several families ({', '.join(families)}); "
                               f"rename it in one of them and re-run the workflow")
        if len(ids) > 1:
            raise PinfeedError(f"part name {part!r} matches several parts ({', '.join(ids)}); give the id")
        return found

    def damaged_of(self, part: str, **fields) -> list[dict]:
        """The damaged shards of ``part`` (name or id) whose known ``fields``
        (``model``, ``belt_speed``, ``v_pin``, ...) match; unknown ones match."""
        return [d for d in self.damaged if part in (d["part_id"], d["part_name"])
                and all(d.get(k) is None or d[k] == v for k, v in fields.items())]

    def _refuse_damaged_in(self, part, model, mu_c, method, v_pin, belt_speed, key="") -> None:
        """Raise when a damaged shard would have been served by this query: its
        friction is the one (or one of those) chosen among all the part's
        frictions, whole or damaged."""
        where = {"model": model, "v_pin": float(v_pin), "belt_speed": float(belt_speed),
                 "support_key": key}
        bad = self.damaged_of(part, **where)
        if mu_c is not None and bad:
            whole = {e["mu_c"] for e in self.entries if part in (e["part_id"], e["part_name"])
                     and all(e.get(k, 0.0) == v for k, v in where.items())}
            stored = sorted(whole | {b["mu_c"] for b in bad if b["mu_c"] is not None})
            chosen = _select(stored, float(mu_c), method) if stored else []
            bad = [b for b in bad if b["mu_c"] is None or b["mu_c"] in chosen]
        _refuse_damaged(bad, part)

    def _open_entry(self, e: dict) -> xr.Dataset:
        path = self.root / e["file"]
        if not path.is_file():
            raise PinfeedError(f"{path} is gone from disk; {RECOMPUTE}")
        if path not in self._verified:
            if _sha256(path) != e["sha256"]:
                raise PinfeedError(f"{path} changed since it was indexed (checksum); {RECOMPUTE}")
            self._verified.add(path)
        return xr.open_dataset(path, engine="h5netcdf", chunks={})

    def entries_on(self, part: str, support: str) -> list[dict]:
        """The entries of one part on one support (its text or file key), or a
        one-line error naming the part's stored supports."""
        found = self.entries_for(part)
        on = [e for e in found if e.get("support_key", "") == _support_key(support)]
        if not on:
            supports = sorted({e.get("support", "uniform") for e in found}, key=lambda s: (s != "uniform", s))
            raise PinfeedError(f"part {part!r} has no maps on support {support!r}; stored supports: "
                               f"{', '.join(supports)} (add it to sweep.supports)")
        return on

    def _stored(self, part, model, belt_speed, support, key, v_pin) -> list[dict]:
        """The entries of one part, model, belt speed, support and pin speed
        (each stored exactly), or a one-line error naming what is stored."""
        found = [e for e in self.entries_for(part) if e["model"] == model]
        if not found:
            models = sorted({e["model"] for e in self.entries_for(part)})
            raise PinfeedError(f"part {part!r} has no {model} maps; stored models: {', '.join(models)}")
        belts = sorted({e.get("belt_speed", 0.0) for e in found})
        found = [e for e in found if e.get("belt_speed", 0.0) == float(belt_speed)]
        if not found:
            raise PinfeedError(f"part {part!r} has no {model} maps at belt speed {float(belt_speed):g} mm/s; "
                               f"stored belt speeds: {', '.join(f'{v:g}' for v in belts)} "
                               f"(add it to sweep.belt_speed)")
        supports = sorted({e.get("support", "uniform") for e in found}, key=lambda s: (s != "uniform", s))
        found = [e for e in found if e.get("support_key", "") == key]
        if not found:
            hint = ("supports other than uniform are swept with model minpower only"
                    if key and model != "minpower" else "add it to sweep.supports")
            raise PinfeedError(f"part {part!r} has no {model} maps on support {support!r}; stored supports: "
                               f"{', '.join(supports)} ({hint})")
        speeds = sorted({e.get("v_pin", 0.0) for e in found})
        found = [e for e in found if e.get("v_pin", 0.0) == float(v_pin)]
        if not found:
            raise PinfeedError(f"part {part!r} has no {model} maps at v_pin/v_b = {float(v_pin):g}; "
                               f"stored speeds: {', '.join(f'{v:g}' for v in speeds)} (add it to sweep.v_pin)")
        return found

    def query(self, part: str, model: str = "minpower", mu_c=None, d=None,
              method: str = "nearest", v_pin: float = 0.0,
              belt_speed: float = 0.0, support: str = "uniform") -> xr.Dataset:
        """Maps of one part, model and pin speed, lazily.

        ``mu_c`` and ``d`` select stored values: ``method="nearest"`` takes the
        nearest stored value, ``"bracket"`` the stored values on either side (or
        the exact one). ``None`` keeps all. ``v_pin`` (speed ratio v_pin / v_b,
        default 0: static pins) must be stored exactly, since maps of different
        speeds are not interpolated. ``attrs["selection"]`` says what was
        chosen. ``belt_speed`` (mm/s, default 0: quasi-static) selects the
        dynamic model's maps at that speed, stored exactly (``model`` is then
        ``"dynamic"``). ``support`` (default uniform) selects the maps
        of one support, by its text or file key, stored exactly; the result has
        a scalar ``support`` coordinate. Returns dims ``(mu_c, d, theta_i)``.
        """
        key = _support_key(support)
        if float(belt_speed) > 0.0:
            model = "dynamic"
        if method not in ("nearest", "bracket"):
            raise PinfeedError(f"unknown selection method {method!r}; use nearest or bracket")
        _check_finite(mu_c=mu_c, d=d, v_pin=v_pin)
        if mu_c is not None and float(mu_c) < 0:
            raise PinfeedError(f"mu_c must be a finite number >= 0, got {mu_c!r}")
        self._refuse_damaged_in(part, model, mu_c, method, v_pin, belt_speed, key)
        found = self._stored(part, model, belt_speed, support, key, v_pin)
        notes = [] if float(v_pin) == 0.0 else [f"v_pin {float(v_pin):g} stored exactly"]
        notes += [] if not key else [f"support {found[0]['support']}"]
        stored_mu = sorted({e["mu_c"] for e in found})
        if mu_c is not None:
            chosen = _select(stored_mu, float(mu_c), method)
            notes.append(f"mu_c {float(mu_c):g} -> {_describe(chosen, float(mu_c), method)}")
            found = [e for e in found if e["mu_c"] in chosen]
        found.sort(key=lambda e: e["mu_c"])
        parts = [self._open_entry(e).expand_dims(mu_c=[e["mu_c"]]) for e in found]
        ds = xr.concat(parts, dim="mu_c", combine_attrs="drop_conflicts")
        ds["mu_c"].attrs.update(units="1", long_name="pin-part friction coefficient")
        ds = ds.assign_coords(support=((), found[0].get("support", "uniform"),
                                       {"long_name": "support distribution"}))
        if d is not None:
            stored_d = [float(x) for x in ds["d"].values]
            picks = []
            for want in np.atleast_1d(d):
                chosen = _select(stored_d, float(want), method)
                notes.append(f"d {float(want):g} -> {_describe(chosen, float(want), method)}")
                picks.extend(c for c in chosen if c not in picks)
            ds = ds.sel(d=picks)
        ds.attrs["selection"] = "; ".join(notes) if notes else "all stored mu_c and d"
        return ds

    def cube(self, family: str) -> xr.Dataset:
        """All maps of a family as one lazy cube (part, model, mu_c, v_pin, d,
        theta_i), with a ``support`` dimension after ``v_pin`` when the family
        has maps on supports other than uniform; combinations not stored are NaN."""
        # Quasi-static maps only: dynamic maps at belt speed > 0 are queried
        # one speed at a time (``query(..., belt_speed=...)``).
        found = [e for e in self.entries if e["family"] == family and not e.get("belt_speed", 0.0)]
        _refuse_damaged([d for d in self.damaged if d["family"] in (family, None) and not d["belt_speed"]],
                        f"family {family}")
        if not found:
            fams = sorted({e["family"] for e in self.entries})
            raise PinfeedError(f"unknown family {family!r}; known families: {', '.join(fams) or 'none'}")
        pieces = []
        supports = {e.get("support", "uniform") for e in found} != {"uniform"}
        for e in found:
            ds = self._open_entry(e)
            ds = ds.drop_attrs() if hasattr(ds, "drop_attrs") else ds.assign_attrs({})
            dims = dict(part=[e["part_id"]], model=[e["model"]], mu_c=[e["mu_c"]], v_pin=[e.get("v_pin", 0.0)])
            if supports:
                dims["support"] = [e.get("support", "uniform")]
            pieces.append(ds.expand_dims(**dims))
        cube = xr.combine_by_coords(pieces, combine_attrs="drop", join="outer")  # missing speeds: NaN
        cube.attrs.update(family=family, title=f"pinfeed map cube of family {family}")
        cube["v_pin"].attrs.update(units="1", long_name="pin speed across the belt over belt speed")
        if supports:
            cube["support"].attrs.update(long_name="support distribution")
        return cube


def _support_key(support) -> str:
    """The file key of a support given by its text or its key ('' for uniform)."""
    text = str(support)
    return text if re.fullmatch(r"points-[0-9a-f]{10}", text) else support_key(text)


def _refuse_damaged(bad: list[dict], what: str) -> None:
    """Raise naming the damaged shard(s) a query would have used, with the way back."""
    if not bad:
        return
    more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
    raise PinfeedError(f"{what}: a shard it needs is damaged: {bad[0]['problem']}{more}; {RECOMPUTE}")


def _check_finite(**values) -> None:
    """Refuse NaN and infinity: every comparison with NaN is false, so 'nearest'
    would silently serve the first stored value."""
    for name, value in values.items():
        if value is None:
            continue
        try:
            arr = np.atleast_1d(np.asarray(value, dtype=float))
        except (TypeError, ValueError):
            raise PinfeedError(f"{name} must be a number, got {value!r}") from None
        if not np.all(np.isfinite(arr)):
            raise PinfeedError(f"{name} must be a finite number, got {value!r}")


def nearest_stored(stored, want: float) -> float:
    """The value of ``stored`` nearest ``want`` (the lower one on a tie), as
    :meth:`Catalog.query` picks a friction."""
    return _select(list(stored), float(want), "nearest")[0]


def _select(stored: list[float], want: float, method: str) -> list[float]:
    stored = sorted(stored)
    if method == "nearest" or want in stored:
        return [min(stored, key=lambda s: (abs(s - want), s))]
    below = [s for s in stored if s < want]
    above = [s for s in stored if s > want]
    if not below or not above:
        return [below[-1] if below else above[0]]  # outside the stored range: the end
    return [below[-1], above[0]]


def _describe(chosen, want, method) -> str:
    if len(chosen) == 1 and chosen[0] == want:
        return "stored exactly"
    if len(chosen) == 1:
        how = "nearest stored" if method == "nearest" else "outside the stored range, end"
        return f"{how} {chosen[0]:g}"
    return f"bracketed by {chosen[0]:g} and {chosen[1]:g}"
