"""Sphinx configuration of the pinfeed manual (``make docs``)."""
from __future__ import annotations

import os
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
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinxarg.ext",
    "sphinx_gallery.gen_gallery",
    "config_schema",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "_ext", "examples/README.txt", "**/GALLERY_HEADER.rst"]
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3
suppress_warnings = ["config.cache"]  # the gallery's conf entries hold functions

# Docstrings are NumPy style; napoleon reads them without failing on older ones.
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_ivar = True
autodoc_typehints = "none"
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False}

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
}
