"""GPU backend (issue 15) without a GPU: numba's CUDA simulator and PTX.

- The CUDA grid kernel, run by numba's CUDA simulator on a tiny grid with
  jams and misses, gives the CPU's answers (theta_f to 1e-6 degrees on ok
  rollouts, equal statuses).
- The kernel compiles to PTX for a Hopper GPU (cc 9.0) with the NVVM of the
  numba-cuda[cu12] wheels, without a device.
- Asking for the cuda backend where it cannot run is a one-line error.

The first two need the ``cuda`` extra (``pip install '.[cuda]'``, which
``make test`` installs) and skip without it.
"""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import circular_diff
from pipeline.cli import main
from pipeline.errors import PinfeedError
from pipeline.maps import simulate

HAVE_NUMBA_CUDA = importlib.util.find_spec("numba_cuda") is not None
needs_cuda_extra = pytest.mark.skipif(not HAVE_NUMBA_CUDA,
                                      reason="the cuda extra (numba-cuda) is not installed")
ROOT = Path(__file__).resolve().parents[2]
OK, MISS, JAMMED = 0, 1, 2


@needs_cuda_extra
def test_simulator_matches_cpu_on_a_grid_with_jams_and_misses():
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "cuda_sim_check.py")], env=env,
                          capture_output=True, text=True, timeout=1200, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr[-3000:]
    cases = json.loads(proc.stdout)
    seen = set()
    for case in cases:
        gpu = [np.asarray(x) for x in case["gpu"]]
        cpu = [np.asarray(x) for x in case["cpu"]]
        np.testing.assert_array_equal(gpu[0], cpu[0])  # statuses
        np.testing.assert_array_equal(gpu[1], cpu[1])  # jam reasons
        ok = cpu[0] == OK
        dth = circular_diff(np.degrees(gpu[2][ok]), np.degrees(cpu[2][ok]))
        assert np.all(np.abs(dth) <= 1e-6)
        np.testing.assert_allclose(gpu[3][ok], cpu[3][ok], rtol=0, atol=1e-6)
        seen.update(np.unique(cpu[0]).tolist())
    assert {OK, MISS, JAMMED} <= seen, f"grid should include jams and misses: {seen}"


@needs_cuda_extra
def test_kernel_compiles_to_ptx_for_hopper(monkeypatch):
    from numba import cuda
    import numba.cuda.dispatcher as dispatcher
    from kernels import cuda as kcuda

    class _Hopper:  # stands in for the device numba-cuda asks for its cc
        compute_capability = (9, 0)

    # numba-cuda compiles the @jit functions the kernel calls as device
    # functions for the current device; there is none here.
    monkeypatch.setattr(dispatcher, "get_current_device", lambda: _Hopper())
    ptx, _ = cuda.compile_ptx(kcuda._grid_kernel, kcuda.kernel_signature(), cc=(9, 0))
    assert ".target sm_90" in ptx
    assert ".entry" in ptx and "_grid_kernel" in ptx
    assert ".f64" in ptx  # double precision throughout
    assert "__nv_log" in ptx or "lg2.approx" not in ptx  # libdevice log, no fast-math log


def test_unknown_backend_is_a_clear_error(triangle):
    with pytest.raises(PinfeedError, match="unknown backend 'tpu'"):
        simulate.compute_map(triangle, [0.0], [0.3], 0.2, 3.0, backend="tpu")


def _gpu_usable():
    if not HAVE_NUMBA_CUDA:
        return False
    from kernels import cuda as kcuda
    return kcuda.available()


@pytest.mark.skipif(_gpu_usable(), reason="this machine has a GPU")
def test_cuda_without_a_gpu_is_a_one_line_error(triangle, capsys, tmp_path):
    with pytest.raises(PinfeedError) as exc:
        simulate.compute_map(triangle, [0.0], [0.3], 0.2, 3.0, backend="cuda")
    msg = str(exc.value)
    assert "\n" not in msg and "cuda" in msg and "cpu" in msg
    rc = main(["map", "--vertices", "0,0 60,0 15,35", "--d", "0.3", "--mu-c", "0.2",
               "--pin-radius", "3", "--theta-step", "90", "--backend", "cuda", "--out", str(tmp_path / "m.h5")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "cuda" in err
    assert not (tmp_path / "m.h5").exists()
