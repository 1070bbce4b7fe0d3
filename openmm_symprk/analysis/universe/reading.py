"""Reading a trajectory's waters into memory, checked, for ``symprk observe`` (:func:`read_waters`), and what it
needs around MDAnalysis: opening files with one clear error (:func:`open_universe`) and the box a topology holds
when the frames hold none (:func:`stored_box`).  MDAnalysis' units: Angstrom, ps."""
from __future__ import annotations

import gc
import os
import sys
import warnings
from dataclasses import dataclass

import numpy as np

from ...support import InputError, require
from .base import find_waters
from .checks import describe_steps, dt_problem, geometry_problem, longest_piece, time_steps, wrapped_problem

__all__ = ["WaterTrajectory", "read_waters", "open_universe", "stored_box"]

_NO_TIMES = "Reader has no dt information"  # MDAnalysis' warning for a format without times


@dataclass
class WaterTrajectory:
    """The waters read into memory: ``universe`` (an in-memory Universe of them), ``has_velocities``, ``dt``
    (ps between its frames), ``dt_from`` (where dt came from: "the file's times", "--dt" (with the frames where
    the file's clock starts again, if it does), or a note that the file stores none), ``box_from`` (None: each
    frame's own; else where the box of frames without one came from)."""

    universe: object
    has_velocities: bool
    dt: float
    dt_from: str
    box_from: str | None


def _quiet_mdanalysis_finalizers(unraisable):
    """sys.unraisablehook that drops the AttributeError of an MDAnalysis reader's __del__ on a reader whose
    __init__ failed (it closes a file it never opened); anything else goes to the default hook."""
    where = getattr(unraisable.object, "__module__", "") or ""
    if issubclass(unraisable.exc_type, AttributeError) and where.startswith("MDAnalysis"):
        return
    sys.__unraisablehook__(unraisable)


def open_universe(topology: str, trajectories):
    """``MDAnalysis.Universe(topology, trajectories)``; ValueError in one line when MDAnalysis cannot read them
    (whatever it raised), without the traceback MDAnalysis' half-built reader prints when it is freed."""
    mda = require("MDAnalysis", "analysis", "symprk observe")
    files = trajectories[0] if len(trajectories) == 1 else list(trajectories)
    hook, sys.unraisablehook = sys.unraisablehook, _quiet_mdanalysis_finalizers
    try:
        with warnings.catch_warnings(record=True) as caught:  # shown if the files open, dropped if not
            try:
                u = mda.Universe(topology, files)
            except Exception as exc:  # noqa: BLE001 - a parser may raise anything on a file it cannot read
                what = " ".join(str(exc).split())  # one line (MDAnalysis' topology errors hold two)
                message = f"MDAnalysis cannot read {topology} with {', '.join(trajectories)}: {what}"
                if not isinstance(exc, (OSError, ValueError)):
                    message += f" ({type(exc).__name__})"
                u = None
        if u is not None:
            for w in caught:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            return u
        gc.collect()  # the failed reader is freed here, under the quiet hook
        raise InputError(message)
    finally:
        sys.unraisablehook = hook


def _cryst1(path: str):
    """The box (a, b, c, alpha, beta, gamma) of the first CRYST1 record of a PDB file, or None (none, or the
    1 Angstrom placeholder of a file without a box)."""
    with open(path, "rb") as fh:
        for line in fh:
            if line.startswith(b"CRYST1"):
                try:
                    cell = np.array([float(line[a:b]) for a, b in ((6, 15), (15, 24), (24, 33), (33, 40),
                                                                   (40, 47), (47, 54))])
                except ValueError:
                    return None
                return None if np.allclose(cell[:3], 1.0) or not np.all(cell[:3] > 0) else cell
            if line.startswith((b"ATOM", b"HETATM")):
                return None
    return None


def stored_box(topology: str, trajectories):
    """(box, where) for frames that store none: the CRYST1 of a PDB among the files (a multi-model PDB holds one
    CRYST1 before its models, which MDAnalysis applies to no frame), else the box of the topology file read as
    coordinates (a GRO, a single-frame PDB); (None, None) when none holds one."""
    for path in list(trajectories) + [topology]:
        if str(path).lower().endswith((".pdb", ".ent")) and os.path.isfile(path):
            cell = _cryst1(path)
            if cell is not None:
                return cell, f"the CRYST1 record of {os.path.basename(path)}"
    mda = require("MDAnalysis", "analysis", "symprk observe")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cell = mda.Universe(topology).dimensions
    except Exception:  # noqa: BLE001 - a topology without coordinates (PSF, PRMTOP, TPR ...) holds no box
        return None, None
    if cell is None or not np.all(np.asarray(cell[:3]) > 0):
        return None, None
    return np.asarray(cell, dtype=np.float64), f"the topology {os.path.basename(topology)}"


