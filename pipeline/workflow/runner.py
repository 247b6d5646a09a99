"""The workflow's safety around Snakemake: a catalog checked against disk before
jobs are planned, and recovery after a run was killed (``kill -9``).

``make run`` calls ``python -m pipeline.workflow run SNAKEMAKE-ARGS...``:

1. It takes a lock of its own (``.snakemake/pinfeed-run.lock``, an ``flock``
   the kernel releases when the holder dies, however it dies), so two
   ``make run`` in one folder cannot overlap.
2. If Snakemake's own lock (``.snakemake/locks``) is there but no Snakemake
   process works in this folder, a previous run was killed: it says so in one
   line and removes the stale lock (what ``make unlock`` does). If one is
   alive, it stops with one line naming its pid.
3. It removes the temporary files of atomic writes a killed run left behind
   (``.NAME.XXXX.tmp``; the catalog never reads them anyway).
4. It runs Snakemake with its output to a log file
   (``logs/NAME/snakemake-DATE-TIME.log``, the last 20 kept) and shows on the
   terminal one line per finished stage, a live line on a terminal, and for a
   failed job its rule, log and last lines (:mod:`pipeline.workflow.console`).
   A dry run and Snakemake's listing options (``-n``, ``--list-rules``,
   ``--summary``, ...) print Snakemake's own output instead.
5. When the run made the config's report, it prints its path
   (``report: .../results/NAME/report.html``; for the ``support_study``
   target, ``report_support.html`` and one line per studied part; for the
   ``library`` target, ``library.html`` after the count of parts per answer).

The Snakefile calls :func:`reconcile_catalog` while it loads, before
Snakemake plans any job: Snakemake treats a missing intermediate file (a
shard) as fine when what was made from it (the index) is up to date, so a
deleted shard would never be recomputed. If an indexed shard is gone, or an
expected one is missing, the (derived) index is removed so that the next run
recomputes the shard and re-indexes; a shard that changed and no longer reads
as a pinfeed shard is moved aside to ``NAME.h5.corrupt``.
"""
from __future__ import annotations

import fcntl
import os
import subprocess
import sys
from pathlib import Path

from pipeline.errors import PinfeedError

RUN_LOCK = Path(".snakemake") / "pinfeed-run.lock"
SNAKEMAKE_LOCKS = Path(".snakemake") / "locks"
KEEP_LOGS = 20  # Snakemake logs kept per config (logs/NAME/snakemake-*.log)
# Snakemake options that run no job and print what a person asked to see:
# their output goes to the terminal unchanged.
PASS_THROUGH = {"-n", "--dry-run", "--dryrun", "--unlock", "--summary", "-S", "--detailed-summary",
                "-D", "--lint", "--dag", "--rulegraph", "--filegraph", "--help", "-h", "--version",
                "-v", "--print-compilation", "--cleanup-metadata", "--cleanup-shadow", "--containerize",
                "--delete-all-output", "--delete-temp-output", "--archive", "--report", "--list-changes",
                "--lc", "-l"}


# ---------------------------------------------------------------- catalog against disk


def _shard_readable(path: Path) -> bool:
    """True if ``path`` still opens as a complete pinfeed shard."""
    from pipeline.maps.catalog import entry_from_file
    from pipeline.maps.io import read_map
    try:
        entry_from_file(path.parent, path)
        read_map(path)
    except PinfeedError:
        return False
    return True


def reconcile_catalog(config: dict) -> list[str]:
    """Make the catalog index honest before Snakemake plans its jobs; return one
    line per action taken (empty if the index matches the disk)."""
    from pipeline.maps.catalog import INDEX_NAME, disk_problem, read_index
    from pipeline.maps.sweep import shard_jobs
    root = Path(config["catalog_dir"])
    index = root / INDEX_NAME
    if not index.is_file():
        return []
    try:
        entries = read_index(index, root)["entries"]
    except PinfeedError:
        index.unlink()
        return [f"{index} was unreadable; removed, the workflow rebuilds it"]
    notes = []
    for e in entries:
        path = root / e["file"]
        problem = disk_problem(path, e)
        if problem is None or not path.is_file():
            if problem:
                notes.append(problem)
            continue
        if not _shard_readable(path):  # damaged, not rewritten by a later run
            aside = path.with_name(path.name + ".corrupt")
            os.replace(path, aside)
            notes.append(f"{path}: damaged (checksum and content); moved to {aside.name}")
    notes += [f"{p}: expected by the config but missing" for p in
              sorted({str(j.path(root)) for j in shard_jobs(config)})
              if not Path(p).is_file() and not any(p in n for n in notes)]
    if notes:
        index.unlink(missing_ok=True)
        notes.append(f"removed the stale {index}: the missing shards are recomputed and re-indexed")
    return notes


# ---------------------------------------------------------------- recovery after kill -9


def _live_snakemake_pids(folder: Path) -> list[int]:
    """Pids of Snakemake processes (not this one) whose working folder is ``folder``."""
    pids, here = [], folder.resolve()
    for proc in Path("/proc").glob("[0-9]*"):
        pid = int(proc.name)
        if pid == os.getpid():
            continue
        try:
            cmd = (proc / "cmdline").read_bytes().split(b"\0")
            if not any(b"snakemake" in part for part in cmd[:2]):
                continue
            if Path(os.readlink(proc / "cwd")).resolve() == here:
                pids.append(pid)
        except OSError:
            continue  # gone meanwhile, or not ours to read
    return pids


