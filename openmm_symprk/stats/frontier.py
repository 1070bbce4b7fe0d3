"""Accuracy against cost at equal accuracy: the frontier of integrator families (pure numerics).

A family is the rows of one integrator that differ only in the step h.  For small h the bias of an observable
against the h -> 0 reference is b(h) = c h^p (p the method's order).  Given each row's bias per replica, paired with
the reference replica by replica (the same initial state), this module

* fits c per family and observable by weighted least squares through the origin in x = h^p (weights 1/SE^2 of the
  rows' mean biases): c = sum w x b / sum w x^2 (:func:`fit_c`);
* resamples the replicas (the same resampled replicas for every row and family: they share the reference and the
  initial states) for the spread of c (:func:`bootstrap`);
* at tolerances eps (one per observable, declared before the data) gives each family's equal-accuracy step
  h_eps = min over observables of (eps / |c|)^(1/p), capped at the largest step the family ran (beyond it nothing
  was measured: a bias inside the tolerance at every measured step says nothing about the next one), its cost per
  unit of simulated time (cost per step / h_eps), and the ratio of two families' costs with a bootstrap interval;
* and the largest step at which every observable stays inside its tolerance with a stated confidence (the
  ``1 - level`` quantile of the bootstrap's h_eps: the step a user can take).

Two families of the same order compare by one number per observable whatever eps:
cost_B / cost_A = (s_B / s_A) (c_B / c_A)^(1/p); with several observables the step is the smallest h_eps over them,
so the answer depends on the tolerances' relative sizes, and a family whose bias is indistinguishable from zero is
limited by its largest measured step.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..support.errors import InputError

__all__ = ["Family", "fit_c", "bootstrap", "equal_accuracy_step", "FrontierPoint", "frontier", "compare"]


@dataclass(frozen=True)
class Family:
    """One integrator's rows.  ``steps`` (R,) the step of each row; ``bias`` {observable: (R, N) array} the paired
    bias of each row's replica k against the reference's replica k (NaN where the row has no replica k);
    ``order`` p; ``cost_per_step`` in any unit shared by the families compared (force evaluations, or wall
    seconds per step)."""

    name: str
    steps: tuple
    bias: dict
    order: int = 2
    cost_per_step: float = 1.0
    cap: float | None = None  # the largest usable step (default: the largest measured)

    def __post_init__(self):
        steps = np.asarray(self.steps, dtype=float)
        if steps.ndim != 1 or not len(steps) or not np.all(steps > 0):
            raise InputError(f"{self.name}: steps must be a non-empty list of positive steps, got {self.steps!r}")
        for obs, b in self.bias.items():
            if np.shape(b)[0] != len(steps):
                raise InputError(f"{self.name}: {obs} has {np.shape(b)[0]} rows of biases for {len(steps)} steps")
        if not self.order >= 1:
            raise InputError(f"{self.name}: order must be >= 1, got {self.order!r}")

    @property
    def largest_step(self) -> float:
        return float(self.cap if self.cap is not None else max(self.steps))


def _row_stats(b: np.ndarray) -> tuple:
    """(mean, standard error, count) per row of an (R, N) array with NaN for missing replicas."""
    n = np.sum(np.isfinite(b), axis=1)
    mean = np.where(n > 0, np.nansum(np.where(np.isfinite(b), b, 0.0), axis=1) / np.maximum(n, 1), np.nan)
    dev = np.where(np.isfinite(b), b - mean[:, None], 0.0)
    var = np.where(n > 1, np.sum(dev * dev, axis=1) / np.maximum(n - 1, 1), np.nan)
    return mean, np.sqrt(var / np.maximum(n, 1)), n


def fit_c(steps, bias, order: int, weights=None) -> float:
    """c of b(h) = c h^p by weighted least squares through the origin over the rows (``bias`` (R, N), NaN for
    missing replicas); ``weights`` per row (default 1/SE^2 of the row means; a row with one replica, or none, is left
    out)."""
    x = np.asarray(steps, dtype=float) ** order
    mean, se, n = _row_stats(np.asarray(bias, dtype=float))
    w = 1.0 / se ** 2 if weights is None else np.asarray(weights, dtype=float)
    ok = np.isfinite(mean) & np.isfinite(w) & (w > 0)
    if not ok.any():
        raise InputError("no row with a finite mean bias and a positive weight: need at least two replicas in a row")
    return float(np.sum(w[ok] * x[ok] * mean[ok]) / np.sum(w[ok] * x[ok] ** 2))


def _weights(family: Family, obs: str) -> np.ndarray:
    _, se, _ = _row_stats(np.asarray(family.bias[obs], dtype=float))
    return 1.0 / se ** 2


def bootstrap(families, observables, n_boot: int = 2000, seed: int = 1) -> dict:
    """{family name: {observable: (n_boot,) array of c}}: the replicas resampled with replacement, the same indices
    for every row of every family (they are paired through the reference and the initial states); each fit keeps the
    weights of the full data (resampling them too would let a resample with two equal replicas weigh a row
    infinitely)."""
    families = list(families)
    n = max(np.shape(f.bias[o])[1] for f in families for o in observables)
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, n, size=(n_boot, n))
    out = {}
    for f in families:
        out[f.name] = {}
        for obs in observables:
            b = np.asarray(f.bias[obs], dtype=float)
            b = np.pad(b, ((0, 0), (0, n - b.shape[1])), constant_values=np.nan)
            w = _weights(f, obs)
            x = np.asarray(f.steps, dtype=float) ** f.order
            cs = np.empty(n_boot)
            for i, pick in enumerate(picks):
                mean, _, count = _row_stats(b[:, pick])
                ok = np.isfinite(mean) & np.isfinite(w) & (w > 0)
                cs[i] = np.sum(w[ok] * x[ok] * mean[ok]) / np.sum(w[ok] * x[ok] ** 2) if ok.any() else np.nan
            out[f.name][obs] = cs
    return out


def equal_accuracy_step(cs: dict, tolerances: dict, order: int, cap: float) -> np.ndarray:
    """h_eps = min over observables of (eps / |c|)^(1/p), at most ``cap``; ``cs`` {observable: c or array of c}; NaN
    where some c is NaN (a bootstrap resample that left a row without data says nothing of the step)."""
    h = np.asarray(cap, dtype=float)
    for obs, eps in tolerances.items():
        c = np.abs(np.asarray(cs[obs], dtype=float))
        with np.errstate(divide="ignore"):
            step = np.where(c > 0, (eps / np.where(c > 0, c, 1.0)) ** (1.0 / order), np.inf)
        h = np.where(np.isnan(c), np.nan, np.minimum(h, step))  # no c (a resample without data): no step
    return h


@dataclass(frozen=True)
class FrontierPoint:
    """One family at one set of tolerances: the equal-accuracy step (fitted c's) and its cost per unit of simulated
    time, the step every observable stays inside with the stated confidence (``safe_step``), which observable limits
    the step (or "largest step" where none does before the cap)."""

    family: str
    step: float
    cost: float
    safe_step: float
    safe_cost: float
    limited_by: str
    samples: np.ndarray = field(repr=False)  # bootstrap h_eps, in the bootstrap's order (NaN: a resample without data)


def frontier(family: Family, tolerances: dict, boot: dict, level: float = 0.95) -> FrontierPoint:
    """``family`` at ``tolerances`` ({observable: eps}); ``boot`` its {observable: bootstrap c's}."""
    cs = {obs: fit_c(family.steps, family.bias[obs], family.order, _weights(family, obs)) for obs in tolerances}
    step = float(equal_accuracy_step(cs, tolerances, family.order, family.largest_step))
    limits = {obs: float(equal_accuracy_step({obs: cs[obs]}, {obs: eps}, family.order, np.inf))
              for obs, eps in tolerances.items()}
    binding = min(limits, key=limits.get)
    limited_by = binding if limits[binding] < family.largest_step else "largest step"
    samples = equal_accuracy_step({obs: boot[obs] for obs in tolerances}, tolerances, family.order, family.largest_step)
    safe = float(np.nanquantile(samples, 1.0 - level)) if np.isfinite(samples).any() else float("nan")
    return FrontierPoint(family.name, step, family.cost_per_step / step, safe, family.cost_per_step / safe,
                         limited_by, samples)


def compare(ours: FrontierPoint, theirs: FrontierPoint, cost_ours: float, cost_theirs: float,
            level: float = 0.95) -> tuple:
    """(ratio, low, high): how many times less ``ours`` costs per unit of simulated time than ``theirs`` at equal
    accuracy, cost_theirs/h_theirs over cost_ours/h_ours (the costs per step given: force evaluations or wall time),
    with the bootstrap's central ``level`` interval (the two families' samples come from the same resampled replicas,
    in the same order; nans where no resample gives both)."""
    if len(ours.samples) != len(theirs.samples):
        raise ValueError("the two families' bootstrap samples must come from the same resamples (one bootstrap call)")
    ratio = (cost_theirs / theirs.step) / (cost_ours / ours.step)
    boot = (cost_theirs / theirs.samples) / (cost_ours / ours.samples)
    boot = boot[np.isfinite(boot)]
    if not len(boot):
        return float(ratio), float("nan"), float("nan")
    tail = (1.0 - level) / 2
    return float(ratio), float(np.quantile(boot, tail)), float(np.quantile(boot, 1.0 - tail))
