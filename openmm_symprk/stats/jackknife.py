"""The delete-one-group jackknife: the standard error of a non-linear function of an average.

The members (molecules of a liquid, replicas) are cut into G disjoint groups of consecutive members, the figure
recomputed from the average over all groups but one, G times, and

    SE = sqrt((G - 1) / G  sum_g (f_(g) - mean_g f_(g))^2).

A correlation time or the first minimum of a correlation function is a non-linear function of the curve, which
the jackknife handles better than the scatter of the figures of small groups (each group's own curve is noisier
and the figure of a noisy curve is biased).
"""
from __future__ import annotations

import numpy as np

from ..support.errors import InputError

__all__ = ["jackknife"]


def jackknife(per_member, statistic, n_groups: int = 20):
    """(statistic of the average over members, its delete-one-group jackknife standard error).

    ``per_member``: (L, n) or (L, n, ...) - a quantity per member (a molecule, a replica) on axis 1;
    ``statistic``: a function of the average over members (shape (L, ...)) returning a float or an array of
    floats; ``n_groups``: the number of disjoint groups of consecutive members (at most one per member, at
    least 2)."""
    c = np.asarray(per_member, dtype=np.float64)
    n = c.shape[1] if c.ndim >= 2 else 0
    if n_groups < 2 or n < 2:
        raise InputError(f"the jackknife needs n_groups >= 2 and at least 2 members, got {n_groups} and {n}")
    groups = np.array_split(np.arange(n), min(int(n_groups), n))
    total = c.sum(axis=1)
    value = statistic(total / n)
    jack = np.array([statistic((total - c[:, g].sum(axis=1)) / (n - len(g))) for g in groups], dtype=np.float64)
    g = len(groups)
    se = np.sqrt((g - 1) / g * ((jack - jack.mean(axis=0)) ** 2).sum(axis=0))
    return value, (float(se) if np.ndim(se) == 0 else se)
