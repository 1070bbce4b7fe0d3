"""The thermostat's random numbers as each backend draws them, for known-answer checks.

Every thermostat event draws a standard normal r1 and a chi-squared variate chi2 of N_f - 1 degrees of freedom
(:mod:`openmm_symprk.physics.velocity_rescaling`); a bias in either biases the temperature the thermostat samples
(the mean of K' is c K + (1 - c) K_target (E[r1^2] + E[chi2]) / N_f).  :func:`sample_thermostat_noise` draws ``count``
events' noise on a platform, the way that backend's events draw it:

* native: the plugin's ``sampleThermostatNoise``, i.e. the kernel's own draw (Reference/CPU: the host generator,
  r1 from a normal and chi2 from a gamma distribution; OpenCL/CUDA: OpenMM's device normals, r1 the first of the
  event's block and chi2 the sum of squares of the next N_f - 1, summed by the event's own device function);
* custom: a CustomIntegrator program looping over the event's noise computations
  (:func:`.thermostat_program.emit_noise`, the lines every event runs, and its per-DOF mask) and summing powers of
  the draws in the program, so that nothing per draw crosses to Python.

and returns their moments (:class:`NoiseSample`): the mean and variance of each, with standard errors, the
correlation of r1 with chi2 within an event and of chi2 between successive events (both about N(0, 1/n) for
independent draws).  Each call starts a new Context: a new stream from ``seed``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import openmm as mm

from ..stats.moments import Moments, correlation, power_sums
from . import thermostat_program as tp
from ..support.errors import InputError

__all__ = ["NoiseSample", "sample_thermostat_noise"]

#: draws read back from the native kernel at a time (two float64 each)
CHUNK = 1 << 20


@dataclass(frozen=True)
class NoiseSample:
    """The moments of ``n`` events' noise for ``dof`` thermostatted degrees of freedom: ``r1`` (expected mean 0,
    variance 1), ``chi2`` (mean dof - 1, variance 2 (dof - 1)), and the correlations ``r1_chi2`` (within an event)
    and ``chi2_lag1`` (successive events), each about N(0, 1/n) for independent draws."""

    backend: str
    platform: str
    dof: int
    r1: Moments
    chi2: Moments
    r1_chi2: float
    chi2_lag1: float

    @property
    def n(self) -> int:
        return self.r1.n


def _system(n_particles: int) -> mm.System:
    system = mm.System()
    for _ in range(n_particles):
        system.addParticle(1.0)
    return system


def _context(system, integrator, platform: str, properties):
    return mm.Context(system, integrator, mm.Platform.getPlatformByName(platform), dict(properties or {}))


def _native(dof: int, count: int, platform: str, seed: int, properties) -> tuple:
    from .. import plugin

    swig = plugin.swig_module()
    if swig is None:
        raise plugin.NativeUnavailableError(f"the native backend is unavailable: {plugin.unavailable_reason()}")
    # velocity Verlet between the ends placement's two half events (thermostat, kick, drift, kick, thermostat)
    integrator = swig.SymPRKIntegrator(0.001, [2, 0, 1, 0, 2], [0.5, 0.5, 1.0, 0.5, 0.5], [-1] * 5, [4, 2, 0, 0, 8])
    integrator.setThermostat(300.0, 0.1, 1, int(dof), False)
    integrator.setRandomNumberSeed(int(seed))
    context = _context(_system(max(2, math.ceil(dof / 3))), integrator, platform, properties)
    k = dof - 1
    r_sums, c_sums, cross, lag, previous = np.zeros(4), np.zeros(4), 0.0, 0.0, None
    left = count
    while left:
        a = np.asarray(integrator.sampleThermostatNoise(min(left, CHUNK)), dtype=np.float64).reshape(-1, 2)
        left -= len(a)
        r, y = a[:, 0], a[:, 1] - k
        r_sums += power_sums(r)
        c_sums += power_sums(y)
        cross += float(np.dot(r, y))
        lag += float(np.dot(y[1:], y[:-1])) + (previous * y[0] if previous is not None else 0.0)
        previous = y[-1]
    del context
    return r_sums, c_sums, cross, lag


def _custom(dof: int, count: int, platform: str, seed: int, properties) -> tuple:
    """The event's noise lines in a loop; the sums of powers of r1 and y = chi2 - (dof - 1), of r1 y, and of y times
    the previous event's y, accumulated in the program."""
    names = ("i", "n", "y", "yprev", *(f"r{p}" for p in range(1, 5)), *(f"c{p}" for p in range(1, 5)), "cross", "lag")
    v = {name: f"symprk_noise_{name}" for name in names}
    ig = mm.CustomIntegrator(0.001)
    for name in (*v.values(), tp.R1_VAR, tp.CHI2_VAR):
        ig.addGlobalVariable(name, 0.0)
    ig.addPerDofVariable(tp.MASK_VAR, 0.0)
    ig.setGlobalVariableByName(v["n"], float(count))
    ig.setRandomNumberSeed(int(seed))
    ig.beginWhileBlock(f"{v['i']} < {v['n']}")
    tp.emit_noise(ig)
    ig.addComputeGlobal(v["y"], f"{tp.CHI2_VAR} - {dof - 1}")
    for p in range(1, 5):
        ig.addComputeGlobal(v[f"r{p}"], f"{v[f'r{p}']} + {tp.R1_VAR}^{p}")
        ig.addComputeGlobal(v[f"c{p}"], f"{v[f'c{p}']} + {v['y']}^{p}")
    ig.addComputeGlobal(v["cross"], f"{v['cross']} + {tp.R1_VAR}*{v['y']}")
    ig.addComputeGlobal(v["lag"], f"{v['lag']} + {v['y']}*{v['yprev']}")  # (0 for the first: yprev starts at 0)
    ig.addComputeGlobal(v["yprev"], v["y"])
    ig.addComputeGlobal(v["i"], f"{v['i']} + 1")
    ig.endBlock()
    system = _system(max(2, math.ceil((dof - 1) / 3)))
    context = _context(system, ig, platform, properties)
    ig.setPerDofVariableByName(tp.MASK_VAR, tp.mask_values([1.0] * system.getNumParticles(), dof))
    ig.step(1)
    get = ig.getGlobalVariableByName
    if int(get(v["i"])) != count:
        raise RuntimeError(f"the noise program drew {int(get(v['i']))} events of {count}")
    out = (np.array([get(v[f"r{p}"]) for p in range(1, 5)]), np.array([get(v[f"c{p}"]) for p in range(1, 5)]),
           get(v["cross"]), get(v["lag"]))
    del context
    return out


