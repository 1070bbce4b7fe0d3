"""The velocity-rescaling thermostat's settings, shared by both backends: the option checks, the unit
conversions and the System facts it needs (degrees of freedom, whether the rigid rotation is kept).

    settings = thermostat_settings(system, temperature=300*unit.kelvin, collision_time=0.1*unit.picoseconds)

returns a :class:`ThermostatSettings` (or None without ``temperature``: no thermostat).  The numerics of an
event are :mod:`openmm_symprk.physics.velocity_rescaling`; each backend emits or runs them (the CustomIntegrator
program: :mod:`.thermostat_program`; the native plugin: its kernels).  docs/thermostat.md describes the scheme.
"""
from __future__ import annotations

import operator
from dataclasses import dataclass, replace

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..methods.placement import PLACEMENT_TEXT, check_position
from ..physics.temperature import R_KJ
from ..physics.velocity_rescaling import relaxation_factor
from ..systems.checks import EXACT_MOMENTUM_FORBIDDEN, check_system_type, conservation_issues
from ..systems.properties import thermostat_degrees_of_freedom
from .quantities import positive_quantity
from ..support.errors import InputError

__all__ = ["ThermostatSettings", "thermostat_settings", "temperature_in_kelvin", "collision_time_in_ps",
           "check_interval", "check_seed", "system_is_isolated", "DEFAULT_COLLISION_TIME", "THERMOSTAT_OPTIONS",
           "MAX_SEED", "MAX_INTERVAL", "DEFAULT_POSITION", "check_position"]

#: Default collision time tau (ps) when ``temperature`` is given without ``collision_time``.
DEFAULT_COLLISION_TIME = 0.1
#: The options of the thermostat (both backends take them).
THERMOSTAT_OPTIONS = ("temperature", "collision_time", "thermostat_interval", "random_seed", "thermostat_position")
#: Largest random seed: OpenMM's setRandomNumberSeed takes a 32-bit signed int.
MAX_SEED = 2**31 - 1
#: Largest thermostat interval: the native plugin holds it in a 32-bit signed int (and a longer one is an NVE run).
MAX_INTERVAL = 2**31 - 1
#: Where the thermostat sits when ``thermostat_position`` is not given (see :func:`check_position`).
DEFAULT_POSITION = "auto"


def temperature_in_kelvin(temperature) -> float:
    """A temperature as a float in K: a Quantity compatible with kelvin, or a plain number taken as kelvin;
    positive and finite."""
    return positive_quantity(temperature, "temperature", unit.kelvin, "temperature", "300*unit.kelvin")


def collision_time_in_ps(collision_time) -> float:
    """The collision time tau as a float in ps: a time Quantity or a plain number of picoseconds; > 0, finite."""
    return positive_quantity(collision_time, "collision_time", unit.picoseconds, "time", "0.1*unit.picoseconds")


def _whole_number(value, what: str, minimum: int, accepted: str) -> int:
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{what} {value!r} is a truth value; {accepted}")
    try:
        n = operator.index(value)
    except TypeError:
        raise TypeError(f"{what} must be a whole number, got {value!r}; {accepted}") from None
    if n < minimum:
        raise InputError(f"{what} must be >= {minimum}, got {n}; {accepted}")
    return int(n)


def check_interval(interval) -> int:
    """The thermostat interval n (the thermostat acts every n steps): an int from 1 to :data:`MAX_INTERVAL`."""
    accepted = f"give the number of steps between thermostat events, from 1 (every step) to {MAX_INTERVAL}"
    n = _whole_number(interval, "thermostat_interval", 1, accepted)
    if n > MAX_INTERVAL:
        raise InputError(f"thermostat_interval must be at most {MAX_INTERVAL} (the native plugin holds it in a 32-bit "
                         f"integer; an interval that long is an NVE run: drop temperature= for one), got {n}")
    return n


def check_seed(seed) -> int:
    """A random seed: an int in [0, 2**31 - 1] (0: a fresh seed each time a Context is created)."""
    n = _whole_number(seed, "random_seed", 0, f"give an integer from 0 (a fresh seed for every Context) "
                                              f"to {MAX_SEED}")
    if n > MAX_SEED:
        raise InputError(f"random_seed must be at most {MAX_SEED} (OpenMM takes a 32-bit seed), got {n}")
    return n


def system_is_isolated(system: mm.System) -> bool:
    """True for a System that conserves angular momentum: not periodic, no frozen (massless, non virtual-site)
    particles and no external field (the facts of :func:`openmm_symprk.systems.checks.conservation_issues`)."""
    return not any(key in EXACT_MOMENTUM_FORBIDDEN for key, _ in conservation_issues(system))


