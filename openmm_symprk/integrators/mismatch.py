"""What differs when a checkpoint of another program is loaded into a CustomIntegrator program of this package: the
words of the CheckpointMismatchError its next step raises.

A CustomIntegrator checkpoint restores the program's global variables by position, the signature (global 0) among
them, and nothing that names the options of the run that wrote it.  So :func:`mismatch_message` compiles the programs
that run may have had (this integrator's, with one thing changed: the ensemble, the method, ``exact_momentum``,
``check_finite``, ``max_speed``, the constraints, the thermostat's interval or placement) and names the change whose
signature is the one the Context holds.  A checkpoint of the native plugin starts with its magic number (the bytes
"SymPRK"), one of an OpenMM integrator without state of its own leaves 0.
"""
from __future__ import annotations

import struct
from dataclasses import replace

import openmm as mm

from ..methods.catalogue import methods
from ..methods.resolved import resolve
from . import program
from .thermostat import thermostat_settings

__all__ = ["mismatch_message", "STATE_ADVICE"]

#: How to continue another run, or change ensemble, with a new integrator.
STATE_ADVICE = ("save a State of that run (Simulation.saveState, or Context.getState with positions and velocities) "
                "and load it into a Simulation with this integrator (Simulation.loadState, or Context.setState)")
#: Thermostat intervals tried when the checkpoint's run may have had another one.
_INTERVALS = range(1, 11)


def _signature(method, options, thermostat, has_sites: bool) -> int | None:
    """The signature of the program ``method`` compiles to with ``options`` and the ``thermostat``'s settings (None
    for NVE; None returned if it does not compile)."""
    try:  # the method alone (resolve_for_system would check a System and warn, once per kind, for a candidate)
        constraints = options.constraints
        if constraints is None and options.system is not None:
            constraints = options.system.constraints
        resolved = resolve(method, constraints=constraints, groups=options.groups,
                           inner_method=options.inner_method,
                           thermostat_position=thermostat.position if thermostat is not None else None)
        return program.compile_program(mm.CustomIntegrator(options.step_size), resolved, options, has_sites,
                                       thermostat).signature
    except (ValueError, TypeError):
        return None


def _thermostats(thermostat, system):
    """Thermostat settings the checkpoint's run may have had: this integrator's (``thermostat``) with another interval
    or placement, or (an NVE integrator) the defaults at every interval and placement."""
    base = thermostat
    if base is None:
        try:
            base = thermostat_settings(system, temperature=300.0)
        except (ValueError, TypeError):  # no System, or nothing to thermostat
            return
    for position in dict.fromkeys((base.position, "ends", "middle")):
        for interval in _INTERVALS:
            yield replace(base, interval=interval, position=position)


def _candidates(resolved, options, thermostat, system):
    """(what differs, whether it is the ensemble, method, options, thermostat settings) for the programs the
    checkpoint's run may have had."""
    method = resolved.entry.name if resolved.entry is not None and not resolved.is_mts else None
    if method is None:
        return
    nvt = thermostat is not None
    if nvt:
        yield "the ensemble (the checkpoint's run was NVE, without temperature=; this integrator runs NVT)", True, \
            method, options, None
    for settings in _thermostats(thermostat, system):
        if not nvt:
            yield ("the ensemble (the checkpoint's run was NVT, with temperature=; this integrator runs NVE)", True,
                   method, options, settings)
        elif settings.interval != thermostat.interval:
            yield (f"thermostat_interval (the checkpoint's run had {settings.interval}; this integrator has "
                   f"{thermostat.interval})", False, method, options, settings)
        elif settings.position != thermostat.position:
            yield (f"thermostat_position (the checkpoint's run had {settings.position!r}; this integrator has "
                   f"{thermostat.position!r})", False, method, options, settings)
    on_off = {True: "on", False: "off"}
    yield (f"exact_momentum (the checkpoint's run had it {on_off[not options.exact_momentum]}; this integrator has it "
           f"{on_off[options.exact_momentum]})", False, method, replace(options, exact_momentum=not options.exact_momentum),
           thermostat)
    yield (f"check_finite (the checkpoint's run had it {on_off[not options.check_finite]}; this integrator has it "
           f"{on_off[options.check_finite]})", False, method, replace(options, check_finite=not options.check_finite),
           thermostat)
    if options.max_speed:
        yield (f"max_speed (the checkpoint's run had none; this integrator has {options.max_speed:g} nm/ps)", False,
               method, replace(options, max_speed=0.0), thermostat)
    yield (f"the constraints (the checkpoint's program was compiled {'without' if resolved.constraints else 'with'} "
           f"RATTLE steps; this one {'with' if resolved.constraints else 'without'}: constraints= or the System's "
           f"constraints)", False, method, replace(options, constraints=not resolved.constraints), thermostat)
    for other in methods.splittings():
        if other.name != method:
            yield (f"the method (the checkpoint's run used {other.name!r}; this integrator runs {method!r})", False,
                   other.name, options, thermostat)


def mismatch_message(where: str, resolved, options, thermostat, stored: float, expected: int, system=None) -> str:
    """The message of the CheckpointMismatchError of ``where`` (the class and method), whose program (``resolved``,
    ``options``, the ``thermostat``'s settings or None, signature ``expected``) finds ``stored`` in global 0;
    ``system``: the System given as ``system=`` (for the thermostat an NVE integrator's run may have had)."""
    head = f"{where}: the Context holds the state of another integrator program (a checkpoint was loaded)"
    if struct.pack(">d", stored)[:6] == b"SymPRK":
        return (f"{head}: it was written by the native backend; load it into SymplecticIntegrator(..., "
                f"backend='native') created with the same method and options, or, to go on with this one, "
                f"{STATE_ADVICE}.")
    if not (stored >= 1 and stored == int(stored) and stored < 2**52):
        return (f"{head}: it was not written by a program of this package but by another integrator (OpenMM's "
                f"VerletIntegrator, LangevinMiddleIntegrator and the like). A checkpoint continues the run of the "
                f"integrator that wrote it; to go on from that run with this one, {STATE_ADVICE}.")
    has_sites = options.system.virtual_sites if options.system is not None else True
    for what, ensemble, method, candidate, settings in _candidates(resolved, options, thermostat, system):
        if _signature(method, candidate, settings, has_sites) == int(stored):
            if ensemble:
                return (f"{head}; what differs: {what}. A checkpoint continues one run in its ensemble; to change the "
                        f"ensemble, {STATE_ADVICE}.")
            return (f"{head}; what differs: {what}. Create the integrator as it was when the checkpoint was saved and "
                    f"load the checkpoint into that one, or {STATE_ADVICE}.")
    return (f"{head}, signature {stored:.0f} where this program's is {expected}: a checkpoint saved with another "
            f"method or other options (exact_momentum, constraints, max_speed, groups, the thermostat's), or with "
            f"the native backend. Create the integrator as it was when the checkpoint was saved (a native checkpoint "
            f"needs backend='native') and load the checkpoint into that one, or {STATE_ADVICE}.")
