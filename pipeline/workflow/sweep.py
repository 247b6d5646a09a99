"""The function of ``rules/sweep.smk``: one map shard."""
from __future__ import annotations

from pathlib import Path

from pipeline.maps.sweep import find_job, write_shard


def sweep_shard(config: dict, family: str, part: str, model: str, tag: str, out, threads: int = 1) -> Path:
    """Rule ``sweep_shard``: compute the shard the wildcards name (family, part
    id, model, ``mu_c=..`` tag) with the config's sweep settings; written
    atomically to ``out``."""
    job = find_job(config, family, part, model, tag)
    return write_shard(config, job, out=out, threads=threads)
