"""The function of ``rules/catalog.smk``: the catalog index, rebuilt from disk."""
from __future__ import annotations

from pipeline.maps.catalog import Catalog


def catalog_index(config: dict) -> Catalog:
    """Rule ``catalog_index``: rebuild the index of ``config["catalog_dir"]`` from
    the shards' own attributes; the returned catalog lists its problems."""
    return Catalog.rebuild(config["catalog_dir"])
