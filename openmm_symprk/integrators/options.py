"""The keyword options of the package's integrators, checked once into one frozen :class:`IntegratorOptions`.

Every integrator class takes ``stepSize``, the method, ``system=`` and keyword options.  Its constructor builds one
:class:`IntegratorOptions` with :meth:`IntegratorOptions.build`, which refuses an unknown option name (with close
names, as method names get), checks every value (with an error naming it and what is accepted) and derives what the
backends need (the step size in ps, ``max_speed`` in nm/ps, the facts of ``system=``); both backends then read
that one object.  The thermostat's settings are not among them: they change while the
integrator runs (``setTemperature``), so the integrator holds them once (``integrator.thermostat``, checked by
:func:`.thermostat.thermostat_settings`).

The options (defaults in brackets):

* both backends: ``exact_momentum`` [False] (needs ``system=``), ``check_finite`` [True], ``max_speed`` [None: only
  NaN, infinity and absurd speeds (the custom program: a velocity component above 1e15 nm/ps) count as a blow-up;
  at most :data:`MAX_SPEED_LIMIT`], ``groups`` and ``inner_method`` (multiple time stepping) (and the
  thermostat's options, :data:`.thermostat.THERMOSTAT_OPTIONS`, checked apart);
* the CustomIntegrator backend only: ``constraints`` [None: from ``system=``], ``allow_nonsymplectic`` [False],
  ``tolerance`` [1e-12 nm] and ``max_iterations`` [60] (implicit methods' fixed-point iteration).
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

import openmm.unit as unit

from ..methods.respa import mts_groups
from ..systems.checks import check_system_type
from ..systems.properties import SystemSignature, signature
from .base import step_size_in_ps
from .thermostat import THERMOSTAT_OPTIONS
from ..support.errors import InputError

__all__ = ["IntegratorOptions", "NATIVE_OPTIONS", "CUSTOM_OPTIONS", "OPTIONS", "DEFAULT_TOLERANCE",
           "DEFAULT_MAX_ITERATIONS", "check_option_names", "check_max_speed"]

#: Options of SymplecticIntegrator that both backends take (the native backend takes these only).
NATIVE_OPTIONS = frozenset({"exact_momentum", "check_finite", "max_speed", "groups", "inner_method",
                            *THERMOSTAT_OPTIONS})
#: Options only the CustomIntegrator backend takes.
CUSTOM_OPTIONS = frozenset({"allow_nonsymplectic", "constraints", "tolerance", "max_iterations"})
#: Every option of SymplecticIntegrator.
OPTIONS = NATIVE_OPTIONS | CUSTOM_OPTIONS
#: The fixed-point iteration of implicit methods: tolerance (nm) and iteration cap.
DEFAULT_TOLERANCE = 1e-12
DEFAULT_MAX_ITERATIONS = 60


def check_option_names(given, accepted, where: str) -> None:
    """TypeError naming every option of ``given`` that is not in ``accepted``, with close names (difflib), as
    method names get; a bare Python TypeError would say neither."""
    accepted = sorted(accepted)
    bad = [k for k in given if k not in accepted]
    if not bad:
        return
    parts = []
    for k in bad:
        close = difflib.get_close_matches(str(k), accepted, n=3, cutoff=0.6)
        parts.append(f"{k!r}" + (f" (did you mean {', '.join(map(repr, close))}?)" if close else ""))
    raise TypeError(f"{where} got {'an unknown option' if len(bad) == 1 else 'unknown options'} {', '.join(parts)}; "
                    f"it accepts {', '.join(accepted)}")


#: The largest ``max_speed`` (nm/ps): its square is written into the programs, where single precision (CUDA) refuses a
#: literal beyond float's range (about 3.4e38); 1e15 nm/ps is already some 3e9 times the speed of light.
MAX_SPEED_LIMIT = 1e15


def check_max_speed(max_speed) -> float:
    """``max_speed`` in nm/ps as a float in [0, MAX_SPEED_LIMIT] (None or 0: only NaN, infinity and absurd speeds count
    as a blow-up)."""
    if max_speed is None:
        return 0.0
    if unit.is_quantity(max_speed):
        max_speed = max_speed.value_in_unit(unit.nanometer / unit.picosecond)
    try:
        value = float(max_speed)
    except (TypeError, ValueError):
        raise TypeError(f"max_speed must be a speed in nm/ps (or None), got {max_speed!r}") from None
    if not math.isfinite(value) or value < 0 or value > MAX_SPEED_LIMIT:
        raise InputError(f"max_speed must be a speed from 0 to {MAX_SPEED_LIMIT:g} nm/ps (None or 0: only NaN, "
                         f"infinity and absurd speeds), got {max_speed!r}")
    return value


def _check_tolerance(tolerance) -> float:
    if not (isinstance(tolerance, (int, float)) and not isinstance(tolerance, bool) and tolerance > 0
            and math.isfinite(tolerance)):
        raise InputError(f"tolerance must be a positive number of nm, got {tolerance!r}")
    return float(tolerance)


def _check_max_iterations(max_iterations) -> int:
    if isinstance(max_iterations, bool) or int(max_iterations) < 1:
        raise InputError(f"max_iterations must be at least 1, got {max_iterations!r}")
    return int(max_iterations)


@dataclass(frozen=True)
class IntegratorOptions:
    """An integrator's options, checked (see the module docstring); build it with :meth:`build`."""

    step_size: float  # ps, the step size the integrator is created with
    system: SystemSignature | None = None  # the facts of system= (None without one)
    exact_momentum: bool = False
    check_finite: bool = True
    max_speed: float = 0.0  # nm/ps; 0: only NaN and infinity count as a blow-up
    groups: tuple | None = None  # multiple time stepping: ((force group, substeps), ...)
    inner_method: object = None  # multiple time stepping: the inner levels' method (None: the outer one)
    constraints: bool | None = None  # RATTLE steps or not; None: from system= (kick/drift methods keep them without)
    allow_nonsymplectic: bool = False
    tolerance: float = DEFAULT_TOLERANCE  # nm
    max_iterations: int = DEFAULT_MAX_ITERATIONS

    @classmethod
    def build(cls, where: str, step_size, system=None, *, exact_momentum=False, check_finite=True, max_speed=None,
              groups=None, inner_method=None, constraints=None, allow_nonsymplectic=False,
              tolerance=DEFAULT_TOLERANCE, max_iterations=DEFAULT_MAX_ITERATIONS) -> IntegratorOptions:
        """The checked options of ``where`` (the class name, for messages), each by its name (the module docstring
        lists them).  A class refuses the names it does not take before it calls this (:func:`check_option_names`)."""
        dt = step_size_in_ps(step_size)
        max_speed = check_max_speed(max_speed)
        if constraints is not None and not isinstance(constraints, bool):
            raise TypeError(f"constraints must be True, False or None (from system=), got {constraints!r}")
        tolerance = _check_tolerance(tolerance)
        max_iterations = _check_max_iterations(max_iterations)
        exact_momentum = bool(exact_momentum)
        if exact_momentum and system is None:
            raise InputError("exact_momentum=True needs system= (the System the integrator will run): the "
                             "projection is only right for an isolated System, which is checked, and it uses the "
                             "System's masses")
        if system is not None:
            check_system_type(system)
        return cls(step_size=dt, system=signature(system) if system is not None else None,
                   exact_momentum=exact_momentum, check_finite=bool(check_finite), max_speed=max_speed,
                   groups=mts_groups(groups) if groups is not None else None, inner_method=inner_method,
                   constraints=constraints, allow_nonsymplectic=bool(allow_nonsymplectic),
                   tolerance=tolerance, max_iterations=max_iterations)
