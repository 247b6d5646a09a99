"""Run under NUMBA_ENABLE_CUDASIM=1 by tests/kernels/test_cuda.py: the CUDA grid
kernel on a tiny grid against the CPU grid; prints one JSON line."""
import json
import sys

import numpy as np

from kernels import cuda as kcuda
from kernels.batch import _rollout_grid, blocks_for
from kernels.rollout import _prepare, max_steps_for
from kernels.support import _point_table

V_NOTCH = [(0.0, 0.0), (60.0, 0.0), (40.0, 15.0), (60.0, 30.0), (0.0, 30.0)]
TRIANGLE = [(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)]

out = []
for xy, model, mu in ((V_NOTCH, 0, 0.3), (TRIANGLE, 0, 0.2), (V_NOTCH, 2, 0.6)):
    prep = _prepare(np.array(xy, float))
    th = np.radians(np.arange(0.0, 360.0, 30.0) + 0.37)
    d = np.array([-0.9, -0.3, 0.2, 0.6, 1.3])  # |d| > 1 plus the pin radius: misses
    gpu = kcuda.rollout_grid(*prep, model, mu, 3.0, th, d, 0.0, np.inf, 0.1, 1e-7,
                             max_steps_for(len(xy)))
    cpu = _rollout_grid(*prep, model, mu, 3.0, th, d, 0.0, np.inf, 0.1, 1e-7,
                        blocks_for(2, th.size * d.size))
    out.append({"gpu": [np.asarray(x).tolist() for x in gpu],
                "cpu": [np.asarray(x).tolist() for x in cpu]})
# A point support: the kernel code MINPOWER_POINTS with the support points in
# the support table in place of its quadrature rows, built by the function
# ``simulate._kernel_part`` uses (a table stacked by hand here read its header
# wrongly and so ran past its end: results that changed from run to run).
prep = _prepare(np.array(TRIANGLE, float))
pts = np.array([[-0.6, -0.3, 0.3], [0.8, -0.3, 0.3], [-0.2, 0.5, 0.4]])
quad = _point_table(prep[3], pts)
prep = prep[:3] + (quad,) + prep[4:]
th = np.radians(np.arange(0.0, 360.0, 30.0) + 0.37)
d = np.array([-0.9, -0.3, 0.2, 0.6, 1.3])
gpu = kcuda.rollout_grid(*prep, 3, 0.2, 3.0, th, d, 0.0, np.inf, 0.1, 1e-7, max_steps_for(3))
cpu = _rollout_grid(*prep, 3, 0.2, 3.0, th, d, 0.0, np.inf, 0.1, 1e-7,
                    blocks_for(2, th.size * d.size))
out.append({"gpu": [np.asarray(x).tolist() for x in gpu],
            "cpu": [np.asarray(x).tolist() for x in cpu]})
json.dump(out, sys.stdout)
