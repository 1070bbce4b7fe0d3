"""Radial distribution function of one kind of site (water's O) in an orthorhombic periodic box, and its
first peak.  Units: nm.

g(r) (:func:`radial_distribution`) is MDAnalysis' ``InterRDF`` (every distinct pair by the minimum image, bins of
width dr up to r_max <= half the shortest edge, each bin's count divided by the ideal-gas count, so that uniform
random points give g = 1), run on the frames given as arrays through an in-memory Universe.  It is used, not
re-implemented: against a numpy all-pairs histogram neither was faster by a margin that held on the
216-water benchmark (examples/analysis_benchmark.py, docs/analysis.md), and InterRDF's grid search scales
with N, not N^2.  Its error: the frames cut into
``n_blocks`` consecutive blocks, g of each block, standard deviation / sqrt(n_blocks).

First peak (:func:`first_peak`): the first run of bins beyond ``r_min`` where g > 1 (``above``), its
highest bin refined by the parabola through it and its two neighbours (vertex position and height); the
same on each block's g gives their standard errors.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..support import InputError, require
from .molecules import check_box

__all__ = ["Rdf", "radial_distribution", "Peak", "first_peak"]


@dataclass
class Rdf:
    """g(r) at the bin centres r (nm), its standard error and each block's g (n_blocks, n_bins)."""

    r: np.ndarray
    g: np.ndarray
    se: np.ndarray
    blocks: np.ndarray
    dr: float


def radial_distribution(x, box, r_max: float, dr: float = 0.005, n_blocks: int = 5) -> Rdf:
    """g(r) of the sites ``x`` (F, N, 3) nm (e.g. the O atoms of every water) in an orthorhombic ``box``
    (3 edges nm, or (F, 3) one per frame), in bins of ``dr`` nm up to ``r_max`` nm <= half the shortest
    edge, with block standard errors (``n_blocks`` <= F blocks of consecutive frames), by MDAnalysis'
    ``InterRDF`` on an in-memory Universe of the sites."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 3 or x.shape[2] != 3 or x.shape[1] < 2:
        raise InputError(f"x must have shape (n_frames, n_sites >= 2, 3) in nm, got {x.shape}")
    f, n = x.shape[:2]
    box = check_box(box, f)
    if not 0 < r_max <= 0.5 * box.min() + 1e-12:
        raise InputError(f"r_max = {r_max} nm must be > 0 and at most half the shortest box edge "
                         f"({0.5 * box.min():g} nm): the minimum image misses pairs beyond it")
    if not 0 < dr < r_max:
        raise InputError(f"dr must be between 0 and r_max = {r_max} nm, got {dr}")
    if not 1 <= n_blocks <= f:
        raise InputError(f"n_blocks must be between 1 and the number of frames {f}, got {n_blocks}")
    mda = require("MDAnalysis", "analysis", "openmm_symprk.analysis.structure.radial_distribution")
    InterRDF = require("MDAnalysis.analysis.rdf", "analysis", "openmm_symprk.analysis.structure").InterRDF
    MemoryReader = require("MDAnalysis.coordinates.memory", "analysis", "openmm_symprk.analysis.structure").MemoryReader

    n_bins = max(1, int(np.floor(r_max / dr + 1e-9)))
    u = mda.Universe.empty(n, trajectory=False)
    dims = np.hstack([box * 10.0, np.full((f, 3), 90.0)]).astype(np.float32)
    u.load_new((x * 10.0).astype(np.float32), format=MemoryReader, dimensions=dims)
    bounds = np.cumsum([0] + [len(b) for b in np.array_split(np.arange(f), n_blocks)])
    blocks, r = [], None
    for start, stop in zip(bounds[:-1], bounds[1:]):
        rdf = InterRDF(u.atoms, u.atoms, nbins=n_bins, range=(0.0, n_bins * dr * 10.0), exclusion_block=(1, 1))
        rdf.run(start=int(start), stop=int(stop))
        blocks.append(np.asarray(rdf.results.rdf, dtype=np.float64))
        r = np.asarray(rdf.results.bins, dtype=np.float64) * 0.1
    blocks = np.array(blocks)
    weights = np.diff(bounds) / f
    se = blocks.std(axis=0, ddof=1) / np.sqrt(n_blocks) if n_blocks > 1 else np.full(n_bins, np.nan)
    return Rdf(r, weights @ blocks, se, blocks, float(dr))


@dataclass
class Peak:
    """First peak of g(r): position (nm; Angstrom from :class:`openmm_symprk.analysis.universe.RadialDistribution`)
    and height, with standard errors from the blocks."""

    r: float
    height: float
    r_se: float
    height_se: float


def _vertex(r, g, r_min, above, unit="nm"):
    """Parabola through the highest bin of the first run of bins beyond r_min with g > above, and its two
    neighbours: (position, height)."""
    over = (r > r_min) & (g > above)
    if not over.any():
        raise InputError(f"g(r) never exceeds {above} beyond r_min = {r_min:g} {unit}: no first peak")
    start = int(np.argmax(over))
    stop = start + (int(np.argmin(over[start:])) if not over[start:].all() else len(g) - start)
    k = start + int(np.argmax(g[start:stop]))
    if k == 0 or k == len(g) - 1:
        raise InputError(f"the first peak's highest bin is at the end of the range (r = {r[k]:.4g} {unit}): "
                         f"no peak to refine (raise r_max or r_min)")
    g0, g1, g2 = g[k - 1], g[k], g[k + 1]
    curv = g0 - 2.0 * g1 + g2
    if curv >= 0:
        return float(r[k]), float(g1)
    h = r[1] - r[0]
    shift = 0.5 * (g0 - g2) / curv  # in bins, within [-1/2, 1/2] since g1 is the highest of the three
    return float(r[k] + shift * h), float(g1 - 0.25 * (g0 - g2) * shift)


def first_peak(rdf: Rdf, r_min: float = 0.0, above: float = 1.0, unit: str = "nm") -> Peak:
    """Position (nm) and height of the first peak of ``rdf``: the first run of bins beyond ``r_min`` nm where
    g > ``above`` (water's O-O: 0.26-0.33 nm), its highest bin refined by the parabola through it and its
    two neighbours; standard errors from the same on each block's g.  (``rdf.r`` in another unit gives the
    position in it: ``unit`` names it in the errors.)"""
    r, h = _vertex(rdf.r, rdf.g, r_min, above, unit)
    if len(rdf.blocks) > 1:
        per = np.array([_vertex(rdf.r, b, r_min, above, unit) for b in rdf.blocks])
        se = per.std(axis=0, ddof=1) / np.sqrt(len(per))
    else:
        se = (np.nan, np.nan)
    return Peak(r, h, float(se[0]), float(se[1]))
