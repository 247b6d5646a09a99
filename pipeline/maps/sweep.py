"""The sweep: one shard per (family, part, model, mu_c, v_pin), each a map set over (d, theta_i).

Static pins (v_pin = 0) keep the file name ``mu_c=MU.h5``, so catalogs
written before dynamic pins existed stay valid; a moving pin's shard is
``mu_c=MU_v_pin=V.h5`` (V the speed ratio v_pin / v_b). Belt speeds > 0
(``sweep.belt_speed``) add shards of the dynamic model under
``dynamic/mu_c=MU[_v_pin=V]_belt=S_mu_s=M.h5``. Supports other than uniform
(``sweep.supports``) add minpower shards
``mu_c=MU[_v_pin=V]_support=KEY.h5`` (``parts.support.support_key``); uniform keeps
every name, file and byte as it was. The catalog stacks a family's shards
along a ``support`` dimension and queries one support at a time.

A shard is an HDF5 file (xarray, h5netcdf engine) that describes itself:
CF-style variable attributes, the part's outline, every sweep parameter, the
pinfeed version and git commit, the config hash and the creation time. Data
is gzip-compressed and chunked so one map (one d) is one chunk.

``run_sweep`` computes whatever shards are missing, locally or on a
dask.distributed cluster (``scheduler`` address), then rebuilds the index.
The Snakemake workflow calls :func:`write_shard` once per job instead.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pipeline.config import config_hash, mu_label, theta_grid
from pipeline.maps import simulate
from pipeline.maps.io import temps_beside, write_atomic
from pipeline.parts.families import family_parts
from pipeline.parts.part import Part
from pipeline.parts.support import parse_support, support_key
from pipeline.provenance import provenance_attrs

SCHEMA_VERSION = 1


@dataclass(frozen=True)
class ShardJob:
    """One shard to compute: a part's map set at one model, mu_c, pin speed and belt (mm/s)."""
    family: str
    part: Part
    model: str
    mu_c: float
    v_pin: float = 0.0
    belt_speed: float = 0.0  # mm/s; > 0 only for the dynamic model
    mu_s: float = 0.5
    support: str = "uniform"  # a support's text (parse_support); minpower only when not uniform

    @property
    def tag(self) -> str:
        """The shard's file stem (:func:`shard_tag`)."""
        return shard_tag(self.mu_c, self.v_pin, self.belt_speed, self.mu_s, self.support)

    def path(self, catalog_dir) -> Path:
        """The shard's file under ``catalog_dir``."""
        return Path(catalog_dir) / self.family / self.part.id / self.model / f"{self.tag}.h5"


def shard_tag(mu_c, v_pin=0.0, belt_speed=0.0, mu_s=0.5, support="uniform") -> str:
    """File stem of a shard: ``mu_c=0.15`` (static pin) or ``mu_c=0.15_v_pin=-2.0``;
    dynamic maps add ``_belt=150.0_mu_s=0.5`` (belt speed in mm/s), supports
    other than uniform ``_support=KEY`` (``parts.support.support_key``)."""
    tag = f"mu_c={mu_label(mu_c)}"
    tag = tag if float(v_pin) == 0.0 else f"{tag}_v_pin={mu_label(v_pin)}"
    if float(belt_speed) > 0.0:
        tag = f"{tag}_belt={mu_label(belt_speed)}_mu_s={mu_label(mu_s)}"
    key = support_key(support)
    return f"{tag}_support={key}" if key else tag


def shard_path(catalog_dir, family, part_id, model, mu_c, v_pin=0.0, belt_speed=0.0,
               mu_s=0.5, support="uniform") -> Path:
    """The shard file ``catalog_dir/family/part_id/model/TAG.h5`` (see :func:`shard_tag`)."""
    return (Path(catalog_dir) / family / part_id / model
            / f"{shard_tag(mu_c, v_pin, belt_speed, mu_s, support)}.h5")


