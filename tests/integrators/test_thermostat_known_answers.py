"""Known answers for the thermostat's randomness, both backends and every platform here (issue 36).

1. The noise every event draws -- a standard normal r1 and a chi-squared variate chi2 of N_f - 1 degrees of
   freedom -- drawn as each backend's events draw it (:func:`openmm_symprk.integrators.noise.sample_thermostat_noise`)
   for N_f - 1 = 20, 600 and 3000: E[chi2] = N_f - 1 resolved to 0.05 % (one standard error) where the platform
   draws fast enough, Var[chi2] = 2 (N_f - 1), E[r1] = 0, Var[r1] = 1, and no correlation of r1 with chi2 or of chi2
   between successive events (a reused or overlapping block of random numbers would show there).
2. The stationary state of 1000 independent 3-d harmonic oscillators (Verlet, h w = 0.5, both placements; ``symprk nvt
   known`` prints both tables; the case is :mod:`openmm_symprk.integrators.known_answers`): the
   configurational temperature k<q^2>/kT and the kinetic one at the thermostat point against their exact values
   (ends: 1/(1 - h^2 w^2/4) and 1; middle: 1 and 1), and native (Reference and OpenCL) equal to custom within
   3 combined standard errors (0.1 % for the kinetic temperature, 0.15 % for the configurational one).

Fixed seeds; every bound is 3 standard errors (4 for the secondary moments: twelve of them per case) and each test
also asserts the resolution it claims."""
import math

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from helpers import COMMON, native_skip_reason
from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.integrators.noise import sample_thermostat_noise
from openmm_symprk.integrators.known_answers import (OSCILLATORS, exact_temperatures, noise_draws,
                                                   stationary_temperatures)

pytestmark = pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")

OPENCL = COMMON in [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]
NATIVE = native_skip_reason() is None
DOUBLE = {"Precision": "double"}


def _case(backend, platform):
    marks = []
    if backend == "native":
        marks.append(pytest.mark.skipif(not NATIVE, reason=str(native_skip_reason())))
        if platform == COMMON:
            marks.append(pytest.mark.skipif(not NATIVE or COMMON not in plugin.platforms(),
                                            reason=f"no native {COMMON} kernel here"))
    if platform == COMMON:
        marks.append(pytest.mark.skipif(not OPENCL, reason=f"OpenMM has no {COMMON} platform here"))
    return pytest.param(backend, platform, marks=marks, id=f"{backend}-{platform}")


def _draws(backend, platform, k):
    """Events to draw for chi2 of k degrees of freedom: enough for a relative standard error of 0.05 % of E[chi2]
    (2 / (k 0.0005^2)), but where each event is a CustomIntegrator loop pass on OpenCL (about 0.5 ms here) the
    smallest k is held to 40000 events (0.16 %: a wrong mask, one variate too many or too few, is 5 %)."""
    n = noise_draws(k, 0.0005)
    if backend == "custom" and platform == COMMON:
        n = min(n, 40_000)
    return n


@pytest.mark.parametrize("backend, platform", [_case("native", "Reference"), _case("native", "CPU"),
                                               _case("native", COMMON), _case("custom", "Reference"),
                                               _case("custom", "CPU"), _case("custom", COMMON)])
@pytest.mark.parametrize("k", [20, 600, 3000])
def test_event_noise_has_the_known_moments(backend, platform, k):
    n = _draws(backend, platform, k)
    s = sample_thermostat_noise(backend, k + 1, n, platform, seed=11 + k,
                                properties=DOUBLE if platform == COMMON else None)
    assert s.n == n and s.dof == k + 1
    resolution = s.chi2.mean_se / k
    assert resolution < (0.0017 if n == 40_000 else 0.00055), resolution  # what the draws resolve
    assert abs(s.chi2.mean_z(k)) < 3, (s.chi2.mean / k, resolution)
    assert abs(s.chi2.variance_z(2 * k)) < 4, (s.chi2.variance / (2 * k), s.chi2.variance_se / (2 * k))
    assert abs(s.r1.mean_z(0.0)) < 4, s.r1
    assert abs(s.r1.variance_z(1.0)) < 4, s.r1
    for name, r in (("r1 with chi2", s.r1_chi2), ("chi2 with the previous event's", s.chi2_lag1)):
        assert abs(r) * math.sqrt(n) < 4, (name, r)


def test_noise_sampler_refuses_bad_input():
    with pytest.raises(ValueError, match="backend must be 'native' or 'custom', got 'gpu'"):
        sample_thermostat_noise("gpu", 21, 100)
    with pytest.raises(ValueError, match="dof must be at least 2"):
        sample_thermostat_noise("custom", 1, 100)
    with pytest.raises(ValueError, match="count must be at least 3 events, got 2"):
        sample_thermostat_noise("custom", 21, 2)
    with pytest.raises(ValueError, match="seed must be an integer from 1"):
        sample_thermostat_noise("custom", 21, 100, seed=0)


