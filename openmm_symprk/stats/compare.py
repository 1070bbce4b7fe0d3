"""Estimates over replicas, and whether two rows agree.

Independent replicas (runs from different equilibrated states) give two standard errors of a mean: one from the
correlation-corrected errors of each replica, one model-free from the scatter of their means.  :func:`combine`
reports the larger, so neither an underestimated correlation time nor a lucky handful of replicas makes an error
bar too small.  Rows run from the same replica states are compared replica by replica (:func:`paired`): what the
replicas share (each its own total energy, and much of the scatter that follows from it) cancels in the
differences.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..support.errors import InputError

__all__ = ["Estimate", "combine", "paired", "difference", "agrees", "no_larger"]


@dataclass
class Estimate:
    mean: float
    se: float
    replicas: int = 1
    se_within: float = float("nan")  # from the correlation-corrected errors of each replica
    se_between: float = float("nan")  # from the scatter of the replica means (nan for one replica)

    def __format__(self, spec):
        spec = spec or ".2f"
        return f"{format(self.mean, spec)} ± {format(self.se, spec)}"

    def as_dict(self) -> dict:
        return {"mean": self.mean, "se": self.se, "replicas": self.replicas, "se_within": self.se_within,
                "se_between": self.se_between}


def combine(means, ses) -> Estimate:
    """The mean over replicas and the larger of the two standard errors (within / between replicas)."""
    means = np.asarray(means, dtype=np.float64)
    ses = np.asarray(ses, dtype=np.float64)
    r = len(means)
    if r == 0:
        raise InputError("no replicas to combine")
    if len(ses) != r:
        raise InputError(f"{r} means but {len(ses)} standard errors")
    within = float(np.sqrt((ses ** 2).sum()) / r)
    between = float(means.std(ddof=1) / np.sqrt(r)) if r > 1 else float("nan")
    se = within if not np.isfinite(between) else max(within, between)
    return Estimate(float(means.mean()), se, r, within, between)


def paired(row: dict, ref: dict) -> Estimate | None:
    """The row minus the reference over the replicas both have (``{replica: (mean, se)}`` each), or None."""
    common = sorted(set(row) & set(ref))
    if not common:
        return None
    return combine([row[r][0] - ref[r][0] for r in common],
                   [float(np.hypot(row[r][1], ref[r][1])) for r in common])


def difference(a: Estimate, b: Estimate) -> Estimate:
    """a - b for independent estimates (errors added in quadrature)."""
    return Estimate(a.mean - b.mean, float(np.hypot(a.se, b.se)), min(a.replicas, b.replicas))


def agrees(a: Estimate, b: Estimate, k: float = 2.0) -> bool:
    """|a - b| within ``k`` combined standard errors (pass ``Estimate(0, 0)`` as ``b`` for a paired difference)."""
    d = difference(a, b)
    return abs(d.mean) <= k * d.se


def no_larger(a: Estimate, b: Estimate, k: float = 2.0) -> bool:
    """|a| is not larger than |b| beyond ``k`` combined standard errors (e.g. a drift against a baseline's)."""
    return abs(a.mean) <= abs(b.mean) + k * float(np.hypot(a.se, b.se))