def shard_jobs(config) -> list[ShardJob]:
    """Every shard the config asks for, in a stable order."""
    jobs = []
    for family, spec in config["families"].items():
        for part in family_parts(family, spec):
            for model in config["sweep"]["models"]:
                for mu in config["sweep"]["mu_c"]:
                    for v in config["sweep"]["v_pin"]:
                        jobs.append(ShardJob(family, part, model, float(mu), float(v)))
            # Belt speeds > 0: one dynamic shard per (mu_c, v_pin, speed).
            mu_s = float(config["sweep"].get("mu_s", 0.5))
            for speed in config["sweep"].get("belt_speed", [0.0]):
                if float(speed) <= 0.0:
                    continue
                for mu in config["sweep"]["mu_c"]:
                    for v in config["sweep"]["v_pin"]:
                        jobs.append(ShardJob(family, part, "dynamic", float(mu), float(v),
                                             float(speed), mu_s))
            # Supports other than uniform: minpower shards (the model that takes them).
            for support in config["sweep"].get("supports", ["uniform"]):
                if not support_key(support):
                    continue
                parse_support(support, part)  # a support outside this part: a one-line error
                for mu in config["sweep"]["mu_c"]:
                    for v in config["sweep"]["v_pin"]:
                        jobs.append(ShardJob(family, part, "minpower", float(mu), float(v),
                                             support=" ".join(str(support).split())))
    return jobs


def find_job(config, family, part_id, model, tag) -> ShardJob:
    """The job of a shard named by its folder parts and file stem (``shard_tag``)."""
    for job in shard_jobs(config):
        if (job.family, job.part.id, job.model) == (family, part_id, model) and job.tag == tag:
            return job
    from pipeline.errors import PinfeedError
    raise PinfeedError(f"the config has no shard {family}/{part_id}/{model}/{tag}")


def compute_shard(config, job: ShardJob, threads=None, backend=None):
    """The map set of one shard as a self-describing Dataset.

    ``backend`` (``"cpu"`` or ``"cuda"``) overrides the config's
    ``sweep.backend`` (default ``"cpu"``)."""
    sweep = config["sweep"]
    kernel = sweep.get("kernel", {})
    ds = simulate.compute_map(job.part, theta_grid(config), np.asarray(sweep["d"], float), job.mu_c,
                              sweep["pin_radius"], model=job.model, v_pin=job.v_pin, threads=threads,
                              **({"belt_speed": job.belt_speed, "mu_s": job.mu_s} if job.belt_speed > 0 else {}),
                              ds_max=kernel.get("ds_max", 0.1), tol=kernel.get("tol", 1e-7),
                              backend=backend or sweep.get("backend", "cpu"),
                              **({"support": job.support} if support_key(job.support) else {}))
    ds.attrs.update(provenance_attrs())
    ds.attrs.update({
        "title": f"pinfeed configuration maps: {job.part.id}, {job.model}, mu_c={job.mu_c:g}, "
                 f"v_pin/v_b={job.v_pin:g}"
                 + (f", belt {job.belt_speed:g} mm/s, mu_s={job.mu_s:g}" if job.belt_speed > 0 else "")
                 + (f", support {job.support}" if support_key(job.support) else ""),
        "family": job.family,
        "theta_step": float(sweep["theta_step"]),
        "config_hash": config_hash(config),
        "catalog_schema_version": SCHEMA_VERSION,
        "Conventions": "CF-1.10",
    })
    return ds


def _encoding(ds):
    nt = ds.sizes["theta_i"]
    enc = {}
    for name, var in ds.data_vars.items():
        if var.dims == ("d", "theta_i"):
            enc[name] = {"compression": "gzip", "compression_opts": 4, "shuffle": True,
                         "chunksizes": (1, nt)}
    return enc


def write_shard(config, job: ShardJob, out=None, threads=None, backend=None) -> Path:
    """Compute one shard and write it atomically (to ``out`` or its catalog path)."""
    out = Path(out) if out else job.path(config["catalog_dir"])
    ds = compute_shard(config, job, threads=threads, backend=backend)
    return write_atomic(ds, out, encoding=_encoding(ds))


