"""``symprk observe TOPOLOGY TRAJECTORY``: the water observables of any trajectory MDAnalysis reads, with errors.

The waters (:func:`~openmm_symprk.analysis.universe.find_waters`) are read once (a progress bar on long
trajectories) into an in-memory Universe, on which the analyses of :mod:`openmm_symprk.analysis.universe` run:
self-diffusion of the centres of mass (and its Yeh-Hummer value with ``--viscosity`` and ``--temperature``),
reorientation times tau_1, tau_2 of the dipole, H-H and O-H vectors, and the O-O g(r) first peak from positions;
the angular-velocity autocorrelation and the translational and rotational temperatures need velocities too
(TRR, NetCDF, H5MD; DCD and XTC store none).  An observable that cannot be computed from the trajectory (too
short, too coarse, no velocities) is printed as missing with the reason.  ``--json FILE`` writes them all.
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from ..support import require

__all__ = ["OBSERVED", "observe", "build_parser", "main"]

#: (key, description, unit) of what ``symprk observe`` reports, in its order.  It reads like
#: :data:`openmm_symprk.analysis.observe.OBSERVABLES` on purpose but is not that table: that one's keys are the keys
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


def read_waters(universe, select=None, start=None, stop=None, step=None, progress=None):
    """An in-memory Universe of the waters of ``universe`` (``select``: an MDAnalysis selection to look in) at
    frames ``start:stop:step``, and whether it has velocities.  ``progress``: show a tqdm bar (default: when
    more than :data:`PROGRESS_FRAMES` frames are read)."""
    mda = require("MDAnalysis", "analysis", "symprk observe")
    MemoryReader = require("MDAnalysis.coordinates.memory", "analysis", "symprk observe").MemoryReader
    tqdm = require("tqdm", "analysis", "symprk observe's progress bar").tqdm
    from .universe import find_waters

    group = universe.select_atoms(select) if select else universe.atoms
    if select and group.n_atoms == 0:
        raise ValueError(f"the selection {select!r} matches no atom")
    waters = find_waters(group)
    frames = range(*slice(start, stop, step).indices(universe.trajectory.n_frames))
    if len(frames) < 2:
        raise ValueError(f"{len(frames)} frame(s) selected: the observables need at least 2")
    n = waters.atoms.n_atoms
    x = np.empty((len(frames), n, 3), dtype=np.float32)
    v = np.empty_like(x) if universe.trajectory.ts.has_velocities else None
    dims = np.zeros((len(frames), 6), dtype=np.float32)
    times = np.empty(len(frames))
    show = len(frames) > PROGRESS_FRAMES if progress is None else progress
    sliced = universe.trajectory[frames.start:frames.stop:frames.step]
    for k, ts in enumerate(tqdm(sliced, total=len(frames), disable=not show, desc="reading frames",
                                unit="frame", file=sys.stderr)):
        x[k] = waters.atoms.positions
        if v is not None:
            if not ts.has_velocities:
                v = None
            else:
                v[k] = waters.atoms.velocities
        if ts.dimensions is not None:
            dims[k] = ts.dimensions
        times[k] = ts.time
    memory = mda.Merge(waters.atoms)
    steps = np.diff(times)
    dt = float(np.median(steps)) if len(steps) else 1.0
    memory.load_new(x, format=MemoryReader, velocities=v, dimensions=None if not dims[:, :3].all() else dims,
                    dt=dt if dt > 0 else 1.0)
    return memory, v is not None


def _pair(value, se, scale=1.0):
    if value is None or not np.isfinite(value):
        return None
    return [float(value) * scale, float(se) * scale if se is not None and np.isfinite(se) else float("nan")]


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
        if viscosity_mpas is None:
            notes["D_inf"] = "give --viscosity (mPa s, the model's) and --temperature (K) for the Yeh-Hummer value"
        else:
            obs["D_inf"] = _pair(d.results.D_infinite, d.results.se)

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
            raise ValueError(f"frames every {dt:g} ps cannot resolve the omega ACF (water's librations last ~0.1 "
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
            raise ValueError(g.results.note)
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
    """The observables as a text table, the missing ones with their reasons below it."""
    lines = [f"{'observable':40s} {'value':>22s}  unit"]
    for key, what, unit in OBSERVED:
        pair = obs.get(key)
        text = "-" if pair is None else f"{pair[0]:.4g} ± {pair[1]:.2g}"
        lines.append(f"{what:40s} {text:>22s}  {unit}")
    missing = [key for key, _, _ in OBSERVED if obs.get(key) is None and key in notes]
    if missing:
        lines.append("")
        labels = dict((key, what) for key, what, _ in OBSERVED)
        lines += [f"{labels[key]}: {notes[key]}" for key in missing]
    return "\n".join(lines)


def build_parser():
    ap = argparse.ArgumentParser(prog="symprk observe", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("topology", help="topology file MDAnalysis reads (PDB, PSF, PRMTOP, TPR, GRO ...)")
    ap.add_argument("trajectory", nargs="+", help="trajectory file(s) (DCD, XTC, TRR, NetCDF, H5MD ...)")
    ap.add_argument("--select", default=None, help="MDAnalysis selection to look for waters in (default: all)")
    ap.add_argument("--start", type=int, default=None)
    ap.add_argument("--stop", type=int, default=None)
    ap.add_argument("--step", type=int, default=None)
    ap.add_argument("--window", type=float, nargs=2, metavar=("T_MIN", "T_MAX"), default=None,
                    help="diffusion fit window, ps (default: T/10 to T/2 of the analysed time T)")
    ap.add_argument("--viscosity", type=float, default=None, help="the model's shear viscosity, mPa s (Yeh-Hummer)")
    ap.add_argument("--temperature", type=float, default=None, help="temperature, K (Yeh-Hummer)")
    ap.add_argument("--omega-lag", type=float, default=0.5, help="longest lag of the omega ACF, ps (default 0.5)")
    ap.add_argument("--json", default=None, metavar="FILE", help="write the observables to FILE as JSON")
    ap.add_argument("--progress", choices=("auto", "always", "never"), default="auto",
                    help=f"progress bar while reading (auto: more than {PROGRESS_FRAMES} frames)")
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        if (args.viscosity is None) != (args.temperature is None):
            raise ValueError("the Yeh-Hummer correction needs both --viscosity and --temperature")
        mda = require("MDAnalysis", "analysis", "symprk observe")
        files = args.trajectory[0] if len(args.trajectory) == 1 else args.trajectory
        try:
            u = mda.Universe(args.topology, files)
        except (OSError, ValueError, TypeError) as exc:
            raise ValueError(f"MDAnalysis cannot read {args.topology} with {', '.join(args.trajectory)}: {exc}") \
                from None
        progress = {"auto": None, "always": True, "never": False}[args.progress]
        memory, has_v = read_waters(u, args.select, args.start, args.stop, args.step, progress)
        obs, notes = observe(memory, window_ps=args.window, viscosity_mpas=args.viscosity,
                             temperature_k=args.temperature, omega_lag_ps=args.omega_lag, has_velocities=has_v)
    except (ValueError, OSError) as exc:
        print(f"symprk observe: error: {exc}", file=sys.stderr)
        return 2
    n_waters = memory.residues.n_residues
    dt = float(memory.trajectory.dt)
    print(f"{n_waters} waters, {memory.trajectory.n_frames} frames every {dt:g} ps"
          f"{'' if has_v else ' (positions only: no velocities)'}; errors are standard errors "
          f"(molecules' scatter, jackknife over molecules, or blocks of frames)")
    print(format_table(obs, notes))
    if not has_v:
        print("\nThe omega ACF, T_trans and T_rot need velocities: write the trajectory with them (TRR, NetCDF, "
              "H5MD) to get them.")
    if args.json:
        units = {key: unit for key, _, unit in OBSERVED}
        data = {"topology": args.topology, "trajectory": args.trajectory, "n_waters": n_waters,
                "n_frames": memory.trajectory.n_frames, "dt_ps": dt, "velocities": has_v,
                "observables": {key: None if obs[key] is None else
                                {"value": obs[key][0], "se": obs[key][1], "unit": units[key]} for key in obs},
                "notes": notes}
        with open(args.json, "w") as fh:
            json.dump(data, fh, indent=2, allow_nan=True)
            fh.write("\n")
        print(f"\nwrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
