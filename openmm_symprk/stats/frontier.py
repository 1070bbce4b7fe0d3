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

A family whose dynamics differ from the reference's at any step (OpenMM's Langevin integrators against a velocity-
rescaling reference: friction slows diffusion whatever h) names those observables in ``free``: their bias is fitted
as a + c h^p, and the equal-accuracy step is where |a + c h^p| leaves the tolerance, none (0) where |a| is already
beyond it: such a family costs infinitely much at that tolerance, as it should.  Families whose h-independent part
comes from one cause of different strengths (OpenMM's LangevinMiddleIntegrator at two frictions) share it: ``shared =
(group, s)`` makes a = kappa s, with one kappa fitted jointly over the group's rows (:func:`fits`): linear response in
the friction, which lets the strong friction's well-measured effect fix the weak one's.

Two families of the same order compare by one number per observable whatever eps:
cost_B / cost_A = (s_B / s_A) (c_B / c_A)^(1/p); with several observables the step is the smallest h_eps over them,
so the answer depends on the tolerances' relative sizes, and a family whose bias is indistinguishable from zero is
limited by its largest measured step.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..support.errors import InputError

__all__ = ["Family", "fit", "fit_c", "fits", "strata", "resample", "bootstrap", "equal_accuracy_step", "FrontierPoint",
           "frontier", "compare", "replicas_for_interval"]


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
    free: tuple = ()  # observables whose bias has an h-independent part a (fitted as a + c h^p)
    shared: tuple | None = None  # (group, s): the free observables' a is kappa * s, kappa shared by the group

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


def _solve(x, mean, w, intercept: bool) -> tuple:
    """(a, c) of mean = a + c x by weighted least squares (a = 0 without ``intercept``); NaNs where the rows cannot
    fix them (no row; an intercept with fewer than two distinct x)."""
    ok = np.isfinite(mean) & np.isfinite(w) & (w > 0)
    if not ok.any():
        return float("nan"), float("nan")
    x, mean, w = x[ok], mean[ok], w[ok]
    if not intercept:
        return 0.0, float(np.sum(w * x * mean) / np.sum(w * x * x))
    if len(np.unique(x)) < 2:
        return float("nan"), float("nan")
    sw, sx, sy = np.sum(w), np.sum(w * x), np.sum(w * mean)
    sxx, sxy = np.sum(w * x * x), np.sum(w * x * mean)
    c = (sw * sxy - sx * sy) / (sw * sxx - sx * sx)
    return float((sy - c * sx) / sw), float(c)


def fit(steps, bias, order: int, weights=None, intercept: bool = False) -> tuple:
    """(a, c) of b(h) = a + c h^p by weighted least squares over the rows (``bias`` (R, N), NaN for missing
    replicas; a = 0, through the origin, without ``intercept``); ``weights`` per row (default 1/SE^2 of the row
    means; a row with one replica, or none, is left out).  ValueError where no row can be used, or an intercept is
    asked for with fewer than two steps."""
    x = np.asarray(steps, dtype=float) ** order
    mean, se, n = _row_stats(np.asarray(bias, dtype=float))
    w = 1.0 / se ** 2 if weights is None else np.asarray(weights, dtype=float)
    a, c = _solve(x, mean, w, intercept)
    if not np.isfinite(c):
        raise InputError("no row with a finite mean bias and a positive weight (need at least two replicas in a row"
                         + (", and two steps for an intercept)" if intercept else ")"))
    return a, c


def fit_c(steps, bias, order: int, weights=None) -> float:
    """c of b(h) = c h^p, through the origin (:func:`fit` without an intercept)."""
    return fit(steps, bias, order, weights)[1]


def _joint(group, obs: str, means: dict) -> dict:
    """{family name: (a, c)} of ``obs`` for the families of one shared group, fitted jointly by weighted least squares:
    mean bias = kappa s_f + c_f h^p over every row of every family (``means``: {name: row means}); NaNs where the
    rows cannot fix them."""
    rows_y, rows_w, design = [], [], []
    k = len(group)
    for j, f in enumerate(group):
        x = np.asarray(f.steps, dtype=float) ** f.order
        w = _weights(f, obs)
        for xi, yi, wi in zip(x, means[f.name], w):
            if np.isfinite(yi) and np.isfinite(wi) and wi > 0:
                row = np.zeros(1 + k)
                row[0], row[1 + j] = f.shared[1], xi
                design.append(row)
                rows_y.append(yi)
                rows_w.append(wi)
    if len(rows_y) < 1 + k:
        return {f.name: (float("nan"), float("nan")) for f in group}
    sw = np.sqrt(np.asarray(rows_w))
    sol, *_ = np.linalg.lstsq(np.asarray(design) * sw[:, None], np.asarray(rows_y) * sw, rcond=None)
    return {f.name: (float(sol[0] * f.shared[1]), float(sol[1 + j])) for j, f in enumerate(group)}


def fits(families, obs: str, means: dict | None = None) -> dict:
    """{family name: (a, c)} of ``obs`` for every family: each on its own (:func:`fit`: a = 0 unless ``obs`` is
    free), or jointly within a shared group (:func:`_joint`).  ``means``: {name: row means} (default: the families'
    own; the bootstrap passes a resample's)."""
    families = list(families)
    if means is None:
        means = {f.name: _row_stats(np.asarray(f.bias[obs], dtype=float))[0] for f in families}
    out, groups = {}, {}
    for f in families:
        if obs in f.free and f.shared is not None:
            groups.setdefault(f.shared[0], []).append(f)
        else:
            x = np.asarray(f.steps, dtype=float) ** f.order
            out[f.name] = _solve(x, means[f.name], _weights(f, obs), obs in f.free)
    for group in groups.values():
        out.update(_joint(group, obs, means))
    return out


def _weights(family: Family, obs: str) -> np.ndarray:
    _, se, _ = _row_stats(np.asarray(family.bias[obs], dtype=float))
    return 1.0 / se ** 2


def strata(families, observables) -> list:
    """[(lo, hi), ...]: the replica indices cut where some row's replicas end (a row has replicas 0 .. count - 1, its
    count being one past its last finite column), so that a row of any count holds whole strata only."""
    families = list(families)
    n = max(np.shape(f.bias[o])[1] for f in families for o in observables)
    ends = {0, n}
    for f in families:
        for o in observables:
            finite = np.isfinite(np.asarray(f.bias[o], dtype=float))
            for row in finite:
                if row.any():
                    ends.add(int(np.flatnonzero(row)[-1]) + 1)
    ends = sorted(ends)
    return list(zip(ends[:-1], ends[1:]))


def resample(bands, n_boot: int, rng) -> np.ndarray:
    """(n_boot, n) replica indices drawn with replacement within each stratum of ``bands`` (:func:`strata`): a row
    with fewer replicas than others gets exactly its own count in every resample, and the replicas rows share stay
    paired.  One stratum: ``rng.integers(0, n, (n_boot, n))``."""
    return np.hstack([rng.integers(lo, hi, size=(n_boot, hi - lo)) for lo, hi in bands])


def bootstrap(families, observables, n_boot: int = 2000, seed: int = 1) -> dict:
    """{family name: {observable: (n_boot, 2) array of (a, c)}} (a = 0 but for the family's ``free`` observables):
    the replicas resampled with replacement, the same indices for every row of every family (they are paired through
    the reference and the initial states), within each stratum of :func:`strata` (rows run at more replicas than
    others); each fit keeps the weights of the full data (resampling them too would let a resample with two equal
    replicas weigh a row infinitely)."""
    families = list(families)
    bands = strata(families, observables)
    n = bands[-1][1]
    picks = resample(bands, n_boot, np.random.default_rng(seed))
    out = {f.name: {obs: np.empty((n_boot, 2)) for obs in observables} for f in families}
    for obs in observables:
        padded = {f.name: np.pad(np.asarray(f.bias[obs], dtype=float),
                                 ((0, 0), (0, n - np.shape(f.bias[obs])[1])), constant_values=np.nan)
                  for f in families}
        for i, pick in enumerate(picks):
            means = {name: _row_stats(b[:, pick])[0] for name, b in padded.items()}
            for name, pair in fits(families, obs, means).items():
                out[name][obs][i] = pair
    return out


def _pair(value) -> tuple:
    """(a, c) of a fit given as c alone (through the origin), as a pair, or as an (..., 2) array of pairs."""
    if isinstance(value, tuple):
        return np.asarray(value[0], dtype=float), np.asarray(value[1], dtype=float)
    arr = np.asarray(value, dtype=float)
    if arr.ndim >= 2 and arr.shape[-1] == 2:
        return arr[..., 0], arr[..., 1]
    return np.zeros_like(arr), arr


def equal_accuracy_step(fits: dict, tolerances: dict, order: int, cap: float) -> np.ndarray:
    """h_eps = min over observables of the largest h at which |a + c h^p| <= eps holds from h = 0 on (for a = 0:
    (eps / |c|)^(1/p); 0 where |a| > eps already), at most ``cap``; ``fits`` {observable: c, (a, c), or an (n, 2)
    array of (a, c) pairs}; NaN where a fit is NaN (a bootstrap resample that left a row without data says nothing
    of the step)."""
    h = np.asarray(cap, dtype=float)
    for obs, eps in tolerances.items():
        a, c = _pair(fits[obs])
        with np.errstate(divide="ignore", invalid="ignore"):
            x_out = np.where(c != 0, (np.sign(c) * eps - a) / np.where(c != 0, c, 1.0), np.inf)
            step = np.where(np.abs(a) > eps, 0.0, np.maximum(x_out, 0.0) ** (1.0 / order))
        h = np.where(np.isnan(c) | np.isnan(a), np.nan, np.minimum(h, step))  # no fit: no step
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


def frontier(family: Family, tolerances: dict, boot: dict, level: float = 0.95, point: dict | None = None) -> FrontierPoint:
    """``family`` at ``tolerances`` ({observable: eps}); ``boot`` its {observable: bootstrap (a, c)'s}; ``point`` its
    {observable: (a, c)} fitted on all the replicas (default: fitted here, on its own; a shared group's families pass
    their joint fit, :func:`fits`)."""
    cs = point if point is not None else {
        obs: fit(family.steps, family.bias[obs], family.order, _weights(family, obs), obs in family.free)
        for obs in tolerances}
    step = float(equal_accuracy_step(cs, tolerances, family.order, family.largest_step))
    limits = {obs: float(equal_accuracy_step({obs: cs[obs]}, {obs: eps}, family.order, np.inf))
              for obs, eps in tolerances.items()}
    binding = min(limits, key=limits.get)
    limited_by = binding if limits[binding] < family.largest_step else "largest step"
    samples = equal_accuracy_step({obs: boot[obs] for obs in tolerances}, tolerances, family.order, family.largest_step)
    safe = float(np.nanquantile(samples, 1.0 - level)) if np.isfinite(samples).any() else float("nan")
    with np.errstate(divide="ignore"):
        return FrontierPoint(family.name, step, family.cost_per_step / step if step > 0 else np.inf, safe,
                             family.cost_per_step / safe if safe > 0 else np.inf, limited_by, samples)


def compare(ours: FrontierPoint, theirs: FrontierPoint, cost_ours: float, cost_theirs: float,
            level: float = 0.95) -> tuple:
    """(ratio, low, high): how many times less ``ours`` costs per unit of simulated time than ``theirs`` at equal
    accuracy, cost_theirs/h_theirs over cost_ours/h_ours (the costs per step given: force evaluations or wall time),
    with the bootstrap's central ``level`` interval (the two families' samples come from the same resampled replicas,
    in the same order; nans where no resample gives both)."""
    if len(ours.samples) != len(theirs.samples):
        raise ValueError("the two families' bootstrap samples must come from the same resamples (one bootstrap call)")
    with np.errstate(divide="ignore", invalid="ignore"):  # a step of 0 (a bias beyond the tolerance at h -> 0): inf
        ratio = (cost_theirs / np.float64(theirs.step)) / (cost_ours / np.float64(ours.step))
        boot = (cost_theirs / theirs.samples) / (cost_ours / ours.samples)
    boot = boot[~np.isnan(boot)]
    if not len(boot):
        return float(ratio), float("nan"), float("nan")
    tail = (1.0 - level) / 2
    method = "linear" if np.isfinite(boot).all() else "inverted_cdf"  # no interpolation between infinite samples
    return (float(ratio), float(np.quantile(boot, tail, method=method)),
            float(np.quantile(boot, 1.0 - tail, method=method)))


def replicas_for_interval(n: int, ratio: float, low: float, high: float, within: float = 0.25) -> float:
    """Replicas that would bring a ratio's interval (``low``-``high`` around ``ratio``, measured over ``n``
    replicas) inside ``ratio`` (1 +- ``within``): on a log scale the interval's half-widths shrink as 1/sqrt(n),
    the measured scatter kept.  ``n`` where it is already inside; inf where an end is infinite or not a number (no
    replica count mends a family that meets the tolerance at no step)."""
    if n < 1 or not 0 < within < 1:
        raise InputError(f"replicas_for_interval: n must be >= 1 and within in (0, 1), got n={n!r}, within={within!r}")
    values = np.array([ratio, low, high], dtype=float)
    if not (np.isfinite(values).all() and (values > 0).all()):
        return float("inf")
    grow = max(np.log(ratio / low) / -np.log1p(-within), np.log(high / ratio) / np.log1p(within))
    return float(max(n, int(np.ceil(n * grow ** 2))))