def _write_job(config, job, threads, backend=None):
    return str(write_shard(config, job, threads=threads, backend=backend))


def run_sweep(config, scheduler: str | None = None, threads: int | None = None,
              progress: bool = True, backend: str | None = None) -> list[Path]:
    """Compute every missing shard, then rebuild the catalog index.

    With ``scheduler`` (a dask.distributed address such as ``tcp://host:8786``)
    the shards run as tasks on that cluster; otherwise here, one after
    another, each on ``threads`` Numba threads (or on this worker's GPU with
    ``backend="cuda"``, overriding the config's ``sweep.backend``). A worker
    that dies mid-sweep costs nothing but time: dask runs its tasks again on
    the others, and the temporary file of a write it did not finish is
    removed once the shard is in place.
    """
    from pipeline.maps.catalog import Catalog
    config = absolute_folders(config)
    root = Path(config["catalog_dir"])
    todo = [j for j in shard_jobs(config) if not j.path(root).is_file()]
    written = []
    if scheduler:
        from distributed import as_completed
        with _client(scheduler) as client:
            futures = [client.submit(_write_job, config, j, threads, backend, pure=False)
                       for j in todo]
            for fut in _progress(as_completed(futures), len(futures), progress):
                written.append(Path(fut.result()))
    else:
        for job in _progress(todo, len(todo), progress):
            written.append(write_shard(config, job, threads=threads, backend=backend))
    catalog = Catalog.rebuild(root)
    check_landed(catalog, written)
    remove_killed_attempts(root, todo)
    return written


def remove_killed_attempts(catalog_dir, jobs) -> list[Path]:
    """Delete the temporary files beside the shards of ``jobs`` once those shards
    are in place: a dask worker killed mid-write leaves its temporary file, and
    dask runs the task again elsewhere. Two sweeps must not write the same
    shards at the same time (one would remove the other's file in progress)."""
    gone = []
    for job in jobs:
        for tmp in temps_beside(job.path(catalog_dir)):
            tmp.unlink(missing_ok=True)
            gone.append(tmp)
    return gone


def absolute_folders(config: dict) -> dict:
    """A copy of ``config`` whose ``catalog_dir`` and ``results_dir`` are absolute
    paths, resolved here: a dask worker runs in its own working folder, where a
    relative path would put the shards somewhere else."""
    out = dict(config)
    for key in ("catalog_dir", "results_dir"):
        if out.get(key) is not None:
            out[key] = str(Path(out[key]).expanduser().resolve())
    return out


def check_landed(catalog, written) -> None:
    """Raise :class:`PinfeedError` unless every shard a task reported is on disk
    under the catalog's folder and in its index (a worker that cannot see
    this folder writes its shards elsewhere)."""
    from pipeline.errors import PinfeedError
    root = Path(catalog.root).resolve()
    indexed = {(root / e["file"]).resolve() for e in catalog.entries}
    lost = [p for p in written if Path(p).resolve() not in indexed]
    if lost:
        raise PinfeedError(f"{len(lost)} of {len(written)} shards computed did not land in the "
                           f"catalog {root} (e.g. {lost[0]}); the workers must share this folder "
                           f"(a path they all see, e.g. a network file system): give --catalog "
                           f"such a path")


SCHEDULER_TIMEOUT = 10  # seconds to reach a dask scheduler


def _client(address: str):
    """A dask.distributed client, or one clear error if the scheduler cannot be
    reached within ``SCHEDULER_TIMEOUT`` seconds."""
    from distributed import Client

    from pipeline.errors import PinfeedError
    try:
        return Client(address, timeout=SCHEDULER_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise PinfeedError(f"cannot reach the dask scheduler at {address} within {SCHEDULER_TIMEOUT} s "
                           f"({reason[:120]}); start it or drop --scheduler to run here") from None


def _progress(it, total, enabled):
    from pipeline.progress import progress
    return progress(it, total, "sweep", unit="shard", enabled=enabled)
