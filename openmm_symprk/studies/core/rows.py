"""The one row type of the studies: a configuration that one run uses, written as one line.

A :class:`Row` says who integrates (a catalogue method run by :class:`~openmm_symprk.SymplecticIntegrator`, a rigid
body engine, or one of OpenMM's integrators), the step, the thermostat (kind, target temperature, collision time
or friction, interval and position in the step), hydrogen mass repartitioning, multiple time stepping, the
backend and the random seed.  It builds the integrator for a System (:meth:`Row.build`; a study runs it with
:class:`~.engine.RowEngine`) and knows its label (a study's runs are stored under it:
:func:`~.store.run_key`), its force (group) evaluations per step (:meth:`Row.evals_per_step`: the resolved
method's ``force_evals``, :class:`openmm_symprk.methods.resolved.ResolvedMethod`; for OpenMM's integrators one table,
:data:`OPENMM_KINDS`), whether its state velocities are on-step or lag half a step (leapfrog), whether it has a
heat-bath energy and whether it keeps the total momentum.

One grammar of labels, :meth:`Row.parse` reading what :attr:`Row.label` writes::

    WHO[/INNER] [H fs | H/N fs] [SVR TAU ps | friction G/ps | collision NU/ps | NU/ps] [cutoff C nm] [every K]
        [ends | middle | auto] [T K] [exact-momentum] [HMR M Da] [native | custom] [seed S]

* WHO: a catalogue method (``verlet``, ``omelyan-2``, ...; aliases resolved), ``rigid:<method>`` (the molecules
  as rigid bodies, :class:`~openmm_symprk.rigid.bodies.RigidBodies`), or OpenMM's ``openmm-verlet``
  (VerletIntegrator), ``langevin`` (LangevinMiddleIntegrator), ``nose-hoover`` (NoseHooverIntegrator), ``dpd``
  (DPDIntegrator), ``openmm-mts`` (MTSIntegrator) or ``mts-langevin`` (MTSLangevinIntegrator);
* ``H/N fs``: multiple time stepping, force group 1 (the scenes put PME's reciprocal space there) once per step of
  H fs, group 0 N times; ``/INNER`` names the inner levels' method (:func:`openmm_symprk.methods.resolve`);
* ``SVR TAU ps``: this package's stochastic velocity rescaling with collision time TAU, every K steps, at the
  ``ends`` of the step or in its ``middle`` (``auto``: the method's choice, :mod:`openmm_symprk.methods.placement`).
  **A row without a position word runs the thermostat at the ends** (:data:`ROW_POSITION`, what the stored results
  of such rows were run with, and what their labels, the keys of those results, mean), where
  :class:`~openmm_symprk.SymplecticIntegrator`'s default is ``auto`` (verlet: the middle); the label leaves
  ``ends`` out and writes any other placement.  OpenMM's Langevin kinds take a friction
  (default 1/ps), Nose-Hoover a collision frequency (default 1/ps), DPD a cutoff (default: the System's
  nonbonded cutoff); T is the target temperature (default 300 K).

The earlier grammars read as the same rows: the bench's ``<method>[/<inner>]@mts<n>``, ``openmm-mts<n>``,
``openmm-langevin`` (with its step given apart), ``symprk nvt drift --rows`` ``method@step_fs``, ``symprk
equipartition --rows`` ``method:step_fs``, and the
OpenMM names ``openmm-nosehoover``, ``openmm-dpd``, ``openmm-mtslangevin``, ``nosehoover``.
"""
from __future__ import annotations

import dataclasses
from fractions import Fraction
import math
import re
import warnings
from dataclasses import dataclass

from ...methods.placement import POSITIONS
from ...support.errors import InputError

__all__ = ["Row", "OPENMM_KINDS", "ROW_POSITION", "split_groups"]

#: OpenMM's integrators a row may name: who -> thermostat kind ("" for NVE); each evaluates the forces (all groups)
#: once per step, its multiple-time-step kinds (openmm-mts, mts-langevin) 1 + N times (:meth:`Row.evals_per_step`).
OPENMM_KINDS = {"openmm-verlet": "", "openmm-mts": "", "langevin": "langevin", "mts-langevin": "langevin",
                "nose-hoover": "nose-hoover", "dpd": "dpd"}