def _stores_times(trajectory, frame) -> bool:
    """Whether the trajectory's format stores times (MDAnalysis warns when it does not, and counts 1 ps)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        trajectory[frame].time  # noqa: B018 - read for the warning of a format without times
    return not any(_NO_TIMES in str(w.message) for w in caught)


def read_waters(universe, select=None, start=None, stop=None, step=None, progress: bool | int = 200, dt=None,
                fallback_box=None) -> WaterTrajectory:
    """The waters of ``universe`` (``select``: an MDAnalysis selection to look in) at frames ``start:stop:step``,
    read into memory and checked (:class:`WaterTrajectory`).  ``step``: a positive integer; ``dt``: the
    interval between the trajectory's frames (ps) for a file that stores no times, or whose clock starts again;
    it must agree with the times a file stores (:func:`~.checks.dt_problem`); ``fallback_box``: a callable giving
    (box, where) for frames that store no box (:func:`stored_box`); ``progress``: show a tqdm bar (True, False,
    or beyond that many frames).  ValueError, saying what to do, for a ``step`` or ``dt`` out of range, a ``dt``
    that contradicts the stored times, frames unevenly spaced in time, molecules that are not water in the first
    frame, or positions wrapped into a box the file does not store."""
    mda = require("MDAnalysis", "analysis", "symprk observe")
    MemoryReader = require("MDAnalysis.coordinates.memory", "analysis", "symprk observe").MemoryReader
    tqdm = require("tqdm", "analysis", "symprk observe's progress bar").tqdm

    if dt is not None and not (np.isfinite(dt) and dt > 0):
        raise InputError(f"--dt must be a positive number of ps (the time between the trajectory's frames), got {dt}")
    if step is not None and (isinstance(step, bool) or int(step) != step or step < 1):
        raise InputError(f"--step must be a positive integer (read every step-th frame: 1 reads them all), got {step}")
    group = universe.select_atoms(select) if select else universe.atoms
    if select and group.n_atoms == 0:
        raise InputError(f"the selection {select!r} matches no atom")
    waters = find_waters(group)
    frames = range(*slice(start, stop, step).indices(universe.trajectory.n_frames))
    if len(frames) < 2:
        raise InputError(f"{len(frames)} frame(s) selected: the observables need at least 2")
    stores_times = _stores_times(universe.trajectory, frames[0])
    n = waters.atoms.n_atoms
    x = np.empty((len(frames), n, 3), dtype=np.float32)
    v = np.empty_like(x) if universe.trajectory.ts.has_velocities else None
    dims = np.full((len(frames), 6), np.nan)
    read_times = np.empty(len(frames))
    show = progress if isinstance(progress, bool) else len(frames) > progress
    sliced = universe.trajectory[frames.start:frames.stop:frames.step]
    for k, ts in enumerate(tqdm(sliced, total=len(frames), disable=not show, desc="reading frames",
                                unit="frame", file=sys.stderr)):
        x[k] = waters.atoms.positions
        if v is not None:
            if not ts.has_velocities:
                v = None
            else:
                v[k] = waters.atoms.velocities
        if ts.dimensions is not None and np.all(np.asarray(ts.dimensions[:3]) > 0):
            dims[k] = ts.dimensions
        if stores_times:
            read_times[k] = ts.time
    numbers = np.asarray(frames, dtype=np.float64)
    if dt is not None:
        dt_from = "--dt"
        if stores_times:
            problem, restarts = dt_problem(read_times, dt, frames)
            if problem is not None:
                raise InputError(problem)
            if restarts:
                dt_from += (f"; the file's clock starts again at frame{'s' if len(restarts) > 1 else ''} "
                            f"{', '.join(str(f) for f in restarts[:5])}{' ...' if len(restarts) > 5 else ''}")
        times = numbers * dt
    elif stores_times:
        times, dt_from = read_times, "the file's times"
    else:
        times, dt_from = numbers * 1.0, "no times in the file: taken 1 ps apart; give the interval with --dt PS"
    interval, irregular = time_steps(times)
    if len(irregular):
        first, stop = longest_piece(frames, irregular)
        restart = dt is None and bool(np.any(np.diff(times)[irregular] <= 0))
        raise InputError(f"{describe_steps(times, irregular, frames)}: a time correlation (MSD, reorientation) "
                         f"over them would join what is not joined. Analyse one evenly spaced piece with "
                         f"--start/--stop (the longest: --start {first} --stop {stop})"
                         + (", or, if the frames do follow each other at one interval (a file whose clock starts "
                            "again), give it with --dt PS" if restart else ""))
    box_from = None
    missing = np.isnan(dims[:, 0])
    if missing.any():
        cell, where = (dims[0], "the first frame") if not missing[0] else (None, None)
        if cell is None and missing.all() and fallback_box is not None:
            cell, where = fallback_box()
        if cell is not None:
            dims[missing] = cell
            box_from = f"{where} (for {int(missing.sum())} frames that store none)"
    box = None if np.isnan(dims[:, 0]).any() else dims
    if box is not None and np.any(np.abs(box[:, 3:] - 90.0) > 1e-3):
        raise InputError(f"the box is triclinic (angles {np.round(box[0, 3:], 3).tolist()}): these analyses need an "
                         f"orthorhombic box")
    residues = [f"residue {r.resname} {r.resid}" for r in waters.atoms[waters.molecules[:, 0]].residues]
    problem = None
    if box is None:  # first: a split molecule is not water either, but the reason is the missing box
        problem = wrapped_problem(x, waters.masses, waters.molecules, times, frames)
        if problem is not None:
            problem += ("; give a trajectory that stores its box, or a topology that holds it (a PDB with "
                        "CRYST1, a GRO), or unwrapped positions")
    if problem is None:
        problem = geometry_problem(x[0], waters.molecules, None if box is None else box[0, :3], residues)
    if problem is not None:
        raise InputError(problem)
    memory = mda.Merge(waters.atoms)
    memory.load_new(x, format=MemoryReader, velocities=v, dimensions=None if box is None else box.astype(np.float32),
                    dt=interval)
    return WaterTrajectory(memory, v is not None, interval, dt_from, box_from)
