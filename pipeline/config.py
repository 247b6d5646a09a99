"""Load and validate a workflow config before any work starts.

Validation is the JSON schema in ``config/schema.yaml`` (a description for
every key) with its defaults filled in, then the checks a schema cannot
express: every part is a simple polygon, 360 is a multiple of theta_step,
planned parts exist, sensing parts are planned (default: the planned parts).
The Snakefile and the CLI both call :func:`load_config`, so a bad config
fails with one clear message before any work starts.
"""
from __future__ import annotations

import copy
import functools
import hashlib
import json
import math
import re
from pathlib import Path

import jsonschema
import yaml

from pipeline.checks import MAX_MAP, check_finite_tree, check_grid_size, check_pin_ratio, check_time_limit
from pipeline.errors import PinfeedError
from pipeline.parts.families import family_parts
from pipeline.provenance import source_date_epoch

SCHEMA_PATH = Path(__file__).resolve().parent.parent / "config" / "schema.yaml"
DEFAULT_CONFIG = Path(__file__).resolve().parent.parent / "config" / "config.yaml"


@functools.lru_cache(maxsize=1)
def _schema_text() -> str:
    return SCHEMA_PATH.read_text()


@functools.lru_cache(maxsize=1)
def _schema():
    """The parsed schema, read once: ``schema_default`` is called for every
    settings default (tens of times when the planner's types are defined),
    and parsing the YAML each time cost seconds. Callers do not change it
    (``schema_default`` hands out copies)."""
    return yaml.safe_load(_schema_text())


def schema_default(*path: str):
    """The default that ``config/schema.yaml`` gives the key at ``path`` (for
    example ``schema_default("verify", "trials")``): the one place defaults
    live, read by the settings' types for callers that come without a config."""
    node = _schema()
    for key in path:
        node = node["properties"][key]
    if "default" not in node:
        raise KeyError(f"config/schema.yaml gives {'/'.join(path)} no default")
    return copy.deepcopy(node["default"])


def _fill_defaults(validator_cls):
    validate_props = validator_cls.VALIDATORS["properties"]

    def set_defaults(validator, properties, instance, schema):
        if isinstance(instance, dict):
            for prop, sub in properties.items():
                if "default" in sub and prop not in instance:
                    instance[prop] = copy.deepcopy(sub["default"])
        yield from validate_props(validator, properties, instance, schema)

    return jsonschema.validators.extend(validator_cls, {"properties": set_defaults})


def _where(err) -> str:
    path = "/".join(str(p) for p in err.absolute_path)
    return path or "(top level)"


def resolve_outlines(cfg: dict, base_dir) -> None:
    """Make every relative ``outline`` path of an explicit part absolute,
    relative to ``base_dir`` (the config file's folder); say clearly when a
    part gives both or neither of ``vertices`` and ``outline``."""
    families = cfg.get("families") if isinstance(cfg.get("families"), dict) else {}
    for fam, spec in families.items():
        parts = spec.get("parts") if isinstance(spec, dict) else None
        for i, p in enumerate(parts if isinstance(parts, list) else []):
            if not isinstance(p, dict):
                continue
            where = f"config error at families/{fam}/parts/{i}"
            if ("vertices" in p) == ("outline" in p):
                raise PinfeedError(f"{where}: give either vertices or outline (a DXF or SVG file), "
                                   f"{'not both' if 'vertices' in p else 'one of them'}")
            extra = [k for k in ("layer", "id", "flatten_tol", "units", "join_tol") if k in p and "outline" not in p]
            if extra:
                raise PinfeedError(f"{where}: {', '.join(extra)} only apply to an outline file")
            if isinstance(p.get("outline"), str):
                p["outline"] = str((Path(base_dir) / p["outline"]).resolve())


def resolve_library_paths(cfg: dict, base_dir) -> None:
    """Make the ``library.paths`` entries (drawings, folders, glob patterns)
    absolute, relative to ``base_dir`` (the config file's folder)."""
    lib = cfg.get("library")
    if isinstance(lib, dict) and isinstance(lib.get("paths"), list):
        lib["paths"] = [str(Path(base_dir) / p) if isinstance(p, str) and p.strip() and not Path(p).is_absolute()
                        else p for p in lib["paths"]]


