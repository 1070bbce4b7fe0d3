"""``symprk observe TOPOLOGY TRAJECTORY``: the water observables of any trajectory MDAnalysis reads, with errors.

The waters (:func:`~openmm_symprk.analysis.universe.find_waters`) are read once (a progress bar on long
trajectories) into an in-memory Universe, on which the analyses of :mod:`openmm_symprk.analysis.universe` run:
self-diffusion of the centres of mass (and its Yeh-Hummer value with ``--viscosity`` and ``--temperature``),
reorientation times tau_1, tau_2 of the dipole, H-H and O-H vectors, and the O-O g(r) first peak from positions;
the angular-velocity autocorrelation and the translational and rotational temperatures need velocities too
(TRR, NetCDF, H5MD; DCD and XTC store none).  An observable that cannot be computed from the trajectory (too
short, too coarse, no velocities) is printed as missing with the reason.  ``--json FILE`` writes them all.

Refused, in one line, before anything is computed: frames unevenly spaced in time (files of one run with a
stretch not written between them: analyse one piece with --start/--stop), a --dt that contradicts the times the
file stores, a --step that is not a positive integer, molecules that are not water in the first frame (a
topology listing the atoms in another order than the trajectory), positions wrapped into a box the file does
not store, a --json path that cannot be written or that names an input file, and files MDAnalysis cannot read.
Frames without a box take the first frame's, or the topology's (a multi-model PDB's one CRYST1); molecules
split across the box (atoms wrapped one by one) are made whole.  A format without times (PDB, GRO ...) is read
as frames 1 ps apart unless --dt gives the interval; --dt also joins files whose clock starts again.
"""
from __future__ import annotations

import argparse
import json
import os
import stat

import numpy as np

from ..support import InputError, require

__all__ = ["OBSERVED", "observe", "build_parser", "run"]

#: (key, description, unit) of what ``symprk observe`` reports, in its order.  It reads like
#: :data:`openmm_symprk.studies.fidelity.observables.OBSERVABLES` on purpose but is not that table: that one's keys are the keys
#: of the fidelity study's stored runs (and hold PE and drift, which a trajectory alone cannot give), these are the
#: keys of ``--json`` (with D_inf and O-H, which the study does not report).
OBSERVED = [
    ("D", "self-diffusion D_PBC (centres of mass)", "1e-5 cm2/s"),
    ("D_inf", "D + Yeh-Hummer correction", "1e-5 cm2/s"),
    ("tau1_dipole", "tau1 dipole", "ps"), ("tau2_dipole", "tau2 dipole", "ps"),
    ("tau1_HH", "tau1 H-H", "ps"), ("tau2_HH", "tau2 H-H", "ps"),
    ("tau1_OH", "tau1 O-H", "ps"), ("tau2_OH", "tau2 O-H", "ps"),
    ("w_zero", "omega ACF first zero", "fs"), ("w_min", "omega ACF first minimum", ""),
    ("w_int", "omega ACF integral", "fs"),
    ("T_trans", "T_trans", "K"), ("T_rot", "T_rot", "K"), ("dT", "T_rot - T_trans", "K"),
    ("g_r", "g_OO first peak position", "nm"), ("g_h", "g_OO first peak height", ""),
]
#: The observables that need velocities.
NEEDS_VELOCITIES = ("w_zero", "w_min", "w_int", "T_trans", "T_rot", "dT")
#: The longest interval between frames (ps) from which the omega ACF is reported.
OMEGA_MAX_INTERVAL_PS = 0.02
#: Trajectories with more frames than this show a progress bar while they are read.
PROGRESS_FRAMES = 200


def _pair(value, se, scale=1.0):
    """[value, se] scaled, or None for a missing value; a missing error is None (JSON null, never NaN)."""
    if value is None or not np.isfinite(value):
        return None
    return [float(value) * scale, float(se) * scale if se is not None and np.isfinite(se) else None]