def sample_thermostat_noise(backend: str, dof: int, count: int, platform: str = "Reference", seed: int = 1,
                            properties: dict | None = None) -> NoiseSample:
    """The moments of ``count`` thermostat events' noise for ``dof`` degrees of freedom, drawn as ``backend``
    ("native" or "custom") draws it on ``platform`` (with its ``properties``, e.g. {"Precision": "double"}; the custom
    program sums the draws in its global variables, which a single-precision platform holds as floats), from
    ``seed`` (> 0)."""
    if backend not in ("native", "custom"):
        raise InputError(f"backend must be 'native' or 'custom', got {backend!r}")
    dof, count = int(dof), int(count)
    if dof < 2:
        raise InputError(f"dof must be at least 2 (chi2 has dof - 1 degrees of freedom), got {dof}")
    if count < 3:
        raise InputError(f"count must be at least 3 events, got {count}")
    if not (isinstance(seed, (int, np.integer)) and 0 < seed < 2 ** 31):
        raise InputError(f"seed must be an integer from 1 to 2**31 - 1 (0 would draw a fresh one), got {seed!r}")
    draw = _native if backend == "native" else _custom
    r_sums, c_sums, cross, lag = draw(dof, count, platform, seed, properties)
    k = dof - 1
    r1 = Moments.from_power_sums(count, r_sums)
    chi2 = Moments.from_power_sums(count, c_sums, shift=k)  # the sums are of y = chi2 - k
    # the correlations' sums are of y; the n - 1 successive pairs have the moments of the whole series to O(1/n)
    return NoiseSample(backend, platform, dof, r1, chi2, correlation(count, cross, r1, chi2, shift_y=k),
                       correlation(count - 1, lag, chi2, chi2, shift_x=k, shift_y=k))
