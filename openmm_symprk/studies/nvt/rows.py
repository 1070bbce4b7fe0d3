"""The integrators the NVT measurements compare, each built from a row name.

A row is a name, a step size and what to build: the package's integrators (``temperature=`` for NVT, or NVE),
OpenMM 8.6's thermostatted integrators and its VerletIntegrator.  The Langevin-type thermostats and
Nose-Hoover use friction (collision frequency) 1/ps, OpenMM's usual choice; ours uses ``collision_time`` 0.1 ps
(the package's default, as GROMACS users set v-rescale's tau).  Velocity rescaling acts on one collective
variable, the kinetic energy, so its tau is no per-particle friction; and an event is the same work whatever tau.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import openmm as mm
import openmm.unit as unit

#: Thermostat settings shared by the rows (K, 1/ps, ps, nm)
TEMPERATURE = 300.0
FRICTION = 1.0
COLLISION_TIME = 0.1
DPD_CUTOFF = 0.9

#: The multiple-time-step split of the rows with groups=: the slow group 1 (PME reciprocal space) once per outer
#: step, the fast group 0 twice.
MTS_GROUPS = [(1, 1), (0, 2)]


@dataclass(frozen=True)
class Row:
    name: str  # what the tables print
    kind: str  # "openmm-langevin", "openmm-nosehoover", "openmm-dpd", "openmm-mtslangevin", "openmm-verlet",
    #             or "symprk" (the package's SymplecticIntegrator)
    step_fs: float
    method: str = ""  # catalogue name (symprk rows)
    nvt: bool = True  # thermostat on
    interval: int = 1  # thermostat_interval (symprk rows)
    mts: bool = False  # groups=MTS_GROUPS
    peer: str = ""  # the OpenMM row it replaces (its ratio is printed too)
    options: dict = field(default_factory=dict, compare=False)

    @property
    def has_heat_bath(self) -> bool:
        """Whether total + heat-bath energy is a conserved quantity of the row (computeHeatBathEnergy)."""
        return self.kind in ("symprk", "openmm-nosehoover", "openmm-verlet")


KINDS = ("openmm-langevin", "openmm-nosehoover", "openmm-dpd", "openmm-mtslangevin", "openmm-verlet", "symprk")


def build(row: Row, system: mm.System, seed: int = 1, backend: str = "native"):
    """(integrator, force evaluations per step) for ``row`` on ``system``."""
    dt = row.step_fs * unit.femtoseconds
    T = TEMPERATURE * unit.kelvin
    if row.kind == "openmm-langevin":
        ig, evals = mm.LangevinMiddleIntegrator(T, FRICTION / unit.picosecond, dt), 1
    elif row.kind == "openmm-nosehoover":
        ig, evals = mm.NoseHooverIntegrator(T, FRICTION / unit.picosecond, dt), 1
    elif row.kind == "openmm-dpd":
        ig, evals = mm.DPDIntegrator(T, FRICTION / unit.picosecond, DPD_CUTOFF * unit.nanometer, dt), 1
    elif row.kind == "openmm-mtslangevin":
        ig = mm.MTSLangevinIntegrator(T, FRICTION / unit.picosecond, dt, MTS_GROUPS)
        evals = sum(n for _, n in MTS_GROUPS)
    elif row.kind == "openmm-verlet":
        ig, evals = mm.VerletIntegrator(dt), 1
    elif row.kind == "symprk":
        from ...integrators import SymplecticIntegrator

        options = dict(row.options)
        if row.nvt:
            options.update(temperature=TEMPERATURE, collision_time=COLLISION_TIME, thermostat_interval=row.interval,
                           random_seed=seed)
        if row.mts:
            options.update(groups=MTS_GROUPS)
        with warnings.catch_warnings():  # the one-time ConservationWarning of a periodic box: known here
            warnings.simplefilter("ignore")
            ig = SymplecticIntegrator(dt, row.method, system=system, backend=backend, **options)
        evals = ig.program_info.force_evals
    else:
        raise ValueError(f"row {row.name!r}: unknown kind {row.kind!r}; known: {', '.join(KINDS)}")
    if row.kind != "symprk" and hasattr(ig, "setRandomNumberSeed"):
        ig.setRandomNumberSeed(seed)
    return ig, evals