# -- the stationary state of harmonic oscillators ---------------------------------------------------------------------
#: samples per run; with c = exp(-h/tau) = 0.018 the kinetic energy at the thermostat point is nearly fresh every step
#: (statistical inefficiency ~1: 0.02 % standard error), the configurational temperature ~2.5 (0.03 %)
SAMPLES = 16_000


def _stationary(backend, platform, position):
    st = stationary_temperatures(backend, platform, position, SAMPLES, properties=DOUBLE if platform == COMMON else None)
    return st.configurational, st.kinetic


#: the custom backend's runs take a minute or more each (a Python step() per sample): marked slow, run by .ci/run
STATIONARY_CASES = [pytest.param("custom", "Reference", marks=pytest.mark.slow, id="custom-Reference"), _case("native", "Reference"),
                    _case("native", COMMON)]


@pytest.fixture(scope="module")
def stationary():
    cache = {}

    def get(backend, platform, position):
        key = (backend, platform, position)
        if key not in cache:
            cache[key] = _stationary(*key)
        return cache[key]

    return get


@pytest.mark.parametrize("position", ["ends", "middle"])
@pytest.mark.parametrize("backend, platform", STATIONARY_CASES)
def test_oscillators_sample_the_exact_temperatures(stationary, backend, platform, position):
    assert OSCILLATORS["n"] == 1000 and OSCILLATORS["h_omega"] == 0.5
    q, kin = stationary(backend, platform, position)
    q_exact, kin_exact = exact_temperatures(position)
    assert q_exact == (1 / (1 - 0.5 ** 2 / 4) if position == "ends" else 1.0) and kin_exact == 1.0
    assert q.se < 0.0004 and kin.se < 0.00025, (q.se, kin.se)
    assert abs(q.mean - q_exact) < 3 * q.se, (q.mean, q.se, q_exact)
    assert abs(kin.mean - kin_exact) < 3 * kin.se, (kin.mean, kin.se)


@pytest.mark.slow  # it needs the custom backend's runs
@pytest.mark.parametrize("position", ["ends", "middle"])
@pytest.mark.parametrize("backend, platform", STATIONARY_CASES[1:])
def test_native_samples_what_custom_samples(stationary, backend, platform, position):
    """Different random streams, the same stationary state: the kinetic temperature at the thermostat point agrees
    within 3 combined standard errors that are at most 0.1 % (it would show the 0.14 % once seen between 86 short
    runs), the configurational one within 3 SE of at most 0.15 %."""
    pairs = zip(stationary(backend, platform, position), stationary("custom", "Reference", position))
    for (native, custom), resolution in zip(pairs, (0.0005, 0.00034)):
        se = math.hypot(native.se, custom.se)
        assert se < resolution, se
        assert abs(native.mean - custom.mean) < 3 * se, (native.mean, custom.mean, se)


# -- common random numbers: rows on one event grid draw the same numbers ---------------------------------------------
@pytest.mark.parametrize("backend, platform", [_case("native", "Reference"), _case("native", COMMON)])
def test_runs_on_one_event_grid_draw_the_same_numbers(backend, platform, water8):
    """Two runs with events at the same simulated times (2 fs steps every 6 steps, 4 fs steps every 3: every 12 fs)
    and the same seed consume the thermostat's stream event for event: after the same simulated time the next draws
    coincide bit for bit, although the runs took different steps and scaled different kinetic energies (the draws
    do not depend on the state).  This pairs an NVT row with the NVT reference replica by replica, as NVE rows are."""
    props = DOUBLE if platform == COMMON else {}
    next_draws = []
    for step_fs, interval in ((2.0, 6), (4.0, 3)):
        ig = SymplecticIntegrator(step_fs * 1e-3, "omelyan-2", system=water8.system, backend=backend, temperature=300,
                                  collision_time=0.1, thermostat_interval=interval, random_seed=77,
                                  thermostat_position="ends")
        ctx = mm.Context(water8.system, ig, mm.Platform.getPlatformByName(platform), props)
        ctx.setPositions(water8.positions)
        ctx.setVelocities(water8.velocities)
        ig.step(int(round(48 / step_fs)))  # 48 fs: 4 intervals, 8 events
        assert ig.computeHeatBathEnergy().value_in_unit(unit.kilojoule_per_mole) != 0
        next_draws.append(np.asarray(ig.sampleThermostatNoise(4)))
        del ctx
    assert next_draws[0].tobytes() == next_draws[1].tobytes()
