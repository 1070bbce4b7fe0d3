"""The fidelity study's rows made into running integrators (the OpenMM side; the rows are data in
:mod:`.presets`).

:func:`check_row` validates a row and names what is wrong; :func:`describe` gives its label, ensemble, force
evaluations per step, whether it keeps the total momentum and whether it has a conserved effective energy;
:func:`availability` says whether this installation can run it (the package's thermostat rows need an
integrator that accepts ``temperature=``); :class:`Engine` runs one row from a replica state.
"""
from __future__ import annotations

import openmm as mm
import openmm.unit as unit

from ...methods.catalogue import get_method
from ...systems.properties import masses
from ...systems.repartition import repartition_hydrogen_mass, rigid_velocities_for_masses

__all__ = ["KINDS", "UNAVAILABLE_THERMOSTAT", "RowUnavailable", "check_row", "describe", "label", "availability",
           "Engine"]

#: Options each kind of row takes (besides kind, step_fs and hmr_da).
KINDS = {"symprk": {"method", "collision_time_ps"}, "langevin": {"friction_per_ps"},
         "mts-langevin": {"friction_per_ps", "inner_steps"}, "nose-hoover": {"collision_frequency_per_ps"},
         "dpd": {"friction_per_ps", "cutoff_nm"}}
_REQUIRED = {"symprk": {"method"}, "langevin": {"friction_per_ps"}, "mts-langevin": {"friction_per_ps", "inner_steps"},
             "nose-hoover": {"collision_frequency_per_ps"}, "dpd": {"friction_per_ps"}}

#: What the output says for a thermostat row this installation cannot run.
UNAVAILABLE_THERMOSTAT = "unavailable: needs the thermostat"


class RowUnavailable(RuntimeError):
    """This installation cannot run the row (e.g. the integrator does not accept ``temperature=``)."""


def check_row(row: dict) -> dict:
    """``row`` with step_fs as a float; ValueError naming the row and the bad field otherwise."""
    if not isinstance(row, dict) or row.get("kind") not in KINDS:
        raise ValueError(f"row {row!r}: kind must be one of {', '.join(KINDS)}")
    kind = row["kind"]
    extra = set(row) - KINDS[kind] - {"kind", "step_fs", "hmr_da"}
    missing = _REQUIRED[kind] - set(row)
    if extra or missing:
        raise ValueError(f"row {row!r}: a {kind} row takes {', '.join(sorted(KINDS[kind] | {'step_fs', 'hmr_da'}))}"
                         + (f"; unknown: {', '.join(sorted(extra))}" if extra else "")
                         + (f"; missing: {', '.join(sorted(missing))}" if missing else ""))
    for k, v in row.items():
        if k not in ("kind", "method") and (isinstance(v, bool) or not float(v) > 0):
            raise ValueError(f"row {row!r}: {k} must be a positive number, got {v!r}")
    if kind == "symprk":
        m = get_method(row["method"])
        if not m.is_splitting:
            raise ValueError(f"row {row!r}: {m.name} is a {m.family} method; rigid water runs kick/drift splittings "
                             f"and compositions only (e.g. verlet, omelyan-2, pefrl)")
    if "inner_steps" in row and int(row["inner_steps"]) != row["inner_steps"]:
        raise ValueError(f"row {row!r}: inner_steps must be a whole number")
    return dict(row, step_fs=float(row["step_fs"]))


def _g(x) -> str:
    return f"{float(x):g}"


def label(row: dict) -> str:
    """e.g. 'verlet 0.5 fs', 'omelyan-2 4 fs SVR 1 ps', 'langevin 4 fs friction 1/ps HMR 3 Da'."""
    kind, h = row["kind"], _g(row["step_fs"])
    if kind == "symprk":
        text = f"{row['method']} {h} fs" + (f" SVR {_g(row['collision_time_ps'])} ps" if "collision_time_ps" in row
                                            else "")
    elif kind == "mts-langevin":
        text = f"mts-langevin {h}/{int(row['inner_steps'])} fs friction {_g(row['friction_per_ps'])}/ps"
    elif kind == "nose-hoover":
        text = f"nose-hoover {h} fs {_g(row['collision_frequency_per_ps'])}/ps"
    else:
        text = f"{kind} {h} fs friction {_g(row['friction_per_ps'])}/ps"
    return text + (f" HMR {_g(row['hmr_da'])} Da" if "hmr_da" in row else "")


def describe(row: dict) -> dict:
    """label; ensemble ("NVE" or "NVT"); evals_per_step (force evaluations; MTS: force-group evaluations, one
    reciprocal-space and inner_steps direct-space); keeps_momentum; heat_bath (a conserved effective energy:
    NVE's total energy, or total + heat-bath energy); family ("symprk" or "openmm")."""
    kind = row["kind"]
    nvt = kind != "symprk" or "collision_time_ps" in row
    evals = {"symprk": lambda: get_method(row["method"]).force_evals,
             "mts-langevin": lambda: 1 + int(row["inner_steps"])}.get(kind, lambda: 1)()
    return {"label": label(row), "ensemble": "NVT" if nvt else "NVE", "evals_per_step": evals,
            "keeps_momentum": kind not in ("langevin", "mts-langevin"),
            "effective_energy": kind in ("symprk", "nose-hoover"), "family": "symprk" if kind == "symprk" else "openmm",
            "hmr": "hmr_da" in row}