def observe(universe, *, window_ps=None, viscosity_mpas=None, temperature_k=None, omega_lag_ps: float = 0.5,
            has_velocities: bool = True) -> tuple:
    """({key: [value, se] or None}, {key: why it is missing}) of the waters of ``universe`` (every frame; see
    :data:`OBSERVED`), each analysis of :mod:`openmm_symprk.analysis.universe` run with its defaults."""
    from .universe import AngularVelocityCorrelation, KineticTemperatures, RadialDistribution, Reorientation
    from .universe import SelfDiffusion
    from .universe.base import ANGSTROM_IN_NM

    obs, notes = {key: None for key, _, _ in OBSERVED}, {}

    def attempt(keys, fn):
        try:
            fn()
        except (ValueError, np.linalg.LinAlgError) as exc:
            for key in keys:
                notes.setdefault(key, str(exc))

    def diffusion():
        d = SelfDiffusion(universe, window_ps, viscosity_mpas=viscosity_mpas, temperature_k=temperature_k).run()
        obs["D"] = _pair(d.results.D, d.results.se)
        if d.results.se_note:
            notes["D"] = d.results.se_note
        if viscosity_mpas is None:
            notes["D_inf"] = "give --viscosity (mPa s, the model's) and --temperature (K) for the Yeh-Hummer value"
        else:
            obs["D_inf"] = _pair(d.results.D_infinite, d.results.se)
            if d.results.se_note:
                notes["D_inf"] = d.results.se_note

    def reorientation():
        r = Reorientation(universe).run()
        for name in ("dipole", "HH", "OH"):
            for order in (1, 2):
                key = f"tau{order}_{name}"
                tau = r.results.tau[name][f"tau{order}"]
                obs[key] = None if tau is None else _pair(tau.tau, tau.se)
                if tau is None:
                    notes[key] = r.results.notes[name][f"tau{order}"]

    def omega():
        dt = float(universe.trajectory.dt)
        if dt > OMEGA_MAX_INTERVAL_PS:
            raise InputError(f"frames every {dt:g} ps cannot resolve the omega ACF (water's librations last ~0.1 "
                             f"ps): store frames every {1000 * OMEGA_MAX_INTERVAL_PS:g} fs or less")
        lag = max(2, int(round(omega_lag_ps / dt)))
        a = AngularVelocityCorrelation(universe, max_lag=min(lag, universe.trajectory.n_frames - 1)).run()
        s = a.results.summary
        obs["w_zero"] = _pair(s.t_zero, s.t_zero_se, 1000.0)
        obs["w_min"] = _pair(s.c_min, s.c_min_se)
        obs["w_int"] = _pair(s.integral, s.integral_se, 1000.0)
        if obs["w_zero"] is None:
            notes["w_zero"] = f"no zero crossing within {s.t_max:g} ps (frames every {dt:g} ps)"
        if obs["w_min"] is None:
            notes["w_min"] = f"no minimum within {s.t_max:g} ps (frames every {dt:g} ps)"

    def temperatures():
        k = KineticTemperatures(universe.atoms, by="residues").run()
        obs["T_trans"] = _pair(k.results.mean_translational, k.results.se_translational)
        obs["T_rot"] = _pair(k.results.mean_rotational, k.results.se_rotational)
        obs["dT"] = _pair(k.results.mean_difference, k.results.se_difference)

    def structure():
        g = RadialDistribution(universe).run()
        if g.results.peak is None:
            raise InputError(g.results.note)
        obs["g_r"] = _pair(g.results.peak.r, g.results.peak.r_se, ANGSTROM_IN_NM)  # the table's nm
        obs["g_h"] = _pair(g.results.peak.height, g.results.peak.height_se)

    attempt(("D", "D_inf"), diffusion)
    attempt([k for k, _, _ in OBSERVED if k.startswith("tau")], reorientation)
    if has_velocities:
        attempt(("w_zero", "w_min", "w_int"), omega)
        attempt(("T_trans", "T_rot", "dT"), temperatures)
    else:
        for key in NEEDS_VELOCITIES:
            notes[key] = "needs velocities: the trajectory has none"
    attempt(("g_r", "g_h"), structure)
    return obs, notes


