"""``symprk nvt known``: the thermostat's known answers on this installation, per backend and platform.

1. The noise each event draws (:func:`openmm_symprk.integrators.noise.sample_thermostat_noise`): r1 ~ N(0, 1) and
   chi2 ~ chi^2(N_f - 1) for N_f - 1 = 20, 600, 3000, as z-scores of their means and variances against the exact
   values, and the relative standard error of E[chi2] the draws resolve.
2. The stationary state of N independent 3-d harmonic oscillators under Verlet with the thermostat at the ends or in
   the middle (h w = 0.5): k<q^2>/kT and the kinetic temperature at the thermostat point, in units of the target,
   against the exact values (ends: 1/(1 - h^2 w^2/4) and 1; middle: 1 and 1)
   (:mod:`openmm_symprk.integrators.known_answers`).

The test-suite asserts the same numbers (tests/integrators/test_thermostat_known_answers.py).
"""
from __future__ import annotations

import math

from ...integrators.known_answers import OSCILLATORS, exact_temperatures, noise_draws, stationary_temperatures
from ...integrators.noise import sample_thermostat_noise
from ..core.platforms import names

__all__ = ["run"]


def run(quick: bool = False, platforms=None, log=print) -> dict:
    """Print both tables and return them as {"noise": [...], "oscillators": [...]} (plain numbers)."""
    from ... import plugin

    platforms = [p for p in (platforms or ["Reference", "CPU", "OpenCL"]) if p in names()]
    native = set(plugin.platforms()) if plugin.available() else set()
    double = {"OpenCL": {"Precision": "double"}, "CUDA": {"Precision": "double"}}
    out = {"noise": [], "oscillators": []}
    log("The noise of a thermostat event: z-scores against the exact moments (|z| < 3 expected), and the relative "
        "standard error of E[chi2]")
    log(f"{'backend':8s} {'platform':10s} {'N_f-1':>6s} {'events':>8s} {'E[chi2]':>8s} {'Var':>6s} {'E[r1]':>6s} "
        f"{'Var':>6s} {'corr':>6s} {'lag1':>6s} {'resolves':>9s}")
    for backend in ("native", "custom"):
        for platform in platforms:
            if backend == "native" and platform not in native:
                continue
            for k in (20, 600, 3000):
                n = noise_draws(k, 0.002 if quick else 0.0005)
                if backend == "custom" and platform in ("OpenCL", "CUDA"):
                    n = min(n, 40_000)  # a CustomIntegrator loop pass per event on the device: ~0.1 ms
                s = sample_thermostat_noise(backend, k + 1, n, platform, seed=11 + k, properties=double.get(platform))
                row = dict(backend=backend, platform=platform, k=k, events=n, chi2_mean_z=s.chi2.mean_z(k),
                           chi2_var_z=s.chi2.variance_z(2 * k), r1_mean_z=s.r1.mean_z(0.0),
                           r1_var_z=s.r1.variance_z(1.0), corr_z=s.r1_chi2 * math.sqrt(n),
                           lag_z=s.chi2_lag1 * math.sqrt(n), resolution=s.chi2.mean_se / k)
                out["noise"].append(row)
                log(f"{backend:8s} {platform:10s} {k:6d} {n:8d} {row['chi2_mean_z']:+8.2f} {row['chi2_var_z']:+6.2f} "
                    f"{row['r1_mean_z']:+6.2f} {row['r1_var_z']:+6.2f} {row['corr_z']:+6.2f} {row['lag_z']:+6.2f} "
                    f"{100 * row['resolution']:8.3f}%")
    samples = 2000 if quick else 16_000
    case = OSCILLATORS
    log(f"\n{case['n']} harmonic oscillators, verlet, h w = {case['h_omega']}, tau = {case['collision_time']} ps, "
        f"{samples} steps: temperatures in units of the target (mean ± standard error; exact in brackets)")
    log(f"{'backend':8s} {'platform':10s} {'position':8s} {'k<q^2>/kT':>22s} {'T at the thermostat':>22s}")
    for backend, platform in (("custom", "Reference"), ("native", "Reference"), ("native", "OpenCL")):
        if platform not in platforms or (backend == "native" and platform not in native):
            continue
        for position in ("ends", "middle"):
            st = stationary_temperatures(backend, platform, position, samples, properties=double.get(platform))
            exact = exact_temperatures(position)
            out["oscillators"].append(dict(backend=backend, platform=platform, position=position,
                                           q=st.configurational.mean, q_se=st.configurational.se, q_exact=exact[0],
                                           kinetic=st.kinetic.mean, kinetic_se=st.kinetic.se))
            log(f"{backend:8s} {platform:10s} {position:8s} "
                f"{st.configurational.mean:.5f} ± {st.configurational.se:.5f} [{exact[0]:.4f}] "
                f"{st.kinetic.mean:.5f} ± {st.kinetic.se:.5f} [{exact[1]:.4f}]")
    return out