def clear_stale_lock(folder: Path) -> str | None:
    """Remove Snakemake's lock if no Snakemake works in ``folder``; return what
    was done (None if there was no lock). Raises if a run is alive."""
    locks = [p for p in (folder / SNAKEMAKE_LOCKS).glob("*") if p.is_file()]
    if not locks:
        return None
    alive = _live_snakemake_pids(folder)
    if alive:
        raise PinfeedError(f"another Snakemake run works in {folder} (pid {alive[0]}); wait for it, "
                           f"or stop it and run 'make unlock'")
    for p in locks:
        p.unlink(missing_ok=True)
    return "a previous run was killed and left Snakemake's lock; no run is alive, so it was removed"


def _config_path(args: list[str]) -> Path:
    """The config file the Snakemake arguments name (``--configfile``), else the embedded default."""
    from pipeline.config import DEFAULT_CONFIG
    if "--configfile" in args and args.index("--configfile") + 1 < len(args):
        return Path(args[args.index("--configfile") + 1])
    return DEFAULT_CONFIG


def _config_dirs(args: list[str]) -> list[Path]:
    """catalog_dir and results_dir of the config the Snakemake arguments name."""
    import yaml
    try:
        cfg = yaml.safe_load(_config_path(args).read_text()) or {}
    except (OSError, yaml.YAMLError):
        return []  # Snakemake reports a bad config file itself
    if not isinstance(cfg, dict):
        return []
    return [Path(str(cfg.get(k) or d)) for k, d in (("catalog_dir", "catalog"), ("results_dir", "results"))]


def run(args: list[str]) -> int:
    """``make run``: the checks above, then Snakemake with ``args``; its exit code."""
    from pipeline.maps.io import remove_stale_temps
    folder = Path.cwd()
    (folder / RUN_LOCK).parent.mkdir(parents=True, exist_ok=True)
    with open(folder / RUN_LOCK, "a+") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise PinfeedError(f"another 'make run' is running in {folder}; wait for it to finish") from None
        note = clear_stale_lock(folder)
        if note:
            print(f"pinfeed: {note}", file=sys.stderr)
        gone = [t for d in _config_dirs(args) if d.is_dir() for t in remove_stale_temps(d)]
        if gone:
            print(f"pinfeed: removed {len(gone)} temporary file(s) a killed run left behind",
                  file=sys.stderr)
        if _passes_through(args):
            return subprocess.call(["snakemake", *args])
        from pipeline.workflow.console import follow
        code = follow(["snakemake", *args], _snakemake_log(args), workdir=_workdir(args))
    if code == 0:
        _print_report_path(args)
    return code


def _passes_through(args: list[str]) -> bool:
    """Whether Snakemake's own output is what the arguments ask for (a dry run, a listing)."""
    return any(a in PASS_THROUGH or a.startswith("--list") or a.startswith("--generate-unit-tests")
               for a in args)


def _workdir(args: list[str]) -> Path:
    """Snakemake's working folder: ``--directory``/``-d`` if given, else here."""
    for flag in ("--directory", "-d"):
        if flag in args and args.index(flag) + 1 < len(args):
            return Path(args[args.index(flag) + 1])
    return Path(".")


def _snakemake_log(args: list[str]) -> Path:
    """A new file for Snakemake's output, ``logs/NAME/snakemake-DATE-TIME.log``
    in its working folder (NAME: the config's name); older ones beyond the
    last :data:`KEEP_LOGS` are removed."""
    import time
    import yaml
    from pipeline.config import config_name
    path = _config_path(args)
    try:
        cfg = yaml.safe_load(path.read_text()) or {}
    except (OSError, yaml.YAMLError):
        cfg = {}
    name = str(cfg.get("name") or config_name(path)) if isinstance(cfg, dict) else config_name(path)
    folder = _workdir(args) / "logs" / name
    old = sorted(folder.glob("snakemake-*.log"))
    for stale in old[:max(0, len(old) - KEEP_LOGS + 1)]:
        stale.unlink(missing_ok=True)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    log = folder / f"snakemake-{stamp}.log"
    k = 1
    while log.exists():
        k += 1
        log = folder / f"snakemake-{stamp}-{k}.log"
    return log


def _print_report_path(args: list[str]) -> None:
    """The path of the report a finished run made (none when its targets left it
    out): ``report.html``, or for the ``support_study`` target ``report_support.html``
    and the study's answer per part."""
    from pipeline.config import load_config, results_folder
    results = results_folder(load_config(_config_path(args)))
    if "library" in args:
        from pipeline.maps.io import read_json
        if (results / "library.json").is_file():
            print(f"library: {read_json(results / 'library.json')['summary']}", flush=True)
        report = results / "library.html"
    elif "support_study" in args:
        from pipeline.maps.io import read_json
        from pipeline.workflow.supports import support_summary_text
        for path in sorted((results / "support").glob("*.json")):
            print(f"support: {support_summary_text(read_json(path))}", flush=True)
        report = results / "report_support.html"
    else:
        report = results / "report.html"
    if report.is_file():
        print(f"report: {report.resolve()}", flush=True)


def main(argv=None) -> int:
    """``python -m pipeline.workflow run|unlock [SNAKEMAKE ARGS...]``; returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] not in ("run", "unlock"):
        print("usage: python -m pipeline.workflow run|unlock [SNAKEMAKE ARGS...]", file=sys.stderr)
        return 2
    try:
        if argv[0] == "unlock":
            print(f"pinfeed: {clear_stale_lock(Path.cwd()) or 'no Snakemake lock here'}")
            return 0
        return run(argv[1:])
    except PinfeedError as exc:
        print(f"pinfeed: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
