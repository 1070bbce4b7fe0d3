"""Translational self-diffusion from centre-of-mass trajectories (pure numpy).  Units: nm, ps; D reported in
1e-5 cm^2/s as the literature does (1 nm^2/ps = 1000 x 1e-5 cm^2/s).

Computed, in order:

1. :func:`unwrap` - periodic (wrapped) centres of mass made continuous: each frame-to-frame displacement is
   taken as its minimum image, so no molecule may move more than half a box edge between stored frames (an
   error says so when a step comes close to it).  Positions from an OpenMM State without
   ``enforcePeriodicBox`` are already continuous and need no unwrapping.
2. :func:`mean_squared_displacement` - MSD(m dt) = <|r(t0 + m dt) - r(t0)|^2> averaged over every time origin
   t0, per molecule, by the FFT algorithm: MSD(m) = S1(m) - 2 S2(m) with S2 the origin-averaged position
   autocorrelation (:mod:`.correlation`) and S1(m) = mean over origins of r(k)^2 + r(k+m)^2 (cumulative sums).
3. :func:`remove_drift` - the motion of the molecules' common centre taken out (default in
   :func:`self_diffusion`): a run whose total momentum is not zero translates as a whole.
4. :func:`self_diffusion` - D = slope / 6 of an unweighted least-squares line through the molecule-averaged
   MSD over a stated lag window [t_min, t_max] (Einstein, 3-D); its standard error from the scatter of the
   same fit made per molecule (``error="molecules"``: s / sqrt(n_mol)) or per time block
   (``error="blocks"``: the trajectory cut into blocks, the fit made in each).  The molecules' error treats
   them as independent, which molecules of a liquid are not: they move together (a shared, fluctuating
   mobility; shared flows), and in 216 SPC/E waters (Langevin, 1/ps) the scatter of D between independent
   pieces of one run was 2.5x the molecules' error over 4-ps pieces and 2-2.6x over 20-ps pieces, the
   covariances between molecules 3-5x their own variances.  The scatter between independent replicas, which
   the study adds, is the check.  The MSD at short lags is ballistic and at long lags averages few origins, so
   the window must start after the ballistic regime (~1 ps in water) and end well before the trajectory's
   length.
5. :func:`block_error` - D's standard error from :data:`ERROR_BLOCKS` consecutive time blocks, which counts the
   correlations between molecules (0.85x the scatter between 20-ps pieces of that run, with a window to 2 ps),
   refused (ValueError saying why) where the fit window does not fit twice in a block: a window reaching half
   the run leaves one independent stretch of it, from which no error can be had.
6. :func:`yeh_hummer` - the finite-size correction for comparison with the literature only.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .correlation import origin_averaged_correlation
from .literature import K_BOLTZMANN, NM2_PER_PS_IN_1E5_CM2_PER_S, VISCOSITY_MPAS, XI_CUBIC
from .molecules import check_box
from ..support.errors import InputError



__all__ = ["unwrap", "remove_drift", "mean_squared_displacement", "DiffusionFit", "self_diffusion", "block_error",
           "ERROR_BLOCKS", "yeh_hummer", "VISCOSITY_MPAS", "XI_CUBIC", "NM2_PER_PS_IN_1E5_CM2_PER_S", "K_BOLTZMANN"]

_UNWRAP_LIMIT = 0.4  # a stored step beyond this fraction of an edge cannot be unwrapped safely
#: The number of consecutive time blocks :func:`block_error` takes D's error from.
ERROR_BLOCKS = 5


def unwrap(r, box) -> np.ndarray:
    """Continuous trajectories from periodic ones: ``r`` (F, n, 3) nm wrapped into an orthorhombic ``box``
    (3 edges nm, or (F, 3) one per frame: each step taken in the later frame's box), the first frame kept, each
    step replaced by its minimum image.  ValueError when a step exceeds 0.4 of an edge (frames stored too far
    apart to tell which image the molecule went to)."""
    r = np.asarray(r, dtype=np.float64)
    if r.ndim != 3 or r.shape[2] != 3:
        raise InputError(f"r must have shape (n_frames, n_molecules, 3) in nm, got {r.shape}")
    box = check_box(box, r.shape[0])[1:, None, :]
    step = np.diff(r, axis=0)
    step -= box * np.round(step / box)
    worst = np.abs(step / box).max() if step.size else 0.0
    if worst > _UNWRAP_LIMIT:
        raise InputError(f"a molecule moved {worst:.2f} of a box edge between two stored frames (limit "
                         f"{_UNWRAP_LIMIT}): store frames more often to unwrap the trajectory")
    out = np.empty_like(r)
    out[0] = r[0]
    np.cumsum(step, axis=0, out=out[1:])
    out[1:] += r[0]
    return out


def remove_drift(r, weights=None) -> np.ndarray:
    """``r`` (F, n, 3) nm with the motion of the molecules' common centre (weighted by ``weights`` (n,), e.g.
    the molecules' masses; equal weights by default, exact for one kind of molecule) taken out of every
    frame, the first frame kept.  A state equilibrated by Langevin dynamics without a CMMotionRemover
    carries a total momentum, and an NVE run from it translates as a whole at constant velocity (typically
    sqrt(3 kT / M) = 0.04 nm/ps for 216 waters at 300 K): ballistic, not diffusive, it adds V^2 t^2 to every
    MSD (0.16 nm^2 at 10 ps, as much as water's own diffusion).  With the total
    momentum zero (NVE from P = 0) the common centre does not move and nothing changes; for independent
    walkers (thermostats that do not conserve momentum) removing it lowers D by a factor 1 - 1/n."""
    r = np.asarray(r, dtype=np.float64)
    if r.ndim != 3 or r.shape[2] != 3:
        raise InputError(f"r must have shape (n_frames, n_molecules, 3) in nm, got {r.shape}")
    w = np.ones(r.shape[1]) if weights is None else np.asarray(weights, dtype=np.float64)
    if w.shape != (r.shape[1],) or not np.all(w >= 0) or not w.sum() > 0:
        raise InputError(f"weights must be {r.shape[1]} non-negative numbers (one per molecule), not all zero")
    centre = np.einsum("n,fnd->fd", w / w.sum(), r)
    return r - (centre - centre[0])[:, None, :]


def mean_squared_displacement(r, max_lag: int | None = None) -> np.ndarray:
    """MSD (max_lag + 1, n) nm^2 of each of n molecules at lags 0..max_lag frames (default half the
    trajectory), averaged over time origins, from continuous positions ``r`` (F, n, 3) nm."""
    r = np.asarray(r, dtype=np.float64)
    if r.ndim != 3 or r.shape[2] != 3:
        raise InputError(f"r must have shape (n_frames, n_molecules, 3) in nm, got {r.shape}")
    n = r.shape[0]
    s2 = origin_averaged_correlation(r, max_lag).sum(axis=2)
    lags = np.arange(s2.shape[0])
    sq = (r * r).sum(axis=2)
    csum = np.concatenate([np.zeros((1, sq.shape[1])), np.cumsum(sq, axis=0)])
    # sum_{k=0}^{n-m-1} r(k)^2 + sum_{k=m}^{n-1} r(k)^2
    s1 = (csum[n - lags] + (csum[n] - csum[lags])) / (n - lags)[:, None]
    return np.maximum(s1 - 2.0 * s2, 0.0)


@dataclass
class DiffusionFit:
    """D and its standard error (1e-5 cm^2/s), the molecule-averaged MSD it was fitted to, each molecule's MSD
    and the window."""

    D: float
    se: float
    lag_ps: np.ndarray  # (L,)
    msd: np.ndarray  # (L,) nm^2, averaged over molecules
    window_ps: tuple
    error: str  # "molecules" or "blocks"
    n_samples: int  # molecules or blocks the error came from
    msds: np.ndarray | None = None  # (L, n) nm^2, each molecule's

    def __format__(self, spec):
        spec = spec or ".3f"
        return f"{format(self.D, spec)} ± {format(self.se, spec)}"


def _slopes(t, y):
    """Least-squares slopes of y (L, ...) against t (L,)."""
    tc = t - t.mean()
    return np.tensordot(tc, y - y.mean(axis=0), axes=(0, 0)) / float(tc @ tc)


def _window(window_ps, dt_ps, max_lag):
    t_min, t_max = (float(w) for w in window_ps)
    lo, hi = int(np.ceil(t_min / dt_ps - 1e-6)), int(np.floor(t_max / dt_ps + 1e-6))  # dt from a float32 header
    if not 0 <= t_min < t_max or hi > max_lag or hi - lo < 2:
        raise InputError(f"fit window {window_ps} ps must satisfy 0 <= t_min < t_max <= the longest lag "
                         f"{max_lag * dt_ps:g} ps and hold at least 3 lags of {dt_ps:g} ps")
    return lo, hi


def self_diffusion(r, dt_ps: float, window_ps, *, error: str = "molecules", n_blocks: int = 5,
                   max_lag: int | None = None, drift: bool = True, weights=None) -> DiffusionFit:
    """Self-diffusion coefficient (1e-5 cm^2/s) from continuous centre-of-mass trajectories ``r`` (F, n, 3)
    nm sampled every ``dt_ps``: D = slope / 6 of the molecule-averaged MSD over lags in ``window_ps``
    (t_min, t_max) ps.  ``error``: "molecules" (the per-molecule fits' standard deviation / sqrt(n)) or
    "blocks" (the trajectory cut into ``n_blocks`` consecutive blocks, the window fitted in each; the
    window must then fit in a block).  ``drift`` (default True): take the common centre's motion out first
    (:func:`remove_drift`, with ``weights``).  Uncorrected for the box size (see :func:`yeh_hummer`)."""
    r = remove_drift(r, weights) if drift else np.asarray(r, dtype=np.float64)
    if not dt_ps > 0:
        raise InputError(f"dt_ps must be > 0 (the time between stored frames, ps), got {dt_ps}")
    if error not in ("molecules", "blocks"):
        raise InputError(f"error must be 'molecules' or 'blocks', got {error!r}")
    msd = mean_squared_displacement(r, max_lag)
    lo, hi = _window(window_ps, dt_ps, msd.shape[0] - 1)
    t = np.arange(lo, hi + 1) * dt_ps
    scale = NM2_PER_PS_IN_1E5_CM2_PER_S / 6.0
    mean_msd = msd.mean(axis=1)
    D = float(_slopes(t, mean_msd[lo:hi + 1])) * scale
    if error == "molecules":
        per = _slopes(t, msd[lo:hi + 1]) * scale
    else:
        if n_blocks < 2:
            raise InputError(f"n_blocks must be >= 2, got {n_blocks}")
        length = r.shape[0] // n_blocks
        if hi > length - 1:
            raise InputError(f"the fit window ends at {t[-1]:g} ps, longer than a block of {length} frames "
                             f"({(length - 1) * dt_ps:g} ps): use fewer blocks or a shorter window")
        per = _block_slopes(r, t, lo, hi, n_blocks) * scale
    if len(per) < 2:
        raise InputError("the error needs at least 2 molecules (or blocks)")
    se = float(np.std(per, ddof=1) / np.sqrt(len(per)))
    return DiffusionFit(D, se, np.arange(msd.shape[0]) * dt_ps, mean_msd, (float(t[0]), float(t[-1])), error,
                        len(per), msd)


def _block_slopes(r, t, lo: int, hi: int, n_blocks: int) -> np.ndarray:
    """The slopes (nm^2/ps) of the molecule-averaged MSD over lags lo..hi (times ``t``) in each of ``n_blocks``
    consecutive blocks of ``r``."""
    length = r.shape[0] // n_blocks
    return np.array([float(_slopes(t, mean_squared_displacement(r[b * length:(b + 1) * length], hi)[lo:]
                                   .mean(axis=1))) for b in range(n_blocks)])


def block_error(r, dt_ps: float, window_ps, *, n_blocks: int = ERROR_BLOCKS, drift: bool = True,
                weights=None) -> float:
    """The standard error (1e-5 cm^2/s) of D fitted over ``window_ps`` (t_min, t_max) ps to the whole of the
    continuous centre-of-mass trajectories ``r`` (F, n, 3) nm sampled every ``dt_ps`` (:func:`self_diffusion`,
    with the same ``drift`` and ``weights``): the run cut into ``n_blocks`` consecutive blocks, the same window
    fitted in each, s / sqrt(n_blocks) of the blocks' D.  Unlike the molecules' scatter it counts the
    correlations between molecules (a liquid's molecules move together), as long as the blocks are longer than
    the time over which they do (in water, a few ps).

    ValueError, saying why and what would do, unless t_max is at most half a block (each block then holds the
    window from half its frames as origins): a window reaching further leaves too few independent stretches
    of the run to tell an error from."""
    if isinstance(n_blocks, bool) or int(n_blocks) != n_blocks or n_blocks < 2:
        raise InputError(f"n_blocks must be an integer >= 2, got {n_blocks!r}")
    if not dt_ps > 0:
        raise InputError(f"dt_ps must be > 0 (the time between stored frames, ps), got {dt_ps}")
    r = remove_drift(r, weights) if drift else np.asarray(r, dtype=np.float64)
    length = r.shape[0] // int(n_blocks)
    t_min, t_max = (float(w) for w in window_ps)
    half = 0.5 * length * dt_ps
    if not t_max <= half + 1e-6 * dt_ps:
        run = (r.shape[0] - 1) * dt_ps
        raise InputError(f"no error bar: it comes from {n_blocks} blocks of the run ({run:g} ps: blocks of "
                         f"{length * dt_ps:g} ps), each of which must hold the fit window twice, and the window ends "
                         f"at {t_max:g} ps; a window ending by {half:g} ps, or a run of {2 * n_blocks * t_max:g} ps "
                         f"or more, gives one (the molecules' own scatter would understate it 2-3x: a liquid's "
                         f"molecules move together)")
    lo, hi = _window(window_ps, dt_ps, length - 1)
    t = np.arange(lo, hi + 1) * dt_ps
    per = _block_slopes(r, t, lo, hi, int(n_blocks)) * NM2_PER_PS_IN_1E5_CM2_PER_S / 6.0
    return float(np.std(per, ddof=1) / np.sqrt(len(per)))


def yeh_hummer(box_nm: float, temperature_k: float, viscosity_mpas: float) -> float:
    """The Yeh-Hummer finite-size correction k_B T xi / (6 pi eta L) in 1e-5 cm^2/s, to be added to D from a
    cubic periodic box of edge ``box_nm`` (xi = 2.837297): D_inf = D_PBC + correction.  For comparison with
    the literature only; ``viscosity_mpas``: the model's shear viscosity (e.g. :data:`VISCOSITY_MPAS`)."""
    for name, value in (("box_nm", box_nm), ("temperature_k", temperature_k), ("viscosity_mpas", viscosity_mpas)):
        if not float(value) > 0:
            raise InputError(f"{name} must be > 0, got {value}")
    si = K_BOLTZMANN * temperature_k * XI_CUBIC / (6.0 * np.pi * viscosity_mpas * 1e-3 * box_nm * 1e-9)  # m^2/s
    return float(si / 1e-9)  # 1e-5 cm^2/s = 1e-9 m^2/s