#: Other spellings of OpenMM's integrators (earlier grammars).
ALIASES = {"openmm-langevin": "langevin", "openmm-nosehoover": "nose-hoover", "nosehoover": "nose-hoover",
           "openmm-dpd": "dpd", "openmm-mtslangevin": "mts-langevin"}
#: A row's thermostat position when its label names none: the ends (not the integrator's default, "auto"; one of
#: :data:`openmm_symprk.methods.placement.POSITIONS`, which lists the placements).
ROW_POSITION = "ends"
#: OpenMM integrators whose State velocities lag half a step behind the positions.
LEAPFROG = ("openmm-verlet", "langevin", "dpd")
#: ...and those that do not keep the total momentum (per-particle friction and noise).
NO_MOMENTUM = ("langevin", "mts-langevin")
RIGID_PREFIX = "rigid:"
#: The label's words ``KEY VALUE UNIT``: KEY -> (the field it sets, UNIT).
_QUANTITIES = {"SVR": ("tau_ps", "ps"), "cutoff": ("cutoff_nm", "nm"), "T": ("temperature", "K"),
               "HMR": ("hmr_da", "Da")}
_NUMBER = r"[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?"
_OLD_MTS = re.compile(r"^(?P<who>[^/@\s]+)(?:/(?P<inner>[^@\s]+))?@mts(?P<n>[0-9]+)$")
_OLD_OPENMM_MTS = re.compile(r"^openmm-mts(?P<n>[0-9]+)$")
_OLD_AT_STEP = re.compile(rf"^(?P<who>[^@\s]+)[@:](?P<h>{_NUMBER})$")


def split_groups(inner_steps: int) -> list:
    """The ``groups=`` of a row with multiple time stepping: the slow group 1 once per step, group 0 ``n`` times."""
    return [(1, 1), (0, int(inner_steps))]


def _g(x) -> str:
    """A number as a label writes it: short (%g) where that reads back exactly, else every digit (a bisected step)."""
    short = f"{float(x):g}"
    return short if float(short) == float(x) else repr(float(x))