def config_name(path) -> str:
    """The default config name of a config file: its stem, in file-name-safe characters."""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(path).stem).lstrip(".-")
    return stem or "default"


def results_folder(config: dict) -> Path:
    """This config's results folder: ``results_dir/name`` (plans, verification,
    sensing, figures, animations, report)."""
    return Path(config["results_dir"]) / config.get("name", "default")


def validate_config(config: dict, base_dir=None, name: str | None = None) -> dict:
    """Return a validated copy of ``config`` with defaults filled in. Relative
    outline paths are taken relative to ``base_dir`` (default: the working
    directory). ``name`` (the config file's stem) is the default of ``name``."""
    source_date_epoch()  # before any kernel import trips over a bad value
    cfg = copy.deepcopy(config)
    cfg.setdefault("name", name or "default")
    for key in ("catalog_dir", "results_dir"):
        if isinstance(cfg.get(key), str) and not cfg[key].strip():
            raise PinfeedError(f"config error at {key}: it is empty, which would write into the "
                               f"current folder; name a folder (default {key.split('_')[0]})")
    check_finite_tree(cfg)
    _check_time_limit(cfg)
    resolve_outlines(cfg, base_dir or Path.cwd())
    resolve_library_paths(cfg, base_dir or Path.cwd())
    schema = _schema()
    validator = _fill_defaults(jsonschema.Draft202012Validator)(schema)
    errors = sorted(validator.iter_errors(cfg), key=lambda e: list(e.absolute_path))
    if errors:
        err = errors[0]
        raise PinfeedError(f"config error at {_where(err)}: {err.message}")
    # Defaults of nested objects that were themselves defaulted.
    validator.validate(cfg)
    steps = 360.0 / cfg["sweep"]["theta_step"]
    if abs(steps - round(steps)) > 1e-9:
        raise PinfeedError(f"config error at sweep/theta_step: 360 is not a multiple of "
                           f"{cfg['sweep']['theta_step']}")
    try:
        check_grid_size(len(cfg["sweep"]["d"]) * round(steps), "one shard (d x theta_i)", MAX_MAP)
    except PinfeedError as exc:
        raise PinfeedError(f"config error at sweep/d: {exc}") from None
    cfg["planner"]["parts"] = planned_parts(cfg["planner"]["parts"], _part_homes(cfg), cfg["families"])
    if cfg["planner"]["parts"] and 0 not in cfg["sweep"]["v_pin"]:
        raise PinfeedError("config error at sweep/v_pin: the planner needs static maps; add 0 to the "
                           "speeds (or plan no parts)")
    speeds = cfg["planner"]["dynamic"]["speeds"]
    bad = [v for v in speeds if v == 0 or v not in cfg["sweep"]["v_pin"]]
    if bad:
        raise PinfeedError(f"config error at planner/dynamic/speeds: {', '.join(f'{v:g}' for v in bad)} "
                           f"must be non-zero and listed in sweep/v_pin "
                           f"({', '.join(f'{v:g}' for v in cfg['sweep']['v_pin'])})")
    _check_planner_belt(cfg)
    sensing = cfg["sensing"]
    sensing.setdefault("parts", list(cfg["planner"]["parts"]))
    unplanned = [p for p in sensing["parts"] if p not in cfg["planner"]["parts"]]
    if unplanned:
        raise PinfeedError(f"config error at sensing/parts: {', '.join(unplanned)} not in planner/parts "
                           f"(the sensor plans on the planner's maps); planned parts: "
                           f"{', '.join(cfg['planner']['parts']) or 'none'}")
    _check_support_study(cfg)
    _check_sweep_supports(cfg)
    _check_holdout_trials(cfg)
    return cfg


def _check_holdout_trials(cfg: dict) -> None:
    """The held-out trials that certify a plan may not be fewer than the
    verification trials that chose it (one-line error otherwise)."""
    verify = cfg.get("verify", {})
    held, trials = verify.get("holdout_trials"), verify.get("trials", 300)
    if held is not None and int(held) < int(trials):
        raise PinfeedError(f"config error at verify/holdout_trials: {held} is fewer than verify/trials "
                           f"({trials}); the trials that certify a plan may not be fewer than those "
                           "that chose it (give at least that many, or null for as many)")


