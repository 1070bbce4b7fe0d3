"""Checks of the frames read from a trajectory before anything is computed from them (numpy; MDAnalysis' units,
Angstrom and ps).  Each finds one way a trajectory gives wrong figures without failing, and returns a sentence
saying what it found (None when the frames pass), for the caller to raise with its own advice:

* :func:`time_steps` - frames evenly spaced in time, or where they are not (files of one run with a stretch not
  written between them, a file whose clock starts again): a time correlation over them would join what is not
  joined;
* :func:`geometry_problem` - the molecules found in the topology are water in the frame: O-H and H-H distances
  in :data:`OH_RANGE` and :data:`HH_RANGE` (a topology listing the atoms in another order than the trajectory
  takes an H for the O);
* :func:`wrapped_problem` - positions without a box are continuous: no molecule split across the system, no
  centre of mass jumping by about the system's width between frames (positions wrapped into a box the file
  does not store, which would be taken as motion).
"""
from __future__ import annotations

import numpy as np

__all__ = ["TIME_RTOL", "OH_RANGE", "HH_RANGE", "SPLIT_LIMIT", "JUMP_FRACTION", "MIN_JUMP", "time_steps",
           "describe_steps", "geometry_problem", "wrapped_problem"]

#: Relative spread of the time steps accepted as one interval (beyond float32's rounding of the times).
TIME_RTOL = 1e-3
#: Accepted O-H distances of a water, Angstrom (rigid and flexible models: 0.96-1.0).
OH_RANGE = (0.8, 1.2)
#: Accepted H-H distances of a water, Angstrom (rigid and flexible models: 1.5-1.65).
HH_RANGE = (1.3, 1.9)
#: Without a box, a site farther than this from its molecule's first atom (Angstrom) means a split molecule.
SPLIT_LIMIT = 3.0
#: A centre of mass stepping more than this fraction of the system's width (and more than MIN_JUMP Angstrom)
#: between frames is taken for a jump across a box.
JUMP_FRACTION = 0.8
#: The smallest step of a centre of mass between frames (Angstrom) taken for a jump across a box.
MIN_JUMP = 5.0


def time_steps(times) -> tuple:
    """(dt, irregular): the interval between the frames at ``times`` (ps; the mean step) and the indices k whose
    step times[k + 1] - times[k] differs from the median step by more than :data:`TIME_RTOL` of it (or than the
    float32 rounding of the times, as XTC stores them).  ``irregular`` is empty for evenly spaced frames."""
    t = np.asarray(times, dtype=np.float64)
    if len(t) < 2:
        return float("nan"), np.zeros(0, dtype=int)
    steps = np.diff(t)
    median = float(np.median(steps))
    tol = max(TIME_RTOL * abs(median), 4.0 * float(np.spacing(np.float32(np.abs(t).max()))))
    irregular = np.flatnonzero(~(np.abs(steps - median) <= tol)) if median > 0 else np.arange(len(steps))
    return float((t[-1] - t[0]) / (len(t) - 1)) if median > 0 else median, irregular


def describe_steps(times, irregular, frame_numbers=None) -> str:
    """A sentence naming the first irregular step of ``times`` (and how many there are), with the frames'
    numbers (``frame_numbers``, default 0, 1, ...)."""
    t = np.asarray(times, dtype=np.float64)
    numbers = np.arange(len(t)) if frame_numbers is None else np.asarray(frame_numbers)
    k = int(irregular[0])
    step = t[k + 1] - t[k]
    regular = np.delete(np.diff(t), irregular)
    usual = float(regular.mean()) if len(regular) else float("nan")
    # to one decimal place beyond the usual step's first digit: 100002.9, not 100003 or 100002.8984
    places = 1 + max(0, -int(np.floor(np.log10(abs(usual))))) if np.isfinite(usual) and usual != 0 else 3
    fixed = (lambda value: f"{value:.{places}f}".rstrip("0").rstrip("."))
    what = (f"time goes back by {fixed(-step)} ps" if step < 0 else "no time passes" if step == 0 else
            f"{fixed(step)} ps pass")
    more = f" ({len(irregular)} such steps)" if len(irregular) > 1 else ""
    return (f"the frames are not evenly spaced in time: between frame {numbers[k]} (t = {fixed(t[k])} ps) and "
            f"frame {numbers[k + 1]} (t = {fixed(t[k + 1])} ps) {what} where the other frames are {fixed(usual)} ps "
            f"apart{more}")


def _whole(x, molecules, box):
    """Sites (F, n, k, 3) of each molecule at the image nearest its first atom (box: 3 edges, or None)."""
    xg = x[:, molecules].astype(np.float64)
    if box is not None:
        d = xg - xg[:, :, :1]
        xg -= np.asarray(box, dtype=np.float64) * np.round(d / np.asarray(box, dtype=np.float64))
    return xg


