"""Radial distribution function of one kind of site (water's O) in an orthorhombic periodic box, and its
first peak (pure numpy).  Units: nm.

g(r) (:func:`radial_distribution`): every distinct pair of the N sites at every frame, by the minimum image,
counted in bins of width dr up to r_max <= half the shortest edge (beyond it the minimum image misses
pairs); each bin's count divided by the ideal-gas count at the frame's density,

    g(r_b) = <n_b> / ( N (N - 1) / 2 * 4 pi (r_hi^3 - r_lo^3) / (3 V) ),

so that uniform random points give g = 1 (the N - 1 makes it exact at any N).  Its error: the frames cut
into ``n_blocks`` consecutive blocks, g of each block, standard deviation / sqrt(n_blocks).

First peak (:func:`first_peak`): the first run of bins beyond ``r_min`` where g > 1 (``above``), its
highest bin refined by the parabola through it and its two neighbours (vertex position and height); the
same on each block's g gives their standard errors.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Rdf", "radial_distribution", "Peak", "first_peak"]


@dataclass
class Rdf:
    """g(r) at the bin centres r (nm), its standard error and each block's g (n_blocks, n_bins)."""

    r: np.ndarray
    g: np.ndarray
    se: np.ndarray
    blocks: np.ndarray
    dr: float


def _frame_counts(x, box, edges):
    """Pair counts per bin of one frame (x (N, 3) nm)."""
    i, j = np.triu_indices(len(x), k=1)
    counts = np.zeros(len(edges) - 1)
    for start in range(0, len(i), 1 << 20):  # bounded memory for big frames
        d = x[j[start:start + (1 << 20)]] - x[i[start:start + (1 << 20)]]
        d -= box * np.round(d / box)
        counts += np.histogram(np.sqrt((d * d).sum(axis=1)), bins=edges)[0]
    return counts


def radial_distribution(x, box, r_max: float, dr: float = 0.005, n_blocks: int = 5) -> Rdf:
    """g(r) of the sites ``x`` (F, N, 3) nm (e.g. the O atoms of every water) in an orthorhombic ``box``
    (3 edges nm, or (F, 3) one per frame), in bins of ``dr`` nm up to ``r_max`` nm <= half the shortest
    edge, with block standard errors (``n_blocks`` <= F blocks of consecutive frames)."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 3 or x.shape[2] != 3 or x.shape[1] < 2:
        raise ValueError(f"x must have shape (n_frames, n_sites >= 2, 3) in nm, got {x.shape}")
    f, n = x.shape[:2]
    box = np.broadcast_to(np.asarray(box, dtype=np.float64), (f, 3)) if np.ndim(box) == 1 else np.asarray(box, float)
    if box.shape != (f, 3) or not np.all(box > 0):
        raise ValueError(f"box must be 3 edge lengths (nm, > 0) or one row of 3 per frame, got shape {box.shape}")
    if not 0 < r_max <= 0.5 * box.min() + 1e-12:
        raise ValueError(f"r_max = {r_max} nm must be > 0 and at most half the shortest box edge "
                         f"({0.5 * box.min():g} nm): the minimum image misses pairs beyond it")
    if not 0 < dr < r_max:
        raise ValueError(f"dr must be between 0 and r_max = {r_max} nm, got {dr}")
    if not 1 <= n_blocks <= f:
        raise ValueError(f"n_blocks must be between 1 and the number of frames {f}, got {n_blocks}")
    edges = np.arange(0.0, r_max + 0.5 * dr, dr)
    edges = edges[edges <= r_max + 1e-12]
    shell = 4.0 * np.pi * (edges[1:] ** 3 - edges[:-1] ** 3) / 3.0
    per_frame = np.array([_frame_counts(x[k], box[k], edges) * np.prod(box[k]) for k in range(f)])
    per_frame /= 0.5 * n * (n - 1) * shell
    blocks = np.array([b.mean(axis=0) for b in np.array_split(per_frame, n_blocks)])
    se = blocks.std(axis=0, ddof=1) / np.sqrt(n_blocks) if n_blocks > 1 else np.full(len(shell), np.nan)
    return Rdf(0.5 * (edges[1:] + edges[:-1]), per_frame.mean(axis=0), se, blocks, float(dr))


@dataclass
class Peak:
    """First peak of g(r): position (nm) and height, with standard errors from the blocks."""

    r: float
    height: float
    r_se: float
    height_se: float


def _vertex(r, g, r_min, above):
    """Parabola through the highest bin of the first run of bins beyond r_min with g > above, and its two
    neighbours: (position, height)."""
    over = (r > r_min) & (g > above)
    if not over.any():
        raise ValueError(f"g(r) never exceeds {above} beyond r_min = {r_min} nm: no first peak")
    start = int(np.argmax(over))
    stop = start + (int(np.argmin(over[start:])) if not over[start:].all() else len(g) - start)
    k = start + int(np.argmax(g[start:stop]))
    if k == 0 or k == len(g) - 1:
        raise ValueError(f"the first peak's highest bin is at the end of the range (r = {r[k]:.4g} nm): "
                         f"no peak to refine (raise r_max or r_min)")
    g0, g1, g2 = g[k - 1], g[k], g[k + 1]
    curv = g0 - 2.0 * g1 + g2
    if curv >= 0:
        return float(r[k]), float(g1)
    h = r[1] - r[0]
    shift = 0.5 * (g0 - g2) / curv  # in bins, within [-1/2, 1/2] since g1 is the highest of the three
    return float(r[k] + shift * h), float(g1 - 0.25 * (g0 - g2) * shift)


def first_peak(rdf: Rdf, r_min: float = 0.0, above: float = 1.0) -> Peak:
    """Position (nm) and height of the first peak of ``rdf``: the first run of bins beyond ``r_min`` nm where
    g > ``above`` (water's O-O: 0.26-0.33 nm), its highest bin refined by the parabola through it and its
    two neighbours; standard errors from the same on each block's g."""
    r, h = _vertex(rdf.r, rdf.g, r_min, above)
    if len(rdf.blocks) > 1:
        per = np.array([_vertex(rdf.r, b, r_min, above) for b in rdf.blocks])
        se = per.std(axis=0, ddof=1) / np.sqrt(len(per))
    else:
        se = (np.nan, np.nan)
    return Peak(r, h, float(se[0]), float(se[1]))
