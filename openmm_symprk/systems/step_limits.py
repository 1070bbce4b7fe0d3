"""The steps each method was measured to run on a kind of System, and the one-time warning when an integrator is
built with a larger step for a System of that kind.

The measurements are data (``data/step_limits.toml``, each number with its source): rigid water (the fidelity
study's 216 SPC/E waters), a solvated protein with HBonds, and the same with hydrogen mass repartitioning (the
production bench's villin), all periodic boxes of liquid water.  A periodic System is of a kind when it has what limited
the step there (:func:`system_kinds`): rigid waters, or constrained bonds to hydrogen outside them (with repartitioned
hydrogens, 1.4 Da or more, or without).  An
integrator whose method and step go beyond a measurement of its System's kinds (:func:`step_limit_warning`) warns once,
naming the step measured, the System it was measured on and what to do: a warning only where it applies, so that it can
be acted on.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources

from .checks import warn_once
from .hydrogens import hydrogen_facts

__all__ = ["StepLimitWarning", "StepLimit", "STEP_LIMITS", "SYSTEMS", "system_kinds", "step_limit_warning",
           "warn_step_limit", "REPARTITIONED_HYDROGEN_MASS"]

#: A hydrogen this heavy or heavier (Da) has been repartitioned (HMR: 1.5-4 Da).
REPARTITIONED_HYDROGEN_MASS = 1.4


class StepLimitWarning(UserWarning):
    """The step is beyond what the method was measured to run on a System of this kind."""


@dataclass(frozen=True)
class StepLimit:
    """A measurement: ``method`` on the System kind ``system`` survived every run at ``stable_fs`` (None: not
    measured below the blow-up) and blew up at ``unstable_fs`` (None: it did not blow up in what was run); ``runs``: the
    runs at the step that decides."""

    system: str
    method: str
    stable_fs: float | None
    unstable_fs: float | None
    runs: int


def _load():
    data = tomllib.loads(resources.files(__package__).joinpath("data", "step_limits.toml").read_text())
    systems = {s["key"]: s for s in data["system"]}
    limits = tuple(StepLimit(r["system"], r["method"], r.get("stable_fs"), r.get("unstable_fs"), int(r["runs"]))
                   for r in data["limit"])
    for limit in limits:
        if limit.system not in systems or (limit.stable_fs is None and limit.unstable_fs is None):
            raise ValueError(f"data/step_limits.toml: {limit} names an unknown system or no step")
    return systems, limits


#: The kinds of System measured (key -> {"name", "source"}) and the measurements.
SYSTEMS, STEP_LIMITS = _load()


def system_kinds(system) -> tuple:
    """The kinds of :data:`SYSTEMS` whose measurements apply to ``system``: a periodic System (all were measured in
    liquid water; a cluster in vacuum takes larger steps, docs/benchmarks.md) with "rigid-water" with rigid waters,
    "protein" or "protein-hmr" with constrained bonds to hydrogen outside them and no unconstrained one."""
    if not system.usesPeriodicBoundaryConditions():
        return ()
    facts = hydrogen_facts(system)
    kinds = ("rigid-water",) if facts.rigid_waters else ()
    if facts.solute_constrained and not facts.unconstrained:
        kinds += ("protein-hmr" if facts.solute_hydrogen_mass >= REPARTITIONED_HYDROGEN_MASS else "protein",)
    return kinds


def _steps(fs) -> str:
    return f"{fs:g} fs"


def _within(limit: StepLimit, step_fs: float) -> bool:
    """Whether ``step_fs`` is within ``limit``: below its blow-up, and at most its largest stable step."""
    return ((limit.unstable_fs is None or step_fs < limit.unstable_fs - 1e-9) and
            (limit.stable_fs is None or step_fs <= limit.stable_fs + 1e-9))


def _measured(limit: StepLimit, step_fs: float) -> str:
    """What ``limit`` measured, for a step beyond it."""
    on = f"{SYSTEMS[limit.system]['name']} ({SYSTEMS[limit.system]['source']})"
    if limit.unstable_fs is not None and step_fs >= limit.unstable_fs - 1e-9:
        runs = f"every one of its {limit.runs} runs" if limit.runs > 1 else "its run"
        ran = f"; it ran at {_steps(limit.stable_fs)}" if limit.stable_fs is not None else ""
        return f"{limit.method} blew up at {_steps(limit.unstable_fs)} on {runs} of {on}{ran}"
    return (f"{limit.method} was measured stable up to {_steps(limit.stable_fs)}, and not beyond, in {limit.runs} "
            f"run{'s' if limit.runs > 1 else ''} of {on}")


def step_limit_warning(system, method: str, step_fs: float) -> tuple:
    """(key, message) for ``method`` (a catalogue name) at ``step_fs`` on ``system`` when the step is at or beyond a
    measured blow-up, or beyond the largest step measured stable, on a System of one of its kinds; () otherwise."""
    mine = [limit for limit in STEP_LIMITS if limit.method == method]
    if all(_within(limit, step_fs) for limit in mine):
        return ()  # within every measurement of the method, whatever the System (its facts are not read)
    for kind in system_kinds(system):
        for limit in mine:
            if limit.system != kind or _within(limit, step_fs):
                continue
            advice = (f"use at most {_steps(limit.stable_fs)} with {method}" if limit.stable_fs is not None else
                      f"use a step below {_steps(limit.unstable_fs)} with {method}")
            has = "rigid water" if kind == "rigid-water" else "constrained bonds to hydrogen"
            return (f"step-limit:{kind}:{method}",
                    f"a step of {_steps(step_fs)} with {method} on this System (it has {has}): "
                    f"{_measured(limit, step_fs)}. To be safe, {advice}, or measure your own System (symprk bench "
                    f"--system-xml system.xml --state state.xml).")
    return ()


def warn_step_limit(system, method: str, step_fs: float, context: str = "openmm_symprk") -> bool:
    """Warn once (:class:`StepLimitWarning`) if :func:`step_limit_warning` finds the step beyond a measurement."""
    found = step_limit_warning(system, method, step_fs)
    return bool(found) and warn_once(found[0], f"{context}: {found[1]}", StepLimitWarning)