@dataclass(frozen=True)
class ThermostatSettings:
    """What a backend needs to run the thermostat.

    ``temperature`` (K), ``collision_time`` tau (ps), ``interval`` n (it acts every n steps), ``seed`` (0: a
    fresh one per Context), ``dof`` (the degrees of freedom it samples), ``keep_rotation`` (the System is
    isolated: the rigid rotation about the centre of mass is kept, as the centre-of-mass velocity always is),
    ``position`` ("ends", "middle" or "auto" as asked; where the events sit is the resolved method's, read back by
    :func:`~openmm_symprk.methods.resolved.placement_of`: ``integrator.thermostat_position``).

    What it needs: a peculiar kinetic energy to scale (velocities that are not all one rigid motion).  A System at
    rest, or moving only as a rigid whole, stays where it is (a warning says so): start a run with velocities drawn
    at the temperature (``context.setVelocitiesToTemperature``)."""

    temperature: float
    collision_time: float
    interval: int
    seed: int
    dof: int
    keep_rotation: bool
    position: str = DEFAULT_POSITION

    def c_half(self, step_ps: float) -> float:
        """c = exp(-(n dt / 2) / tau): the relaxation factor of one half event (two per n steps)."""
        return relaxation_factor(0.5 * self.interval * step_ps, self.collision_time)

    @property
    def target_kinetic(self) -> float:
        """N_f k T / 2 (kJ/mol): the mean kinetic energy of the peculiar velocities."""
        return 0.5 * self.dof * R_KJ * self.temperature

    def with_temperature(self, temperature) -> "ThermostatSettings":
        return replace(self, temperature=temperature_in_kelvin(temperature))

    def with_collision_time(self, collision_time) -> "ThermostatSettings":
        return replace(self, collision_time=collision_time_in_ps(collision_time))

    def with_seed(self, seed) -> "ThermostatSettings":
        return replace(self, seed=check_seed(seed))

    def as_dict(self) -> dict:
        out = {"temperature": self.temperature, "collision_time": self.collision_time, "interval": self.interval,
               "seed": self.seed, "dof": self.dof, "keep_rotation": self.keep_rotation}
        if self.position != "ends":  # (the programs of the ends placement keep the metadata they had before)
            out["position"] = self.position
        return out

    def describe(self, position: str, outer: bool = False) -> str:
        """One line; ``position``: where the events sit as the method was resolved ("ends" or "middle"); ``outer``:
        the step is the outer one of multiple time stepping."""
        placed = PLACEMENT_TEXT[position] + (" (the outer step)" if outer else "")
        kept = "centre-of-mass velocity and rigid rotation kept" if self.keep_rotation else \
            "centre-of-mass velocity kept"
        every = "every step" if self.interval == 1 else f"every {self.interval} steps"
        return (f"thermostat: stochastic velocity rescaling at {self.temperature:g} K, collision time "
                f"{self.collision_time:g} ps, {every} ({placed}), {self.dof} degrees of "
                f"freedom, {kept}, seed {self.seed if self.seed else 'fresh per Context'}")


def thermostat_settings(system, *, temperature=None, collision_time=None, thermostat_interval=None,
                        random_seed=None, thermostat_position=None) -> ThermostatSettings | None:
    """The checked thermostat settings of an integrator's options, or None without ``temperature``.

    ``collision_time`` (default 0.1 ps), ``thermostat_interval`` (default 1), ``random_seed`` (default 0) and
    ``thermostat_position`` (default :data:`DEFAULT_POSITION`, :func:`check_position`) only make sense with ``temperature``; ``system`` (the System the integrator will run) is required with it,
    since the degrees of freedom come from it."""
    if temperature is None:
        given = [name for name, value in (("collision_time", collision_time),
                                          ("thermostat_interval", thermostat_interval),
                                          ("random_seed", random_seed),
                                          ("thermostat_position", thermostat_position)) if value is not None]
        if given:
            raise InputError(f"{', '.join(given)} {'was' if len(given) == 1 else 'were'} given without temperature: "
                             f"{'it sets' if len(given) == 1 else 'they set'} up the thermostat, which only runs with "
                             f"temperature= (e.g. temperature=300*unit.kelvin); drop "
                             f"{'it' if len(given) == 1 else 'them'} for an NVE run")
        return None
    kelvin = temperature_in_kelvin(temperature)
    tau = collision_time_in_ps(DEFAULT_COLLISION_TIME if collision_time is None else collision_time)
    interval = check_interval(1 if thermostat_interval is None else thermostat_interval)
    seed = check_seed(0 if random_seed is None else random_seed)
    position = check_position(DEFAULT_POSITION if thermostat_position is None else thermostat_position)
    if system is None:
        raise InputError("temperature= needs system= (the System the integrator will run): the thermostat's "
                         "degrees of freedom and whether the rotation is kept come from it")
    check_system_type(system)
    isolated = system_is_isolated(system)
    dof = thermostat_degrees_of_freedom(system, isolated)
    if dof <= 0:
        raise InputError(
            f"no degrees of freedom to thermostat: the System has {system.getNumParticles()} particle(s) and "
            f"{system.getNumConstraints()} constraint(s), which leaves {dof} degrees of freedom once the "
            f"centre-of-mass velocity{' and the rigid rotation (isolated System)' if isolated else ''} are kept "
            f"(3 per particle with mass - constraints - 3{' - 3 (2 for two particles)' if isolated else ''})")
    return ThermostatSettings(kelvin, tau, interval, seed, dof, isolated, position)
