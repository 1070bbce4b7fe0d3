"""Checks of the frames read from a trajectory before anything is computed from them (numpy; MDAnalysis' units,
Angstrom and ps).  Each finds one way a trajectory gives wrong figures without failing, and returns a sentence
saying what it found (None when the frames pass), for the caller to raise with its own advice:

* :func:`time_steps` - frames evenly spaced in time, or where they are not (files of one run with a stretch not
  written between them, a file whose clock starts again): a time correlation over them would join what is not
  joined;
* :func:`dt_problem` - an interval given for the frames (``symprk observe --dt``) agrees with the times the file
  stores: a gap or another interval is not joined or rescaled without a word;
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
           "describe_steps", "longest_piece", "dt_problem", "geometry_problem", "wrapped_problem"]

#: Relative spread of the time steps accepted as one interval (beyond float32's rounding of the times).
TIME_RTOL = 1e-3
#: Accepted O-H distances of a water, Angstrom (rigid and flexible models: 0.96-1.0).
OH_RANGE = (0.8, 1.2)
#: Accepted H-H distances of a water, Angstrom (rigid and flexible models: 1.5-1.65).
HH_RANGE = (1.3, 1.9)
#: Without a box, a site farther than this from its molecule's first atom (Angstrom) means a split molecule.
SPLIT_LIMIT = 3.0
#: A centre of mass stepping more than this fraction of the system's width (and more than :data:`MIN_JUMP`)
#: between frames is taken for a jump across a box.
JUMP_FRACTION = 0.8
#: The smallest step of a centre of mass between frames taken for a jump across a box, Angstrom.
MIN_JUMP = 5.0


def _tolerance(step: float, times) -> float:
    """How far a time step may differ from ``step`` (ps) and still be that step: :data:`TIME_RTOL` of it, or the
    float32 rounding of the ``times`` (as XTC stores them), whichever is larger."""
    return max(TIME_RTOL * abs(step), 4.0 * float(np.spacing(np.float32(np.abs(times).max()))))


def _fixed(usual: float):
    """A formatter of times to one decimal place beyond the first digit of ``usual`` (ps): 100002.9, not 100003
    or 100002.8984."""
    places = 1 + max(0, -int(np.floor(np.log10(abs(usual))))) if np.isfinite(usual) and usual != 0 else 3
    return lambda value: f"{value:.{places}f}".rstrip("0").rstrip(".")


def time_steps(times) -> tuple:
    """(dt, irregular): the interval between the frames at ``times`` (ps; the mean step) and the indices k whose
    step times[k + 1] - times[k] differs from the median step by more than :data:`TIME_RTOL` of it (or than the
    float32 rounding of the times, as XTC stores them).  ``irregular`` is empty for evenly spaced frames."""
    t = np.asarray(times, dtype=np.float64)
    if len(t) < 2:
        return float("nan"), np.zeros(0, dtype=int)
    steps = np.diff(t)
    median = float(np.median(steps))
    tol = _tolerance(median, t)
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
    fixed = _fixed(usual)
    what = (f"time goes back by {fixed(-step)} ps" if step < 0 else "no time passes" if step == 0 else
            f"{fixed(step)} ps pass")
    more = f" ({len(irregular)} such steps)" if len(irregular) > 1 else ""
    return (f"the frames are not evenly spaced in time: between frame {numbers[k]} (t = {fixed(t[k])} ps) and "
            f"frame {numbers[k + 1]} (t = {fixed(t[k + 1])} ps) {what} where the other frames are {fixed(usual)} ps "
            f"apart{more}")


def longest_piece(frame_numbers, breaks) -> tuple:
    """(first, stop) frame numbers (``--start``/``--stop``) of the longest run of ``frame_numbers`` not cut by
    ``breaks`` (the indices k of the steps between frame k and k + 1 that cut it)."""
    pieces = np.split(np.asarray(frame_numbers), np.asarray(breaks, dtype=int) + 1)
    longest = max(pieces, key=len)
    return int(longest[0]), int(longest[-1]) + 1


def dt_problem(times, dt: float, frame_numbers=None) -> tuple:
    """(problem, restarts) for an interval ``dt`` (ps between consecutive frames of the file) given for frames
    whose file stores ``times`` (ps; ``frame_numbers``: the frames' numbers in the file, default 0, 1, ...).

    Every step of the stored times must be ``dt`` times the frames it spans (within :data:`TIME_RTOL` and the
    float32 rounding of the times) or go back or stand still (a clock that starts again, as in files of one run
    each starting at t = 0: whether they follow each other only the user knows, and ``dt`` says they do).  A step
    forward by anything else contradicts ``dt``: a stretch of the run not written (``dt`` would join it) or
    another interval (``dt`` would rescale every time).  ``problem`` is None or a sentence naming the first such
    step, how many there are and what to do; ``restarts`` lists the frame numbers where the clock starts again."""
    t = np.asarray(times, dtype=np.float64)
    numbers = np.arange(len(t)) if frame_numbers is None else np.asarray(frame_numbers)
    steps = np.diff(t)
    want = dt * np.diff(numbers).astype(np.float64)
    tol = np.maximum(TIME_RTOL * np.abs(want), _tolerance(0.0, t))
    forward = steps > 0
    bad = np.flatnonzero(forward & ~(np.abs(steps - want) <= tol))
    restarts = [int(numbers[k + 1]) for k in np.flatnonzero(~forward)]
    if not len(bad):
        return None, restarts
    k = int(bad[0])
    fixed = _fixed(min(float(want[k]), float(steps[k])))
    more = f" ({len(bad)} of the {len(steps)} steps so)" if len(bad) > 1 else ""
    found = (f"--dt {dt:g} contradicts the times the file stores: between frame {numbers[k]} (t = {fixed(t[k])} ps) "
             f"and frame {numbers[k + 1]} (t = {fixed(t[k + 1])} ps) {fixed(steps[k])} ps pass, where --dt puts "
             f"{fixed(want[k])} ps{more}")
    if len(bad) == int(forward.sum()):  # every step forward disagrees: the file has another interval
        stored = float(np.median(steps[forward] / np.diff(numbers)[forward]))
        return (f"{found}: the file's frames are {fixed(stored)} ps apart; drop --dt to use the file's times "
                f"(--dt is for files that store none, or whose clock starts again)"), restarts
    first, stop = longest_piece(numbers, bad)
    return (f"{found}: --dt cannot join a stretch of the run that was not written; analyse one evenly spaced piece "
            f"with --start/--stop (the longest: --start {first} --stop {stop})"), restarts


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
