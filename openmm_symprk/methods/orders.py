"""Observed convergence order from successive step refinements: the one order fit of the package.

Given final states y_N computed with N, 2N, 4N, ... steps over the same time, the differences
d_k = |y_{N_k} - y_{N_{k+1}}| shrink like (T/N_k)^p, so p = log(d_k / d_{k+1}) / log(N_{k+1} / N_k).  No
reference solution is needed, so a wrong coefficient cannot hide behind a wrong reference.  Used for the
pure-numpy reference integrators (:func:`.reference.measure_order`) and, by the test-suite, for OpenMM programs
(tests/helpers.py).
"""
from __future__ import annotations

import numpy as np

from ..support.errors import InputError


def observed_orders(states, steps):
    """(orders, differences) from final states computed with the step counts ``steps`` (increasing).

    ``differences[k]`` = max |states[k] - states[k+1]|; one order estimate per consecutive triple."""
    if len(states) != len(steps) or len(steps) < 3:
        raise InputError(f"need at least three states, one per step count; got {len(states)} states for "
                         f"step counts {list(steps)}")
    ys = [np.asarray(y, dtype=np.longdouble).ravel() for y in states]
    diffs = np.array([float(np.max(np.abs(a - b))) for a, b in zip(ys, ys[1:])])
    ratios = np.asarray(steps[1:-1], float) / np.asarray(steps[:-2], float)
    with np.errstate(divide="ignore", invalid="ignore"):
        orders = np.log(diffs[:-1] / diffs[1:]) / np.log(ratios)
    return orders, diffs
