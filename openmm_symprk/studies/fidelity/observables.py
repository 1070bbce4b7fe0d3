"""Every observable of one fidelity run from what the run stored (pure numpy): each a (value, standard error)
of this replica, or None with the reason in ``notes``.  Units: nm, ps, K, kJ/mol; D in 1e-5 cm^2/s.

The list :data:`OBSERVABLES` (key, what, unit) is the order of the study's tables.  Per replica:

* ``D`` -- :func:`openmm_symprk.analysis.diffusion.self_diffusion` of the molecules' centres of mass over ``msd_window_ps``, the
  common centre's motion taken out (molecules' error); uncorrected (the Yeh-Hummer value is added in the report);
* ``tau1_dip`` ... ``tau2_hh`` -- :func:`openmm_symprk.analysis.reorientation.reorientation_time` of the dipole and H-H unit vectors,
  C_l fitted over ``tau_fit`` = (c_cut, c_fit) (jackknife over molecules);
* ``w_zero``, ``w_min``, ``w_int`` -- the angular-velocity autocorrelation (space frame, from the frames of the
  short window): first zero (fs), value at the first minimum, integral to ``omega_max_lag_ps`` (fs);
* ``pe`` (per molecule), ``dT`` (T_rot - T_trans), ``T_trans`` -- time averages with correlation-corrected
  errors (:func:`openmm_symprk.stats.series_stats`);
* ``g_r``, ``g_h`` -- position and height of the O-O g(r) first peak beyond ``rdf_r_min_nm`` (5 blocks);
* ``drift`` -- slope of the (effective) energy in kT/ns per degree of freedom (6 N - 3 for rigid water), None
  for a thermostat without a heat-bath energy.
"""
from __future__ import annotations

import numpy as np

from ...analysis import angular, diffusion, reorientation, structure
from ...stats import drift, series_stats
from ..core.units import kt_per_ns_per_dof

__all__ = ["OBSERVABLES", "observables"]

#: (key, description, unit) in table order.
OBSERVABLES = [
    ("D", "self-diffusion D_PBC", "1e-5 cm2/s"),
    ("tau1_dip", "tau1 dipole", "ps"), ("tau2_dip", "tau2 dipole", "ps"),
    ("tau1_hh", "tau1 H-H", "ps"), ("tau2_hh", "tau2 H-H", "ps"),
    ("w_zero", "omega ACF first zero", "fs"), ("w_min", "omega ACF first minimum", ""),
    ("w_int", "omega ACF integral", "fs"),
    ("pe", "PE per molecule", "kJ/mol"), ("dT", "T_rot - T_trans", "K"), ("T_trans", "T_trans", "K"),
    ("g_r", "g_OO first peak position", "nm"), ("g_h", "g_OO first peak height", ""),
    ("drift", "(effective) energy drift", "kT/ns/dof"),
]


def _try(notes, key, fn):
    try:
        return fn()
    except (ValueError, np.linalg.LinAlgError) as exc:
        notes[key] = str(exc)
        return None


def observables(series: dict, cfg: dict, n_waters: int, box_nm, has_drift: bool) -> tuple:
    """({key: [value, se] or None}, {curve name: array}, {key: why it is missing}) from one run's ``series``:
    t (ps), T_trans, T_rot (K), pe, etot (kJ/mol; total plus heat bath), com, dip, hh (F, n, 3; frames every
    ``dt``), oxygen (frames every ``rdf_every``), omega (F_w, n, 3) rad/ps every ``dt_omega`` ps."""
    obs, curves, notes = {}, {}, {}
    t = series["t"]
    dt = float(t[1] - t[0])
    d = _try(notes, "D", lambda: diffusion.self_diffusion(series["com"], dt, cfg["msd_window_ps"]))
    obs["D"] = None if d is None else [d.D, d.se]
    if d is not None:
        curves["msd"] = d.msd
    c_cut, c_fit = cfg["tau_fit"]
    for vec in ("dip", "hh"):
        for order in (1, 2):
            res = _try(notes, f"tau{order}_{vec}",
                       lambda: reorientation.reorientation_time(series[vec], order, dt, c_cut=c_cut, c_fit=c_fit))
            obs[f"tau{order}_{vec}"] = None if res is None else [res[1].tau, res[1].se]
            if res is not None:
                curves[f"c{order}_{vec}"] = res[0]
    dtw = float(series["dt_omega"])
    lag = max(2, int(round(cfg["omega_max_lag_ps"] / dtw)))
    res = _try(notes, "w_zero", lambda: angular.omega_correlation(series["omega"], dtw,
                                                                    min(lag, len(series["omega"]) - 1)))
    if res is None:
        obs.update(w_zero=None, w_min=None, w_int=None)
    else:
        c, s = res
        curves["omega_acf"] = c
        obs["w_zero"] = None if not np.isfinite(s.t_zero) else [1000 * s.t_zero, 1000 * s.t_zero_se]
        obs["w_min"] = None if not np.isfinite(s.c_min) else [s.c_min, s.c_min_se]
        obs["w_int"] = [1000 * s.integral, 1000 * s.integral_se]
        if obs["w_zero"] is None:
            notes["w_zero"] = "no zero crossing within the window"
    for key, x in (("pe", series["pe"] / n_waters), ("dT", series["T_rot"] - series["T_trans"]),
                   ("T_trans", series["T_trans"])):
        s = series_stats(x, dt)
        obs[key] = [s.mean, s.se]
    box = np.full(3, float(box_nm)) if np.ndim(box_nm) == 0 else np.asarray(box_nm, dtype=np.float64)
    rdf = _try(notes, "g_r", lambda: structure.radial_distribution(series["oxygen"], box, 0.5 * box.min(),
                                                                    n_blocks=min(5, len(series["oxygen"]))))
    peak = None if rdf is None else _try(notes, "g_r", lambda: structure.first_peak(rdf, cfg["rdf_r_min_nm"]))
    obs["g_r"] = None if peak is None else [peak.r, peak.r_se]
    obs["g_h"] = None if peak is None else [peak.height, peak.height_se]
    if rdf is not None:
        curves["g_oo"] = rdf.g
    if has_drift:
        obs["drift"] = [kt_per_ns_per_dof(v, cfg["temperature"], 6 * n_waters - 3) for v in drift(t, series["etot"])]
    else:
        obs["drift"] = None
        notes["drift"] = "not applicable: the thermostat exposes no heat-bath energy"
    return obs, curves, notes