def geometry_problem(x0, molecules, box=None, residues=None) -> str | None:
    """Whether the molecules ``molecules`` (n, k: O, H, H, massless sites) of the frame ``x0`` (N, 3) Angstrom
    (``box``: 3 edges in Angstrom, or None) are water: None when every O-H distance lies in :data:`OH_RANGE` and
    every H-H in :data:`HH_RANGE`, else a sentence naming the first molecule outside (``residues``: a label per
    molecule) and what the molecules have."""
    xg = _whole(np.asarray(x0)[None], np.asarray(molecules)[:, :3], box)[0]
    oh = np.linalg.norm(xg[:, 1:3] - xg[:, :1], axis=2)  # (n, 2)
    hh = np.linalg.norm(xg[:, 2] - xg[:, 1], axis=1)
    bad = ((oh < OH_RANGE[0]) | (oh > OH_RANGE[1])).any(axis=1) | (hh < HH_RANGE[0]) | (hh > HH_RANGE[1])
    if not bad.any():
        return None
    i = int(np.argmax(bad))
    label = f"molecule {i}" + (f" ({residues[i]})" if residues is not None else "")
    med = np.median(oh, axis=0)
    return (f"{label} is not water in the first frame: O-H {oh[i, 0]:.2f} and {oh[i, 1]:.2f} Angstrom, H-H "
            f"{hh[i]:.2f} Angstrom, where water has O-H {OH_RANGE[0]}-{OH_RANGE[1]} and H-H {HH_RANGE[0]}-"
            f"{HH_RANGE[1]} Angstrom; {int(bad.sum())} of {len(bad)} molecules are outside (medians: O-H {med[0]:.2f} "
            f"and {med[1]:.2f}, H-H {np.median(hh):.2f} Angstrom): are the topology's atoms in the order of the "
            f"trajectory's?")


def wrapped_problem(x, masses, molecules, times=None, frame_numbers=None, jumps: bool = True) -> str | None:
    """Whether positions ``x`` (F, N, 3) Angstrom stored without a box look wrapped into one: None when they
    look continuous, else a sentence saying what was found: a molecule split (a site more than
    :data:`SPLIT_LIMIT` Angstrom from its first atom), or a centre of mass (``masses`` (N,)) that steps between
    two frames by more than :data:`JUMP_FRACTION` of the system's width along an axis (and more than
    :data:`MIN_JUMP` Angstrom) - a molecule leaving the box on one side and coming back on the other
    (``jumps=False``: splits only, for what whole molecules that jump do not change)."""
    x = np.asarray(x)
    idx = np.asarray(molecules)
    numbers = np.arange(len(x)) if frame_numbers is None else np.asarray(frame_numbers)
    when = (lambda f: f"frame {numbers[f]}" + ("" if times is None else f" (t = {times[f]:g} ps)"))
    split = np.linalg.norm(x[:, idx[:, 1:]] - x[:, idx[:, :1]], axis=3)  # (F, n, k - 1), float32 is plenty
    far = split > SPLIT_LIMIT
    if far.any():
        f, i, _ = (int(a) for a in np.argwhere(far)[0])
        return (f"molecule {i} is split in {when(f)}: a site lies {split[f, i].max():.1f} Angstrom from its oxygen "
                f"({int(far.any(axis=2).sum())} molecule-frames so): the positions are wrapped into a periodic box "
                f"the trajectory does not store")
    if not jumps or idx.shape[0] < 2 or len(x) < 2:
        return None
    m = np.asarray(masses, dtype=np.float64)[idx]
    w = m / m.sum(axis=1, keepdims=True)
    com = np.einsum("nk,fnkd->fnd", w, x[:, idx].astype(np.float64))
    width = np.ptp(com, axis=1)  # (F, 3)
    limit = np.maximum(JUMP_FRACTION * np.maximum(width[:-1], width[1:]), MIN_JUMP)
    step = np.abs(np.diff(com, axis=0))  # (F - 1, n, 3)
    jump = step > limit[:, None, :]
    if not jump.any():
        return None
    f, i, d = (int(a) for a in np.argwhere(jump)[0])
    return (f"the centre of mass of molecule {i} jumps {step[f, i, d]:.1f} Angstrom along {'xyz'[d]} between "
            f"{when(f)} and {when(f + 1)}, about the width of the system along {'xyz'[d]} ({width[f, d]:.1f} "
            f"Angstrom), as a molecule leaving a periodic box on one side and coming back on the other "
            f"({int(jump.any(axis=2).sum())} such jumps): the positions are wrapped into a box the trajectory does "
            f"not store, and without it they cannot be unwrapped (the MSD and D would count each jump as motion)")