@dataclass(frozen=True)
class Row:
    """One configuration a study runs (see the module docstring)."""

    who: str  # catalogue method (canonical name), "rigid:<method>", or a key of OPENMM_KINDS
    step_fs: float
    inner: str = ""  # multiple time stepping: the inner levels' method ("": the outer one)
    mts: int = 0  # multiple time stepping: substeps of group 0 per step (0: none)
    tau_ps: float | None = None  # this package's thermostat: collision time (None: NVE)
    friction_per_ps: float | None = None  # OpenMM's Langevin kinds and DPD
    collision_per_ps: float | None = None  # OpenMM's Nose-Hoover
    cutoff_nm: float | None = None  # DPD (None: the System's nonbonded cutoff)
    every: int = 1  # thermostat_interval
    position: str = ROW_POSITION  # thermostat_position
    temperature: float = 300.0  # K, the thermostat's target
    exact_momentum: bool = False
    hmr_da: float | None = None  # hydrogen mass repartitioning (the System is repartitioned by system_for)
    backend: str = "auto"  # "auto", "native" or "custom"
    seed: int = 1

    def __post_init__(self):
        who = ALIASES.get(self.who, self.who)
        if who not in OPENMM_KINDS:
            from ...methods.catalogue import get_method

            name = who[len(RIGID_PREFIX):] if who.startswith(RIGID_PREFIX) else who
            try:
                canonical = get_method(name).name
            except InputError as exc:
                raise InputError(f"row {self.who!r}: {exc} Rows also name OpenMM's integrators: "
                                 f"{', '.join(OPENMM_KINDS)}") from None
            who = RIGID_PREFIX + canonical if who.startswith(RIGID_PREFIX) else canonical
        object.__setattr__(self, "who", who)
        if self.inner:
            from ...methods.catalogue import get_method

            object.__setattr__(self, "inner", get_method(self.inner).name)
        if not (isinstance(self.step_fs, (int, float)) and not isinstance(self.step_fs, bool) and self.step_fs > 0
                and math.isfinite(self.step_fs)):
            raise InputError(f"row {who!r}: the step must be a positive number of fs, got {self.step_fs!r}")
        object.__setattr__(self, "step_fs", float(self.step_fs))
        kind = OPENMM_KINDS.get(who)
        if who in ("openmm-mts", "mts-langevin") and not self.mts:
            raise InputError(f"row {who!r}: give the inner steps of group 0 as H/N fs, e.g. '{who} 4/2 fs'")
        if self.mts and (self.is_rigid or who in ("openmm-verlet", "langevin", "nose-hoover", "dpd")):
            raise InputError(f"row {who!r}: no multiple time stepping (H/N fs) for this integrator; rows with it are "
                             f"catalogue methods, openmm-mts and mts-langevin")
        if self.inner and not self.mts:
            raise InputError(f"row {who}/{self.inner}: an inner method needs multiple time stepping (H/N fs)")
        if kind == "langevin" or kind == "dpd":
            object.__setattr__(self, "friction_per_ps", 1.0 if self.friction_per_ps is None
                               else float(self.friction_per_ps))
        if kind == "nose-hoover":
            object.__setattr__(self, "collision_per_ps", 1.0 if self.collision_per_ps is None
                               else float(self.collision_per_ps))
        wrong = [(name, value) for name, value, ok in (
            ("SVR", self.tau_ps, self.is_ours and not self.is_rigid),
            ("friction", self.friction_per_ps, kind in ("langevin", "dpd")),
            ("collision", self.collision_per_ps, kind == "nose-hoover"),
            ("cutoff", self.cutoff_nm, kind == "dpd")) if value is not None and not ok]
        if wrong:
            raise InputError(f"row {who!r}: {wrong[0][0]} does not apply to it")
        for name in ("tau_ps", "friction_per_ps", "collision_per_ps", "cutoff_nm", "hmr_da"):
            value = getattr(self, name)
            if value is not None and not (float(value) > 0 and math.isfinite(float(value))):
                raise InputError(f"row {who!r}: {name} must be a positive number, got {value!r}")
        if self.position not in POSITIONS:
            raise InputError(f"row {who!r}: thermostat position {self.position!r}; known: {', '.join(POSITIONS)}")
        if (self.every != 1 or self.position != ROW_POSITION) and self.tau_ps is None:
            raise InputError(f"row {who!r}: 'every' and the thermostat position need a thermostat (SVR TAU ps)")
        if int(self.every) != self.every or self.every < 1:
            raise InputError(f"row {who!r}: every must be a whole number >= 1, got {self.every!r}")
        if self.backend not in ("auto", "native", "custom"):
            raise InputError(f"row {who!r}: backend {self.backend!r}; known: auto, native, custom")
        if (self.backend != "auto" or self.exact_momentum) and not self.is_ours:
            raise InputError(f"row {who!r}: backend and exact-momentum are options of this package's integrators")

    # -- what the row is ------------------------------------------------------------------------------------------
    @property
    def is_ours(self) -> bool:
        """This package's integrator (or rigid-body engine), not one of OpenMM's."""
        return self.who not in OPENMM_KINDS

    @property
    def is_rigid(self) -> bool:
        return self.who.startswith(RIGID_PREFIX)

    @property
    def method(self) -> str:
        """The catalogue method ('' for OpenMM's integrators)."""
        return self.who[len(RIGID_PREFIX):] if self.is_rigid else ("" if not self.is_ours else self.who)

    @property
    def thermostat(self) -> str:
        """"" (NVE), "svr", "langevin", "nose-hoover" or "dpd"."""
        if self.is_ours:
            return "svr" if self.tau_ps is not None else ""
        return OPENMM_KINDS[self.who]

    @property
    def ensemble(self) -> str:
        return "NVT" if self.thermostat else "NVE"

    @property
    def h_ps(self) -> float:
        return self.step_fs * 1e-3

    @property
    def velocity_lag(self) -> tuple:
        """The kicks a State's velocities lack to be at the positions' time, as ((fraction of the step, force groups or
        None for all), ...): half a kick of all forces for OpenMM's leapfrog integrators; for this package's thermostat
        in the middle of the step, the step's closing kicks (its step runs from them, so that the State holds the
        thermostat point's velocities: half of each opening kick, which carries both); () where the State's velocities
        are on-step (NVE, the ends placement, a step that begins with a drift)."""
        if self.who in LEAPFROG:
            return ((Fraction(1, 2), None),)
        if self.thermostat != "svr" or self.is_rigid:
            return ()
        from ...methods.resolved import SubstepKind

        r = self.resolved(thermostat_position=self.position)
        if r.thermostat_position != "middle":
            return ()
        lag = []
        for sub in r.substeps:
            if sub.kind != SubstepKind.KICK:
                break
            lag.append((Fraction(sub.coefficient) / 2, sub.groups))
        return tuple(lag)

    @property
    def leapfrog(self) -> bool:
        """Whether the State velocities lag behind the positions (:attr:`velocity_lag`): OpenMM's leapfrog integrators,
        and this package's middle placement, whose step runs from its closing kicks, as LangevinMiddleIntegrator's
        does."""
        return bool(self.velocity_lag)

    @property
    def has_heat_bath(self) -> bool:
        """Whether the integrator reports a heat-bath energy (``computeHeatBathEnergy``), so that total +
        heat-bath energy is conserved but for the integrator's error (NVE rows of this package: zero)."""
        return (self.is_ours and not self.is_rigid) or self.who == "nose-hoover"

    @property
    def conserves_effective_energy(self) -> bool:
        """NVE, or a thermostat with a heat-bath energy."""
        return self.ensemble == "NVE" or self.has_heat_bath

    @property
    def keeps_momentum(self) -> bool:
        """Whether the total momentum is kept (OpenMM's Langevin integrators apply per-particle friction)."""
        return self.who not in NO_MOMENTUM

    def resolved(self, constraints: bool | None = None, thermostat_position: str | None = None):
        """The method as it runs (:func:`openmm_symprk.methods.resolve`; with ``thermostat_position``, its thermostat
        placed there); ValueError for OpenMM's integrators."""
        from ...methods.resolved import resolve

        if not self.is_ours:
            raise InputError(f"row {self.label!r}: OpenMM's integrators have no resolved method")
        if self.mts:
            return resolve(self.method, constraints, groups=split_groups(self.mts), inner_method=self.inner or None,
                           thermostat_position=thermostat_position)
        return resolve(self.method, constraints, thermostat_position=thermostat_position)

    def require_kick_drift(self, where: str):
        """ValueError unless this package's method of the row is a kick/drift splitting or composition, which is what
        ``where`` runs (constraints keep RATTLE; the rigid-body engine takes no other); OpenMM's rows pass."""
        from ...methods.catalogue import get_method

        m = get_method(self.method) if self.is_ours else None
        if m is not None and not m.is_splitting:
            raise InputError(f"row {self.label!r}: {m.name} is a {m.family} method; {where} runs kick/drift splittings "
                             f"and compositions only, e.g. verlet, omelyan-2, pefrl, yoshida-4 (symprk methods lists "
                             f"their families)")

    def evals_per_step(self, constraints: bool | None = None) -> int:
        """Force (group) evaluations per step: from the resolved method; OpenMM's MTS: 1 + N, otherwise 1."""
        if self.is_ours:
            return int(self.resolved(constraints).force_evals)
        return 1 + self.mts if self.mts else 1

    def evals_per_ps(self, constraints: bool | None = None) -> float:
        return self.evals_per_step(constraints) / self.h_ps

    def steps_for(self, fs: float) -> int:
        """The whole number of this row's steps closest to ``fs`` femtoseconds (at least 1): a sampling interval."""
        return max(1, int(round(float(fs) / self.step_fs)))

    # -- the label -----------------------------------------------------------------------------------------------
    @property
    def label(self) -> str:
        """The row as one line, read back by :meth:`parse` (defaults left out)."""
        who = self.who + (f"/{self.inner}" if self.inner else "")
        parts = [who, f"{_g(self.step_fs)}/{self.mts} fs" if self.mts else f"{_g(self.step_fs)} fs"]
        if self.tau_ps is not None:
            parts.append(f"SVR {_g(self.tau_ps)} ps")
        if self.friction_per_ps is not None:
            parts.append(f"friction {_g(self.friction_per_ps)}/ps")
        if self.collision_per_ps is not None:
            parts.append(f"{_g(self.collision_per_ps)}/ps")
        if self.cutoff_nm is not None:
            parts.append(f"cutoff {_g(self.cutoff_nm)} nm")
        if self.every != 1:
            parts.append(f"every {int(self.every)}")
        if self.position != ROW_POSITION:
            parts.append(self.position)
        if self.temperature != 300.0:
            parts.append(f"T {_g(self.temperature)} K")
        if self.exact_momentum:
            parts.append("exact-momentum")
        if self.hmr_da is not None:
            parts.append(f"HMR {_g(self.hmr_da)} Da")
        if self.backend != "auto":
            parts.append(self.backend)
        if self.seed != 1:
            parts.append(f"seed {int(self.seed)}")
        return " ".join(parts)

    def __str__(self) -> str:
        return self.label

    def replace(self, **changes) -> "Row":
        return dataclasses.replace(self, **changes)

    @classmethod
    def parse(cls, text: str, step_fs: float | None = None, **defaults) -> "Row":
        """The row a label names (see the module docstring); ``step_fs`` for a label without a step (the bench's
        rows name the step apart); ``defaults``: fields the label does not set (e.g. ``temperature``).
        ValueError naming the part not understood and the grammar."""
        if not isinstance(text, str) or not text.strip():
            raise InputError(f"row {text!r}: empty; write e.g. 'verlet 2 fs' or 'omelyan-2 4 fs SVR 0.1 ps'")
        words = text.split()
        fields = dict(defaults)
        who = words.pop(0)
        m = _OLD_MTS.match(who) or _OLD_OPENMM_MTS.match(who)
        if m:  # the bench's <method>[/<inner>]@mts<n> and openmm-mts<n>
            if int(m["n"]) < 1:
                raise InputError(f"row {text!r}: the number of inner steps must be >= 1")
            fields["mts"] = int(m["n"])
            who = m.groupdict().get("who") or "openmm-mts"
            if m.groupdict().get("inner"):
                fields["inner"] = m["inner"]
        elif _OLD_AT_STEP.match(who):  # symprk nvt drift --rows method@step_fs, equipartition --rows method:step_fs
            m = _OLD_AT_STEP.match(who)
            who, fields["step_fs"] = m["who"], float(m["h"])
        elif "/" in who:
            who, fields["inner"] = who.split("/", 1)
        if step_fs is not None:
            fields["step_fs"] = float(step_fs)

        def number(word, what):
            try:
                value = float(word)
            except (TypeError, ValueError):
                raise InputError(f"row {text!r}: {what} needs a number, got {word!r}") from None
            return value

        i = 0
        try:
            while i < len(words):
                w = words[i]
                nxt = words[i + 1] if i + 1 < len(words) else None
                if nxt == "fs":
                    h, _, n = w.partition("/")
                    fields["step_fs"] = number(h, "the step")
                    if n:
                        fields["mts"] = int(number(n, "the inner steps"))
                    i += 2
                elif w in _QUANTITIES and words[i + 2:i + 3] == [_QUANTITIES[w][1]]:
                    fields[_QUANTITIES[w][0]] = number(nxt, w)
                    i += 3
                elif w in ("friction", "collision") and nxt and nxt.endswith("/ps"):
                    fields["friction_per_ps" if w == "friction" else "collision_per_ps"] = number(nxt[:-3], w)
                    i += 2
                elif w.endswith("/ps") and re.fullmatch(_NUMBER, w[:-3]):
                    fields["collision_per_ps"] = float(w[:-3])
                    i += 1
                elif w in ("every", "seed") and nxt:
                    fields[w] = int(number(nxt, w))
                    i += 2
                elif w in POSITIONS:
                    fields["position"] = w
                    i += 1
                elif w == "exact-momentum":
                    fields["exact_momentum"] = True
                    i += 1
                elif w in ("native", "custom"):
                    fields["backend"] = w
                    i += 1
                else:
                    raise InputError(f"row {text!r}: {' '.join(words[i:])!r} not understood")
        except InputError as exc:
            raise InputError(f"{exc}; a row reads WHO[/INNER] [H fs | H/N fs] [SVR TAU ps | friction G/ps | "
                             f"collision NU/ps] [cutoff C nm] [every K] [{' | '.join(POSITIONS)}; none: "
                             f"{ROW_POSITION}] [T K] [exact-momentum] [HMR M Da] [native|custom] [seed S]") from None
        if "step_fs" not in fields:
            raise InputError(f"row {text!r}: no step; write e.g. '{who} 2 fs'")
        if fields.get("collision_per_ps") is not None and ALIASES.get(who, who) in ("langevin", "mts-langevin", "dpd"):
            fields["friction_per_ps"] = fields.pop("collision_per_ps")
        return cls(who, **fields)

    # -- running it ------------------------------------------------------------------------------------------------
    def system_for(self, system, topology=None):
        """The System this row runs: ``system`` itself, or a copy with the hydrogen masses repartitioned
        (``topology`` needed) and, for multiple time stepping on a System whose forces are all in one group, PME's
        reciprocal space moved to group 1 (:func:`openmm_symprk.systems.forcegroups.split_forces`)."""
        import openmm as mm

        out = system
        if self.hmr_da is not None:
            from ...systems.repartition import repartition_hydrogen_mass

            if topology is None:
                raise InputError(f"row {self.label!r}: HMR needs the System's topology")
            out = repartition_hydrogen_mass(out, topology, self.hmr_da)
        if self.mts:
            from ...systems.forcegroups import force_groups, split_forces

            if set(force_groups(out)) <= {0}:
                out = mm.XmlSerializer.clone(out) if out is system else out
                split_forces(out, slow="reciprocal", substeps=self.mts)
        return out

    def build(self, system, seed: int | None = None, constraint_tolerance: float | None = None, quiet: bool = True):
        """The row's integrator for ``system`` (already :meth:`system_for` the row).  ``seed``: the random seed of
        a stochastic row (default the row's own); ``quiet``: no warnings (e.g. the periodic box's
        ConservationWarning, which a study knows).  Raises ConstraintSupportError for a method that cannot run
        a System with constraints; TypeError (an unknown option) where this installation lacks an option the
        row needs."""
        import openmm as mm
        import openmm.unit as unit

        if self.is_rigid:
            raise InputError(f"row {self.label!r}: rigid bodies run as RigidBodies (openmm_symprk.rigid), not as an "
                             f"OpenMM integrator")
        seed = self.seed if seed is None else int(seed)
        h = self.h_ps * unit.picoseconds
        T = self.temperature * unit.kelvin
        with warnings.catch_warnings():
            if quiet:
                warnings.simplefilter("ignore")
            if self.is_ours:
                ig = self._ours(system, h, seed)
            elif self.who == "openmm-verlet":
                ig = mm.VerletIntegrator(h)
            elif self.who == "openmm-mts":
                from openmm.mtsintegrator import MTSIntegrator

                ig = MTSIntegrator(h, split_groups(self.mts))
            elif self.who == "langevin":
                ig = mm.LangevinMiddleIntegrator(T, self.friction_per_ps / unit.picosecond, h)
            elif self.who == "mts-langevin":
                ig = mm.MTSLangevinIntegrator(T, self.friction_per_ps / unit.picosecond, h, split_groups(self.mts))
            elif self.who == "nose-hoover":
                ig = mm.NoseHooverIntegrator(T, self.collision_per_ps / unit.picosecond, h)
            else:  # dpd
                cutoff = self.cutoff_nm if self.cutoff_nm is not None else _nonbonded_cutoff(system)
                ig = mm.DPDIntegrator(T, self.friction_per_ps / unit.picosecond, cutoff * unit.nanometer, h)
            if not self.is_ours and hasattr(ig, "setRandomNumberSeed"):
                ig.setRandomNumberSeed(seed)
        if constraint_tolerance is not None:
            ig.setConstraintTolerance(float(constraint_tolerance))
        return ig

    def _ours(self, system, h, seed):
        from ...integrators import SymplecticIntegrator
        from ...methods.catalogue import get_method

        options = {"backend": self.backend}
        if not get_method(self.method).symplectic:
            options["allow_nonsymplectic"] = True
        if self.mts:
            options.update(groups=split_groups(self.mts), inner_method=self.inner or None)
        if self.exact_momentum:
            options["exact_momentum"] = True
        if self.tau_ps is not None:
            options.update(temperature=self.temperature, collision_time=self.tau_ps, random_seed=seed)
            if self.every != 1:
                options["thermostat_interval"] = int(self.every)
            options["thermostat_position"] = self.position  # always: ROW_POSITION is not the integrator's default
        return SymplecticIntegrator(h, self.method, system=system, **options)


def _nonbonded_cutoff(system) -> float:
    """The nonbonded cutoff of ``system`` in nm (1 nm without a NonbondedForce): DPD's default cutoff."""
    import openmm as mm
    import openmm.unit as unit

    for f in system.getForces():
        if isinstance(f, mm.NonbondedForce):
            return f.getCutoffDistance().value_in_unit(unit.nanometer)
    return 1.0