def _check_sweep_supports(cfg: dict) -> None:
    """sweep/supports: supports other than uniform are swept with minpower (the
    only model that takes one), so minpower must be swept; two supports may not
    share a file key. Each support is checked against each part by
    ``maps.sweep.shard_jobs``."""
    from pipeline.parts.support import support_key
    supports = cfg["sweep"]["supports"]
    others = [s for s in supports if support_key(s)]
    if others and "minpower" not in cfg["sweep"]["models"]:
        raise PinfeedError(f"config error at sweep/supports: {others[0]} needs minpower in sweep/models "
                           f"(the only model that takes a support; "
                           f"{', '.join(cfg['sweep']['models'])} are swept on uniform pressure only)")
    seen = {}
    for s in supports:
        key = support_key(s) or "uniform"
        if key in seen:
            raise PinfeedError(f"config error at sweep/supports: {seen[key]!r} and {s!r} are the same "
                               f"support (file key {key}); list it once")
        seen[key] = s


def _check_support_study(cfg: dict) -> None:
    """The support study's parts are planned parts, and its family (and the
    planner's) needs the mechanics that take point supports."""
    study = cfg.get("support_study") or {}
    unplanned = [p for p in study.get("parts") or [] if p not in cfg["planner"]["parts"]]
    if unplanned:
        raise PinfeedError(f"config error at support_study/parts: {', '.join(unplanned)} not in "
                           f"planner/parts (the study replays the part's plan); planned parts: "
                           f"{', '.join(cfg['planner']['parts']) or 'none'}")
    pc = cfg["planner"]
    if (study.get("family") or pc.get("support_family")) and (
            pc["model"] != "minpower" or pc.get("belt_speed") is not None):
        where = "planner/support_family" if pc.get("support_family") else "support_study/family"
        raise PinfeedError(f"config error at {where}: support families need planner/model minpower "
                           f"without planner/belt_speed (the other models assume uniform pressure); "
                           f"set the family to null or plan with minpower")


def _check_time_limit(cfg: dict) -> None:
    """planner/time_limit_s: seconds above 0 or null, said with the way out
    (before the schema, whose message would not say it)."""
    planner = cfg.get("planner")
    if isinstance(planner, dict) and planner.get("time_limit_s") is not None:
        try:
            check_time_limit(planner["time_limit_s"], "it")
        except PinfeedError as exc:
            raise PinfeedError(f"config error at planner/time_limit_s: {exc}") from None


def _check_planner_belt(cfg: dict) -> None:
    """planner/belt_speed: every planned part must be pushed, not thrown, at it."""
    speed = cfg["planner"].get("belt_speed")
    if speed is None:
        return
    from pipeline.checks import check_belt
    for family, spec in cfg["families"].items():
        for part in family_parts(family, spec):
            if part.name in cfg["planner"]["parts"]:
                try:
                    check_belt(part, speed, cfg["planner"]["mu_s"])
                except PinfeedError as exc:
                    raise PinfeedError(f"config error at planner/belt_speed ({part.name}): {exc}") from None


def planned_parts(wanted, homes: dict, families: dict) -> list:
    """``planner.parts`` as part names: each entry a part name, a family name (its
    parts) or ``all`` (every part), in order, without repeats. ``homes`` maps
    every part name to its family. An unknown name or an empty family is a
    one-line :class:`PinfeedError`."""
    out = []
    for entry in wanted:
        if entry == "all":
            names = list(homes)
        elif entry in homes:
            names = [entry]
        elif entry in families:
            names = [n for n, fam in homes.items() if fam == entry]
            if not names:
                raise PinfeedError(f"config error at planner/parts: family {entry} has no parts; "
                                   f"give it parts or generators, or leave it out of planner/parts")
        else:
            raise PinfeedError(f"config error at planner/parts: {entry} is neither a part, a family "
                               f"nor 'all'; families: {', '.join(families) or 'none'}; parts: "
                               f"{', '.join(homes) or 'none'}")
        out.extend(n for n in names if n not in out)
    return out