def _thermostatted(row, system, temperature, seed):
    """The package's thermostatted integrator, or RowUnavailable when the integrator has no thermostat yet."""
    from ...integrators import SymplecticIntegrator

    try:
        return SymplecticIntegrator(row["step_fs"] * unit.femtoseconds, row["method"], system=system,
                                    temperature=temperature * unit.kelvin,
                                    collision_time=row["collision_time_ps"] * unit.picoseconds, random_seed=seed)
    except TypeError as exc:  # an unexpected keyword: the thermostat is not in this installation
        raise RowUnavailable(f"{UNAVAILABLE_THERMOSTAT} ({exc})") from None
    except ValueError as exc:
        if any(k in str(exc) for k in ("temperature", "collision_time", "random_seed")):
            raise RowUnavailable(f"{UNAVAILABLE_THERMOSTAT} ({exc})") from None
        raise


def make_integrator(row: dict, system: mm.System, temperature: float, seed: int, cutoff_nm: float):
    """An OpenMM integrator for ``row`` on ``system`` (already repartitioned / split in force groups)."""
    kind, h = row["kind"], row["step_fs"] * unit.femtoseconds
    T = temperature * unit.kelvin
    if kind == "symprk":
        if "collision_time_ps" in row:
            return _thermostatted(row, system, temperature, seed)
        from ...integrators import SymplecticIntegrator

        return SymplecticIntegrator(h, row["method"], system=system)
    if kind == "langevin":
        integ = mm.LangevinMiddleIntegrator(T, row["friction_per_ps"] / unit.picosecond, h)
    elif kind == "mts-langevin":
        integ = mm.MTSLangevinIntegrator(T, row["friction_per_ps"] / unit.picosecond, h,
                                         [(1, 1), (0, int(row["inner_steps"]))])
    elif kind == "nose-hoover":
        return mm.NoseHooverIntegrator(T, row["collision_frequency_per_ps"] / unit.picosecond, h)
    else:
        integ = mm.DPDIntegrator(T, row["friction_per_ps"] / unit.picosecond,
                                 row.get("cutoff_nm", cutoff_nm) * unit.nanometer, h)
    integ.setRandomNumberSeed(seed)
    return integ


def _system_for(row, scene):
    """The row's System: HMR repartitioned, and for MTS reciprocal-space PME in force group 1."""
    system = scene.system
    if "hmr_da" in row:
        system = repartition_hydrogen_mass(system, scene.topology, row["hmr_da"])
    if row["kind"] == "mts-langevin":
        if system is scene.system:
            system = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(system))
        for f in system.getForces():
            if isinstance(f, mm.NonbondedForce):
                f.setReciprocalSpaceForceGroup(1)
    return system


def availability(row: dict, scene, temperature: float) -> str | None:
    """None when this installation runs ``row`` on ``scene``; else why not (e.g. UNAVAILABLE_THERMOSTAT ...)."""
    if row["kind"] == "symprk" and "collision_time_ps" in row:
        try:
            _thermostatted(row, scene.system, temperature, 1)
        except RowUnavailable as exc:
            return str(exc)
    return None


def _nonbonded_cutoff(system) -> float:
    for f in system.getForces():
        if isinstance(f, mm.NonbondedForce):
            return f.getCutoffDistance().value_in_unit(unit.nanometer)
    return 1.0


class Engine:
    """One row running from a replica state (x, v) of ``scene`` (a rigid-water box) on the CPU platform.
    ``masses``: the row's masses (HMR changes them; the velocities are carried over by
    :func:`~openmm_symprk.systems.repartition.rigid_velocities_for_masses`)."""

    def __init__(self, scene, x, v, row: dict, temperature: float, seed: int, threads: int = 1):
        self.row, self.info = row, describe(row)
        self.system = _system_for(row, scene)
        self.masses = masses(self.system)
        if "hmr_da" in row:
            v = rigid_velocities_for_masses(x, v, scene.masses(), self.masses, scene.molecules)
        self.integrator = make_integrator(row, self.system, temperature, seed, _nonbonded_cutoff(self.system))
        self.context = mm.Context(self.system, self.integrator, mm.Platform.getPlatformByName("CPU"),
                                  {"Threads": str(threads)})
        self.context.setPositions(x)
        self.context.setVelocities(v)

    def step(self, n: int):
        self.integrator.step(int(n))

    def heat_bath(self) -> float | None:
        """The heat bath's energy (kJ/mol) of an integrator that exposes one, 0 for NVE, None otherwise."""
        if self.info["ensemble"] == "NVE":
            return 0.0
        fn = getattr(self.integrator, "computeHeatBathEnergy", None)
        if fn is None or not self.info["effective_energy"]:
            return None
        e = fn()
        return float(e.value_in_unit(unit.kilojoule_per_mole) if unit.is_quantity(e) else e)

    def sample(self, velocities: bool = True, energy: bool = True):
        """(x nm, v nm/ps or None, potential energy kJ/mol or None) now."""
        import numpy as np

        st = self.context.getState(getPositions=True, getVelocities=velocities, getEnergy=energy)
        x = np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
        v = np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)) \
            if velocities else None
        pe = st.getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole) if energy else None
        return x, v, pe
