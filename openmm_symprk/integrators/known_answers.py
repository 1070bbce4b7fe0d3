"""Known answers of the thermostat, for the test-suite and ``symprk nvt known`` alike.

The stationary state of N independent 3-d harmonic oscillators under Verlet with the thermostat at the ends or in the
middle of the step (:data:`OSCILLATORS`, h w = 0.5): k<q^2>/kT and the kinetic temperature at the thermostat point,
in units of the target (:func:`stationary_temperatures`), against their exact values (:func:`exact_temperatures`:
ends 1/(1 - h^2 w^2/4) and 1; middle 1 and 1).  The noise each event draws is :mod:`.noise`'s;
:func:`noise_draws` is how many events resolve its mean to a given precision.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..physics.temperature import R_KJ
from ..stats import SeriesStats, series_stats
from ..systems.scenes import harmonic_oscillators
from .symplectic import SymplecticIntegrator

__all__ = ["OSCILLATORS", "Stationary", "stationary_temperatures", "exact_temperatures", "noise_draws"]

#: the oscillators' case: count, temperature (K), step (ps), h w, collision time (ps; c = exp(-h/tau) = 0.018, so the
#: kinetic energy at the thermostat point is nearly fresh every step)
OSCILLATORS = dict(n=1000, temperature=300.0, step=0.002, h_omega=0.5, collision_time=0.0005)


def exact_temperatures(position: str, h_omega: float = OSCILLATORS["h_omega"]) -> tuple:
    """(k<q^2>/kT, kinetic temperature at the thermostat point / T) of Verlet with the thermostat at ``position``."""
    return (1 / (1 - h_omega ** 2 / 4) if position == "ends" else 1.0), 1.0


@dataclass(frozen=True)
class Stationary:
    backend: str
    platform: str
    position: str
    configurational: SeriesStats  # k<q^2> / ((3N - 3) kT)
    kinetic: SeriesStats  # 2 K at the thermostat point / ((3N - 3) kT)


def stationary_temperatures(backend: str, platform: str, position: str, samples: int, seed: int = 17,
                            properties: dict | None = None) -> Stationary:
    """The oscillators of :data:`OSCILLATORS` after 300 steps of Verlet with the thermostat at ``position``
    (``backend`` "native" or "custom", random seed ``seed``), sampled every step ``samples`` times on ``platform``
    (``properties``: the platform's, e.g. {"Precision": "double"})."""
    case = OSCILLATORS
    k = (case["h_omega"] / case["step"]) ** 2
    system, x, v = harmonic_oscillators(case["n"], k, case["temperature"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the oscillators' external field: expected here
        integrator = SymplecticIntegrator(case["step"] * unit.picoseconds, "verlet", system=system, backend=backend,
                                          temperature=case["temperature"], collision_time=case["collision_time"],
                                          random_seed=seed, thermostat_position=position)
    context = mm.Context(system, integrator, mm.Platform.getPlatformByName(platform), dict(properties or {}))
    context.setPositions(x)
    context.setVelocities(np.array(v, dtype=np.float64))
    integrator.step(300)
    dof_kT = (3 * case["n"] - 3) * R_KJ * case["temperature"]
    q, kin = np.empty(samples), np.empty(samples)
    for i in range(samples):
        integrator.step(1)
        pe = context.getState(getEnergy=True).getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole)
        q[i] = 2 * pe / dof_kT
        kin[i] = 2 * integrator.thermostat_kinetic_energy().value_in_unit(unit.kilojoule_per_mole) / dof_kT
    del context, integrator
    return Stationary(backend, platform, position, series_stats(q), series_stats(kin))


def noise_draws(k: int, resolution: float = 0.0005) -> int:
    """Events whose chi2 of ``k`` degrees of freedom resolves E[chi2] to ``resolution`` (one relative standard error)."""
    return math.ceil(2.0 / (k * resolution ** 2))
