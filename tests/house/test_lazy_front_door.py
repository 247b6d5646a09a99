"""The planner's front door is lazy: importing ``pipeline.planning`` imports
no wing, and each name is imported from its wing when first asked for
(PEP 562), so a command that needs none of the planner does not pay for it.
"""
from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys

import pytest

from test_layers import ROOT

import pipeline.planning as planning


def test_importing_the_front_door_imports_no_wing():
    code = ("import json, sys\nimport pipeline.planning\n"
            "print(json.dumps(sorted(m for m in sys.modules if m.startswith(('pipeline.planning.', 'numpy', "
            "'scipy', 'numba', 'kernels')))))\n")
    run = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(ROOT)},
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout) == []


@pytest.mark.parametrize("name", planning.__all__)
def test_each_name_is_its_wings_object(name):
    module, attr = planning._MODULE_OF[name]
    assert getattr(planning, name) is getattr(importlib.import_module(f"pipeline.planning.{module}"), attr)
    assert name in dir(planning)


def test_unknown_names_are_refused():
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        planning.nope  # noqa: B018
    with pytest.raises(ImportError):
        from pipeline.planning import nope  # noqa: F401