def _part_homes(cfg: dict) -> dict:
    """Part name -> family, in config order; raises on a bad outline, a name in
    two families, or a pin too large for a part."""
    home = {}
    for family, spec in cfg["families"].items():
        for part in family_parts(family, spec):  # raises on a bad outline
            if part.name in home:
                raise PinfeedError(f"config error at families/{family}: part {part.name} is also in "
                                   f"family {home[part.name]}; part names must be unique across "
                                   f"families (rename one)")
            home[part.name] = family
            try:
                check_pin_ratio(part, cfg["sweep"]["pin_radius"])
            except PinfeedError as exc:
                raise PinfeedError(f"config error at sweep/pin_radius: {exc}") from None
    return home


def load_config(path=None) -> dict:
    """Read a YAML config (default: the embedded ``config/config.yaml``) and validate it."""
    path = Path(path) if path else DEFAULT_CONFIG
    if not path.is_file():
        raise PinfeedError(f"no config file at {path}; pass an existing YAML file")
    try:
        with open(path) as fh:
            config = yaml.safe_load(fh)
    except yaml.YAMLError as exc:
        raise PinfeedError(f"{path} is not valid YAML: {exc}".splitlines()[0]) from None
    if not isinstance(config, dict):
        raise PinfeedError(f"{path} must hold a YAML mapping of settings")
    return validate_config(config, base_dir=path.resolve().parent, name=config_name(path))


# Keys whose default value is left out of the config hash: a key added after
# catalogs were written must not change the hash (a shard's config_hash
# attribute, so its bytes) of a config that does not use it.
HASH_NEUTRAL_DEFAULTS = {("sweep", "supports"): ["uniform"],
                         ("planner", "support_family"): None,
                         ("support_study",): {"family": None, "parts": []},
                         # design for feeding: a config that leaves it alone keeps its hash
                         ("design",): {"kinds": ["chamfer", "notch", "tab"], "chamfer": [0.05, 0.1, 0.15, 0.2],
                                       "notch": [[0.1, 0.05], [0.2, 0.1]], "tab": [[0.1, 0.05], [0.2, 0.1]],
                                       "positions": [0.5], "min_wall_mm": 1.0, "max_change": 0.1,
                                       "depth": None},
                         # the claim's settings: a config that leaves them alone keeps its hash
                         # (and its shards' recorded hash); the code version records the change
                         ("verify", "confidence"): 0.95, ("verify", "rule"): "bound",
                         ("verify", "holdout_trials"): None, ("planner", "width_slack_deg"): 1.0,
                         ("planner", "worst_member_budget"): 150, ("planner", "shape_tolerance_mm"): None}


def config_hash(config: dict) -> str:
    """Hash of the validated config (canonical JSON), recorded in stored files.
    Keys of :data:`HASH_NEUTRAL_DEFAULTS` at their default value are left out,
    so a config that does not use the support keys (``sweep.supports: [uniform]``,
    no ``planner.support_family``, no ``support_study``) hashes as before they
    existed."""
    hashed = config
    for path, default in HASH_NEUTRAL_DEFAULTS.items():
        *sections, key = path
        sub = hashed
        for name in sections:
            sub = sub.get(name) if isinstance(sub, dict) else None
        if isinstance(sub, dict) and key in sub and sub[key] == default:
            trimmed = {k: v for k, v in sub.items() if k != key}
            hashed = dict(hashed, **{sections[0]: trimmed}) if sections else trimmed
    blob = json.dumps(hashed, sort_keys=True, separators=(",", ":"), default=float)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def theta_grid(config: dict):
    """The sweep's theta_i grid, degrees: ``0, step, ...`` below 360 (``sweep.theta_step``)."""
    import numpy as np
    step = config["sweep"]["theta_step"]
    return np.round(np.arange(int(round(360.0 / step))) * step, 10)


def mu_label(mu: float) -> str:
    """File-name form of a friction value: 0.15 -> '0.15' (round-trips through float)."""
    text = repr(float(mu))
    if not math.isclose(float(text), mu):
        raise PinfeedError(f"mu_c {mu} cannot be written exactly")
    return text