def format_table(obs: dict, notes: dict) -> str:
    """The observables as a text table, the missing ones (and missing errors) with their reasons below it."""
    lines = [f"{'observable':40s} {'value':>22s}  unit"]
    for key, what, unit in OBSERVED:
        pair = obs.get(key)
        text = "-" if pair is None else f"{pair[0]:.4g} ± " + ("?" if pair[1] is None else f"{pair[1]:.2g}")
        lines.append(f"{what:40s} {text:>22s}  {unit}")
    missing = [key for key, _, _ in OBSERVED if (obs.get(key) is None or obs[key][1] is None) and key in notes]
    if missing:
        lines.append("")
        labels = dict((key, what) for key, what, _ in OBSERVED)
        lines += [f"{labels[key]}: {notes[key]}" for key in missing]
    return "\n".join(lines)


def build_parser(prog: str = "symprk observe"):
    ap = argparse.ArgumentParser(prog=prog, description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("topology", help="topology file MDAnalysis reads (PDB, PSF, PRMTOP, TPR, GRO ...)")
    ap.add_argument("trajectory", nargs="+", help="trajectory file(s) (DCD, XTC, TRR, NetCDF, H5MD ...)")
    ap.add_argument("--select", default=None, help="MDAnalysis selection to look for waters in (default: all)")
    ap.add_argument("--start", type=int, default=None)
    ap.add_argument("--stop", type=int, default=None)
    ap.add_argument("--step", type=int, default=None, help="read every STEP-th frame (a positive integer)")
    ap.add_argument("--dt", type=float, default=None, metavar="PS",
                    help="time between the trajectory's frames, ps, for formats that store no times (PDB, GRO, XYZ: "
                         "read as 1 ps apart otherwise) or files whose clock starts again; refused where it "
                         "contradicts the times a file stores")
    ap.add_argument("--window", type=float, nargs=2, metavar=("T_MIN", "T_MAX"), default=None,
                    help="diffusion fit window, ps (default: T/10 to T/2 of the analysed time T); D's error comes "
                         "from 5 blocks of the run and needs T_MAX <= T/10")
    ap.add_argument("--viscosity", type=float, default=None, help="the model's shear viscosity, mPa s (Yeh-Hummer)")
    ap.add_argument("--temperature", type=float, default=None, help="temperature, K (Yeh-Hummer)")
    ap.add_argument("--omega-lag", type=float, default=0.5, help="longest lag of the omega ACF, ps (default 0.5)")
    ap.add_argument("--json", default=None, metavar="FILE", help="write the observables to FILE as JSON")
    ap.add_argument("--progress", choices=("auto", "always", "never"), default="auto",
                    help=f"progress bar while reading (auto: more than {PROGRESS_FRAMES} frames)")
    return ap


def _same_file(a: str, b: str) -> bool:
    """Whether the paths ``a`` and ``b`` name one existing file (through symlinks and hard links too)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (or cannot be looked at): not the same file
        return False


def _refuse_json_on_inputs(path: str, topology: str, trajectories) -> None:
    """ValueError when ``--json path`` names a file ``symprk observe`` reads (the topology or a trajectory): writing
    the observables there would replace the input."""
    for what, given in [("topology", topology)] + [("trajectory", t) for t in trajectories]:
        if _same_file(path, given):
            same = "" if os.path.abspath(path) == os.path.abspath(given) else f" ({given})"
            stem = os.path.splitext(path)[0]
            raise InputError(f"--json {path} is the {what}{same} that symprk observe reads: writing the "
                             f"observables there would replace it; give another file name (e.g. "
                             f"{stem}.observe.json)")


def _json_target(path: str) -> tuple:
    """(the file to write, whether to write into it as a stream) for ``--json path``, checked before the analysis
    so that a bad path costs none; ValueError naming the path and why it cannot be written.  A regular file (or
    a new one) is replaced whole (:func:`_write_json`), through a symlink to the file it names; anything else
    that exists (a device such as /dev/stdout or /dev/null, a FIFO) is written into, never replaced."""
    if os.path.isdir(path):
        raise InputError(f"--json {path} is a folder: give a file name (e.g. {os.path.join(path, 'observe.json')})")
    if os.path.exists(path) and not stat.S_ISREG(os.stat(path).st_mode):
        if not os.access(path, os.W_OK):
            raise InputError(f"--json {path} cannot be written (permission denied)")
        return path, True
    target = os.path.realpath(path)
    folder = os.path.dirname(target)
    if not os.path.isdir(folder):
        raise InputError(f"--json {path}: the folder {folder} does not exist")
    probe = os.path.join(folder, f".{os.path.basename(target)}.{os.getpid()}.probe")
    try:
        with open(probe, "x"):
            pass
        os.remove(probe)
    except OSError as exc:
        raise InputError(f"--json {path}: cannot write in {folder} ({exc.strerror or exc})") from None
    return target, False


def _write_json(target: str, stream: bool, data: dict) -> None:
    """``data`` as strict JSON (no NaN: missing numbers are null) in ``target`` (from :func:`_json_target`): a
    regular file is written whole or not at all (a file beside it, then os.replace), a stream is written into."""
    text = json.dumps(data, indent=2, allow_nan=False) + "\n"
    tmp = os.path.join(os.path.dirname(target), f".{os.path.basename(target)}.{os.getpid()}.tmp")
    try:
        if stream:
            with open(target, "w", encoding="utf-8") as fh:
                fh.write(text)
            return
        with open(tmp, "x") as fh:
            fh.write(text)
        os.replace(tmp, target)
    except OSError as exc:
        if not stream and os.path.exists(tmp):
            os.remove(tmp)
        raise InputError(f"cannot write --json {target}: {exc.strerror or exc}") from None


def run(args):
    """The command (:func:`openmm_symprk.cli.main` runs it): ValueError and OSError are the user's mistakes."""
    if (args.viscosity is None) != (args.temperature is None):
        raise InputError("the Yeh-Hummer correction needs both --viscosity and --temperature")
    if args.dt is not None and not (np.isfinite(args.dt) and args.dt > 0):
        raise InputError(f"--dt must be a positive number of ps (the time between the trajectory's frames), "
                         f"got {args.dt:g}")
    if args.json:
        _refuse_json_on_inputs(args.json, args.topology, args.trajectory)
    target, stream = _json_target(args.json) if args.json else (None, False)
    require("MDAnalysis", "analysis", "symprk observe")
    from .universe.reading import open_universe, read_waters, stored_box

    u = open_universe(args.topology, args.trajectory)
    progress = {"auto": PROGRESS_FRAMES, "always": True, "never": False}[args.progress]
    read = read_waters(u, args.select, args.start, args.stop, args.step, progress, dt=args.dt,
                       fallback_box=lambda: stored_box(args.topology, args.trajectory))
    memory, has_v = read.universe, read.has_velocities
    obs, notes = observe(memory, window_ps=args.window, viscosity_mpas=args.viscosity,
                         temperature_k=args.temperature, omega_lag_ps=args.omega_lag, has_velocities=has_v)
    n_waters = memory.residues.n_residues
    dt = read.dt
    when = "" if read.dt_from == "the file's times" else f" ({read.dt_from})"
    print(f"{n_waters} waters, {memory.trajectory.n_frames} frames every {dt:g} ps{when}"
          f"{'' if has_v else ' (positions only: no velocities)'}; errors are standard errors "
          f"(blocks of frames, or jackknife over molecules)")
    if read.box_from:
        print(f"box from {read.box_from}")
    print(format_table(obs, notes))
    if not has_v:
        print("\nThe omega ACF, T_trans and T_rot need velocities: write the trajectory with them (TRR, NetCDF, "
              "H5MD) to get them.")
    if target:
        units = {key: unit for key, _, unit in OBSERVED}
        data = {"topology": args.topology, "trajectory": args.trajectory, "n_waters": n_waters,
                "n_frames": memory.trajectory.n_frames, "dt_ps": dt, "dt_from": read.dt_from,
                "box_from": read.box_from, "velocities": has_v,
                "observables": {key: None if obs[key] is None else
                                {"value": obs[key][0], "se": obs[key][1], "unit": units[key]} for key in obs},
                "notes": notes}
        _write_json(target, stream, data)
        print(f"\nwrote {args.json}")
