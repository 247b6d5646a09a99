"""Sphinx directive ``pinfeed-config-schema``: every key of config/schema.yaml with its
type, default and description, read from the schema at build time."""
from __future__ import annotations

from pathlib import Path

import yaml
from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective

SCHEMA = Path(__file__).resolve().parents[2] / "config" / "schema.yaml"


def _resolve(node: dict, defs: dict) -> dict:
    """The node with a local ``$ref`` replaced by its definition."""
    ref = node.get("$ref", "")
    if ref.startswith("#/$defs/"):
        return {**defs[ref.split("/")[-1]], **{k: v for k, v in node.items() if k != "$ref"}}
    return node


def schema_keys(schema: dict, prefix: str = "", defs: dict | None = None):
    """Yield ``(key, node)`` for every key below ``schema``, depth first.

    ``key`` is dotted; a map of names is written ``NAME`` and a list's items ``[]``.
    """
    defs = schema.get("$defs", {}) if defs is None else defs
    schema = _resolve(schema, defs)
    for name, node in (schema.get("properties") or {}).items():
        key = f"{prefix}.{name}" if prefix else name
        node = _resolve(node, defs)
        yield key, node
        yield from _children(node, key, defs)


def _children(node: dict, key: str, defs: dict):
    if node.get("properties"):
        yield from schema_keys(node, key, defs)
    extra = node.get("additionalProperties")
    if isinstance(extra, dict) and (extra.get("properties") or extra.get("description")):
        yield f"{key}.NAME", extra
        yield from schema_keys(extra, f"{key}.NAME", defs)
    items = _resolve(node.get("items") or {}, defs) if isinstance(node.get("items"), dict) else {}
    if items.get("properties") or items.get("allOf") or items.get("oneOf"):
        yield from _children(items, f"{key}[]", defs)
    for alt in node.get("oneOf", []) + node.get("anyOf", []) + node.get("allOf", []):
        alt = _resolve(alt.get("then", alt), defs)
        if alt.get("properties"):
            yield from schema_keys(alt, key, defs)


def load_schema(path: Path = SCHEMA) -> dict:
    return yaml.safe_load(path.read_text())


def _type(node: dict) -> str:
    kind = node.get("type")
    if kind is None and "enum" in node:
        return "one of " + ", ".join(f"``{v}``" for v in node["enum"])
    if isinstance(kind, list):
        return " or ".join(kind)
    return kind or "any"


def rst_lines(schema: dict) -> list[str]:
    """reStructuredText definition list of every key."""
    lines, seen = [], set()
    for key, node in schema_keys(schema):
        if key in seen:
            continue
        seen.add(key)
        lines.append(f"``{key}``")
        bits = [f"*{_type(node)}*"]
        if "default" in node:
            bits.append(f"default ``{node['default']!r}``")
        if "enum" in node and node.get("type"):
            bits.append("one of " + ", ".join(f"``{v}``" for v in node["enum"]))
        desc = " ".join(str(node.get("description", "")).split()) or "(no description)"
        lines.append("   " + "; ".join(bits) + ". " + desc.replace("*", r"\*").replace("`", "'"))
        lines.append("")
    return lines


class ConfigSchemaDirective(SphinxDirective):
    """Render the config schema as a definition list."""

    def run(self):
        self.env.note_dependency(str(SCHEMA))
        container = nodes.container()
        self.state.nested_parse(StringList(rst_lines(load_schema())), self.content_offset, container)
        return container.children


def setup(app):
    app.add_directive("pinfeed-config-schema", ConfigSchemaDirective)
    return {"parallel_read_safe": True, "version": "1"}
