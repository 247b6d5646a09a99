"""Sphinx configuration of the pinfeed manual (``make docs``)."""
from __future__ import annotations

import os
import re
import shutil
import sys
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _dist_version
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path[:0] = [str(ROOT), str(HERE / "_ext")]
os.environ.setdefault("MPLBACKEND", "Agg")
# The gallery's pages are generated into docs/gallery/ by running the examples;
# start from nothing so that a renamed or removed example leaves no stale page.
shutil.rmtree(HERE / "gallery", ignore_errors=True)
# Likewise the API reference's per-function pages (autosummary's stubs and the
# gallery's back-references), generated into docs/reference/generated/.
shutil.rmtree(HERE / "reference" / "generated", ignore_errors=True)

# The default config's plans, computed from this code (docs/_ext/default_run.py,
# cached by a hash of the code): pages quote them as {{ plans.NAME.KEY }}
# (e.g. {{ plans.asym_triangle.pins }}) and show the figures it writes into
# docs/_generated/; nothing about the default plans is written by hand.
import default_run  # noqa: E402

DEFAULT_RUN = default_run.default_run()

# Plans of other parts and settings that pages state (the tutorial's drawings,
# a support family, a shape tolerance, ...): run once by hand and kept in
# docs/plans/NAME.json (docs/_ext/stored_plans.py, its registry names the
# command of each). Pages quote them as {{ stored.NAME.KEY }} (e.g.
# {{ stored.wedge.width }}; the keys are plan_numbers.numbers') and include
# their console output from docs/_generated/stored/NAME.txt.
import stored_plans  # noqa: E402

myst_substitutions = {"plans": DEFAULT_RUN["parts"], "stored": stored_plans.write_generated()}

project = "pinfeed"
author = "pinfeed developers"
copyright = "2026, pinfeed developers"
# The version of the installed package (pyproject.toml), shown in the header.
try:
    release = _dist_version("pinfeed")
except PackageNotFoundError:        # docs built from a clone that is not installed
    release = "0+unknown"
version = ".".join(release.split(".")[:2])

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinxarg.ext",
    "sphinx_gallery.gen_gallery",
    "config_schema",
    "matplotlib.sphinxext.plot_directive",
]
# Diagrams drawn by code at build time (``.. plot::``): one PNG each, no source
# link or format links under them.
plot_formats = [("png", 150)]
plot_html_show_source_link = False
plot_html_show_formats = False
plot_include_source = False

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "_ext", "_generated", "examples/README.txt", "**/GALLERY_HEADER.rst"]
myst_enable_extensions = ["colon_fence", "deflist", "substitution"]
myst_heading_anchors = 3
suppress_warnings = ["config.cache"]  # the gallery's conf entries hold functions

# Docstrings are NumPy style; napoleon reads them without failing on older ones.
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_ivar = True
autodoc_typehints = "none"
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False}
# One page per function and class of the API reference (docs/reference/api.md),
# from the templates in docs/_templates/autosummary/ (each ends with the
# gallery examples that use the object).
autosummary_generate = True
templates_path = ["_templates"]

# Links to numpy, xarray and matplotlib. Their inventories (objects.inv) come
# from the web: none of the installed packages ships one, and the build must
# work offline (CI has no internet). So the mapping is switched on only when
# asked for, PINFEED_DOCS_INTERSPHINX=1 (a build with web access); otherwise
# it is empty and the types show as plain text. The build never probes the
# network by itself.
INTERSPHINX = {
    "python": ("https://docs.python.org/3", None),
    "numpy": ("https://numpy.org/doc/stable", None),
    "xarray": ("https://docs.xarray.dev/en/stable", None),
    "matplotlib": ("https://matplotlib.org/stable", None),
}
intersphinx_mapping = INTERSPHINX if os.environ.get("PINFEED_DOCS_INTERSPHINX") == "1" else {}
intersphinx_timeout = 10

# Keep quotes as typed: option values and shell text must stay copyable.
smartquotes = False
highlight_language = "text"   # usage lines and shell text are not Python

html_theme = "furo"
html_title = f"pinfeed {release}"
html_static_path: list[str] = []

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"^_|/_",   # helpers shared by the examples (docs/examples/_*.py)
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "show_memory": False,
    "min_reported_time": 9999,
    # Which pinfeed functions each example uses, for the "Examples using"
    # list on every API page (the minigallery in the autosummary templates).
    "doc_module": ("pipeline",),
    "backreferences_dir": "reference/generated/backreferences",
}

# The docstrings list parameters and attributes NumPy-style but as
# "name : what it is" (a description where NumPy puts a type). Napoleon would
# print that description as the type, in italics; so before napoleon reads a
# docstring, such a line becomes "name" with the description under it. A
# real type ("float", "int, optional", "xarray.Dataset") is left alone.
_FIELD_SECTIONS = {"parameters", "other parameters", "attributes", "keyword arguments", "args",
                   "arguments"}
_FIELD = re.compile(r"^(\s*)([\w*][\w*, ]*?) : (.+)$")
_TYPE_WORDS = {"int", "float", "str", "bool", "bytes", "complex", "none", "optional", "list",
               "dict", "tuple", "set", "of", "or", "array", "array-like", "ndarray", "sequence",
               "iterable", "callable", "path", "mapping", "default", "object", "any"}


def _is_type(text: str) -> bool:
    tokens = [t for t in re.split(r"[\s,|\[\]()]+", text.strip()) if t]
    return bool(tokens) and all(t.lower() in _TYPE_WORDS or "." in t.strip(".") or t[:1].isupper()
                                for t in tokens) and not text.rstrip().endswith(".")


def _description_fields(app, what, name, obj, options, lines):
    if what in ("property", "attribute", "data"):
        # Napoleon reads "text: more" on a property's first line as "type: description";
        # these docstrings mean it as one sentence: start them with an empty comment.
        if lines and ":" in lines[0]:
            lines[:0] = ["..", ""]
        return
    section, indent, out = None, None, []
    for i, line in enumerate(lines):
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if nxt.strip() and set(nxt.strip()) == {"-"} and line.strip():
            section = line.strip().lower()
            indent = len(line) - len(line.lstrip())
            out.append(line)
            continue
        if (section in _FIELD_SECTIONS and not line.strip() and nxt.strip()
                and len(nxt) - len(nxt.lstrip()) == indent and not _FIELD.match(nxt)):
            # A paragraph after the fields ends the section (napoleon: two blank lines).
            out += ["", ""]
            section = None
            continue
        m = _FIELD.match(line)
        if (section in _FIELD_SECTIONS and m and len(m.group(1)) == indent
                and not _is_type(m.group(3))):
            out += [m.group(1) + m.group(2), m.group(1) + "    " + m.group(3)]
        else:
            out.append(line)
    lines[:] = out


def setup(app):
    # Before napoleon's own handler (priority 500) turns the sections into fields.
    app.connect("autodoc-process-docstring", _description_fields, priority=400)

