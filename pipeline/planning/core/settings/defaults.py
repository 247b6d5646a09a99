"""The schema's defaults as dataclass fields: the lowest module of the settings.

Every typed settings class takes its defaults from ``config/schema.yaml``
(:func:`pipeline.config.schema_default`) through :func:`schema_value`.
"""
from __future__ import annotations

from dataclasses import field

from pipeline.config import schema_default


def schema_value(*path):
    """A dataclass field whose default is the schema's value at ``path``
    (``schema_value("verify", "trials")``), read when the class is made; a
    list or dict default is made afresh for every instance."""
    value = schema_default(*path)
    if isinstance(value, (list, dict)):
        return field(default_factory=lambda: schema_default(*path))
    return field(default=value)
