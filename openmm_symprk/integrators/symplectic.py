"""``SymplecticIntegrator``: a catalogue method by name, on the backend that suits this installation.

``SymplecticIntegrator(...)`` is a real class: calling it builds an instance of one of its backend
subclasses (:class:`~openmm_symprk.integrators.custom_backend.CustomSymplecticIntegrator`, a CustomIntegrator
program, or :class:`~openmm_symprk.integrators.native_backend.NativeSymplecticIntegrator`, the compiled plugin),
chosen by :func:`~openmm_symprk.integrators.backend.choose_backend`; Python then runs that subclass's
``__init__`` as usual, and ``isinstance(integrator, SymplecticIntegrator)`` holds for both.  Backend
subclasses register themselves with ``class X(SymplecticIntegrator, ..., backend="name")``.
"""
from __future__ import annotations

from .backend import choose_backend
from .base import IntegratorBase
from ..support.errors import InputError

__all__ = ["SymplecticIntegrator"]


class SymplecticIntegrator(IntegratorBase):
    """A catalogue method by name (``openmm_symprk.methods``), e.g. "verlet", "yoshida-4", "kahan-li-8".

    ``SymplecticIntegrator(stepSize, method="verlet", system=None, backend="auto", **options)``

    * ``stepSize``: a time Quantity, or a number of picoseconds;
    * ``method``: a catalogue name, case-insensitive, aliases accepted (velocity-verlet, forest-ruth, ...); an
      unknown name raises UnknownMethodError with close names;
    * ``system``: the System the integrator will run.  It decides whether RATTLE constraint steps are
      compiled, is checked for anything that breaks conservation (one warning per kind), and is recorded:
      a Context of another System is refused with :class:`~openmm_symprk.integrators.base.SystemMismatchError`;
    * ``backend``: "auto" (default) takes the native plugin for kick/drift methods when it has a kernel for
      every platform of this installation (else the CustomIntegrator program, with a one-time warning
      saying why and how to fix it); "native" or "custom" insist on one;
    * options: ``exact_momentum`` (project every kick onto zero net force and torque; isolated systems,
      needs ``system=``), ``check_finite`` (raise SimulationBlowUpError on NaN/inf velocities),
      ``max_speed`` (nm/ps: also count faster velocities as a blow-up); the CustomIntegrator backend also
      takes ``allow_nonsymplectic``, ``constraints``, ``tolerance`` and ``max_iterations``
      (see :class:`~openmm_symprk.integrators.custom_backend.PRKIntegrator`);
    * NVT: ``temperature`` (K, needs ``system=``), ``collision_time`` (ps, default 0.1), ``thermostat_interval``
      (default 1, at most 2**31 - 1), ``random_seed`` (default 0: fresh per Context) and ``thermostat_position``
      ("auto", the default: the better placement for the method, middle for verlet and ends for the others,
      docs/thermostat.md; "ends": half events around the step; "middle": one event at the step's centre, exact
      configurations for Verlet) add stochastic
      velocity rescaling, keeping total momentum (and angular momentum of an isolated System) exactly
      (:mod:`openmm_symprk.integrators.thermostat`); accessors ``getTemperature``, ``setTemperature``,
      ``computeHeatBathEnergy``, ``thermostat_kinetic_energy``, ``thermostat_dof``... (:class:`~.base.IntegratorBase`).
      The thermostat needs a peculiar kinetic energy to scale: a System at rest or moving as a rigid whole stays
      so (a warning says so); start with velocities drawn at the temperature.

    The options are checked once, into one frozen :class:`~.options.IntegratorOptions` (``integrator.options``),
    which the backend reads; ``integrator.resolved`` is the method as it runs, ``integrator.program_info`` the facts
    of the compiled program.
    """

    #: backend name -> concrete class (filled by the subclasses)
    _backends: dict = {}

    def __init_subclass__(cls, backend: str | None = None, **kwargs):
        super().__init_subclass__(**kwargs)
        if backend is not None:
            cls.backend = backend
            SymplecticIntegrator._backends[backend] = cls

    def __new__(cls, stepSize=None, method="verlet", system=None, backend="auto", **options):
        if cls is SymplecticIntegrator:
            cls = SymplecticIntegrator._backends[choose_backend(method, backend, options)]
        return object.__new__(cls)

    @classmethod
    def _check_backend(cls, backend):
        if backend not in ("auto", cls.backend):
            raise InputError(f"{cls.__name__} is the {cls.backend!r} backend; backend={backend!r} asks for another "
                             f"(use SymplecticIntegrator(..., backend={backend!r}))")
