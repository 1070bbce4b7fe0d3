"""Compile a catalogue method, splitting or PRK tableau into an openmm.CustomIntegrator program.

One compiler for everything (docs/openmm_notes.md explains each rule):

* Every program starts with the same header: ``symprk_signature`` (global 0, a hash of the whole
  program: a checkpoint restores globals by position, so global 0 tells whose checkpoint was loaded),
  the step counter, the blow-up record, and a one-time probe of the Context (run in the first step:
  whether its System has constraints, by projecting the velocity field v = x with ConstrainVelocities).
* Splittings and compositions: kick ``v = v + b*dt*f/m``, drift ``x = x + a*dt*v``.  Adjacent pieces
  are already merged by :class:`~openmm_symprk.methods.splitting.Splitting`; the forces of a closing kick
  stay cached and serve the next step's opening kick, so a step costs exactly
  ``Splitting.force_evaluations()`` evaluations in steady state.
* Constraints (RATTLE): after every drift ``ConstrainPositions`` and ``v += (x - x_unconstrained)/(a*dt)``,
  nothing references forces between a drift and its ConstrainPositions, and velocities are projected
  once at the end of the step.  The velocity projections RATTLE makes after inner kicks are absorbed
  exactly by the next drift's position projection, whose multipliers act along the same bond vectors,
  so they are omitted (each one would cost a constraint solve).  The same steps are emitted for a System
  with virtual sites and no constraints: OpenMM's Common platforms place virtual sites only inside
  ConstrainPositions.
* General tableaux (explicit non-splitting, implicit) for unconstrained systems: stage values live in
  per-DOF variables; implicit stages are solved by fixed-point iteration in a single while block.
* Optional exact momentum (:mod:`.projection`): projected kicks, and the round-off net momentum and
  torque of every constraint projection removed (after each RATTLE drift and after the end-of-step
  velocity projection), with the System's masses in double.
* The blow-up check: the first step at which some velocity is NaN or infinite (or faster than a given
  speed) is kept in a global variable.
* Optional thermostat (:mod:`.thermostat_program`, only with ``thermostat=`` settings: without them not one
  computation or variable differs from the NVE program): each THERMOSTAT sub-step of the resolved method is an
  event over its fraction of the interval, in an ``if`` block on the step counter for the step of the interval its
  phase names when the interval n > 1.  Where the events sit is the resolved method's (resolve with
  ``thermostat_position``); the program runs its sub-steps in order.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np
import openmm as mm

from ..methods.resolved import EventPhase, ResolvedMethod, SubstepKind
from .options import IntegratorOptions

#: Global variables every compiled program has, in this order (read by the integrator classes).
SIGNATURE_VAR = "symprk_signature"
STEP_VAR = "symprk_step"
BAD_VAR = "symprk_blowup_step"
PROBED_VAR = "symprk_probed"
PROBE_CONSTRAINTS_VAR = "symprk_probe_constraints"
#: A per-DOF variable the program never sets from Python: its length after binding is the Context's
#: particle count.
PROBE_PER_DOF = "symprk_probe"
NONCONV_VAR = "symprk_nonconverged"
ITER_VAR = "symprk_iterations"
#: Squared speed limit used when only NaN, infinity and absurd speeds (above 1e15 nm/ps) count as a blow-up.  It must
#: be a float in single precision too: OpenMM writes the literal as 1e30f there, and CUDA refuses a float literal out
#: of range (1e300f: "floating constant is out of range"; OpenCL read it as infinity).
NONFINITE_LIMIT2 = "1e30"
#: The literal the guard had before (1e300): :func:`program_signature` hashes the guard as written then, so a
#: checkpoint saved before the change still loads (the state and the step's arithmetic are the same).
_SIGNED_LIMIT2 = "1e300"


@dataclass(frozen=True)
class ProgramInfo:
    """The facts of a compiled program beyond the method it runs (the form of the step, its force evaluations, its
    levels are the method's: :attr:`method`)."""

    method: ResolvedMethod  #: the method compiled
    rattle: bool  #: RATTLE steps emitted: the method keeps constraints, or virtual sites need them (compile_program)
    signature: int  #: the value of global 0 (see the module docstring); the plugin's program signature (native)
    notes: tuple = ()  #: lines describe() prints

    @property
    def force_evals(self) -> int:
        """The method's force evaluations per step (``method.force_evals``)."""
        return self.method.force_evals


def program_signature(integrator: mm.CustomIntegrator) -> int:
    """A 52-bit hash of the program (every computation and variable name), exact as a float64."""
    h = hashlib.sha1()
    guard = f"step({NONFINITE_LIMIT2} - v*v)"
    for i in range(integrator.getNumComputations()):
        kind, var, expr = integrator.getComputationStep(i)
        h.update(f"{kind}|{var}|{expr.replace(guard, f'step({_SIGNED_LIMIT2} - v*v)')};".encode())
    for i in range(integrator.getNumGlobalVariables()):
        h.update(f"g:{integrator.getGlobalVariableName(i)};".encode())
    for i in range(integrator.getNumPerDofVariables()):
        h.update(f"d:{integrator.getPerDofVariableName(i)};".encode())
    return int.from_bytes(h.digest()[:8], "big") >> 12


def _num(c) -> str:
    """A coefficient as an expression literal that round-trips a float64 exactly."""
    return repr(float(c))


class _Emitter:
    """Appends computations to a CustomIntegrator, with the shared header, kick and drift rules."""

    def __init__(self, integrator: mm.CustomIntegrator, constraints: bool, exact_momentum: bool, thermostat=None):
        if integrator.getNumComputations() or integrator.getNumGlobalVariables() or integrator.getNumPerDofVariables():
            raise ValueError("compile into an empty CustomIntegrator: this one already has a program")
        self.ig = integrator
        self.thermostat = thermostat
        self.constraints = constraints
        self.exact_momentum = exact_momentum
        self._vars: set = set()
        for name in (SIGNATURE_VAR, STEP_VAR, BAD_VAR, PROBED_VAR, PROBE_CONSTRAINTS_VAR):
            self.glob(name)
        self.per_dof(PROBE_PER_DOF)
        if exact_momentum:
            from .projection import add_projection_variables

            add_projection_variables(integrator)
        if thermostat is not None:
            from .thermostat_program import add_variables

            add_variables(integrator, thermostat)
        integrator.addUpdateContextState()
        self._probe()

    def thermostat_event(self, sub, name: str):
        """A THERMOSTAT sub-step: its velocity projection where flagged (every step), then the event over its
        fraction of the interval, in an ``if`` block for the step of the interval its phase names when the
        thermostat acts every n > 1 steps (the step counter counts from 0 and is advanced at the end of the step)."""
        from .thermostat_program import emit_event

        if self.thermostat is None:
            raise ValueError(f"{name}: the method was resolved with thermostat events, but the options have no "
                             f"thermostat (temperature=)")
        if sub.project_before:
            self.project_velocities()
        n = int(self.thermostat.interval)
        if n > 1:
            self.ig.beginIfBlock(_in_step_of_interval(sub.phase, n))
        emit_event(self.ig, self.thermostat, float(sub.coefficient))
        if n > 1:
            self.ig.endBlock()

    def _probe(self):
        """Once per Context (first step): does its System have constraints?  ConstrainVelocities changes the
        velocity field v = x exactly when some constraint exists (the relative velocity of a constrained pair
        along its bond is then |r|^2 > 0).  Massless particles are left out of the sum."""
        ig = self.ig
        ig.beginIfBlock(f"{PROBED_VAR} < 0.5")
        ig.addComputePerDof(PROBE_PER_DOF, "v")
        ig.addComputePerDof("v", "x")
        ig.addConstrainVelocities()
        ig.addComputeSum(PROBE_CONSTRAINTS_VAR, "select(m, (v - x)^2, 0)")
        ig.addComputePerDof("v", PROBE_PER_DOF)
        ig.addComputeGlobal(PROBED_VAR, "1")
        ig.endBlock()

    def per_dof(self, name: str):
        if name not in self._vars:
            self.ig.addPerDofVariable(name, 0.0)
            self._vars.add(name)

    def glob(self, name: str, value: float = 0.0):
        if name not in self._vars:
            self.ig.addGlobalVariable(name, value)
            self._vars.add(name)

    def acceleration(self, target: str, force: str = "f") -> str:
        """Store the (optionally momentum-projected) acceleration ``force``/m in per-DOF ``target``."""
        self.per_dof(target)
        if self.exact_momentum:
            from .projection import emit_projected_acceleration

            emit_projected_acceleration(self.ig, target, force=force)
        else:
            self.ig.addComputePerDof(target, f"{force}/m")
        return target

    def kick(self, c, groups=None):
        """v += c*dt*F/m with the forces of ``groups`` (None: all), one computation per group (a CustomIntegrator
        computation may reference one force group only)."""
        for force in (["f"] if groups is None else [f"f{g}" for g in groups]):
            if self.exact_momentum:
                a = self.acceleration("symprk_a", force)
                self.ig.addComputePerDof("v", f"v + {_num(c)}*dt*{a}")
            else:
                self.ig.addComputePerDof("v", f"v + {_num(c)}*dt*{force}/m")

    def project_velocities(self):
        """A velocity projection inside a step (a drift or a thermostat event flagged ``project_before``, see
        :func:`openmm_symprk.methods.resolved.projected_drifts`)."""
        if not self.constraints:
            return
        if self.exact_momentum:
            from .projection import emit_constrain_velocities

            emit_constrain_velocities(self.ig)
        else:
            self.ig.addConstrainVelocities()

    def drift(self, c):
        self.ig.addComputePerDof("x", f"x + {_num(c)}*dt*v")
        if self.constraints:
            self.per_dof("symprk_xu")
            self.ig.addComputePerDof("symprk_xu", "x")
            self.ig.addConstrainPositions()
            self.ig.addComputePerDof("v", f"v + (x - symprk_xu)/({_num(c)}*dt)")
            if self.exact_momentum:
                from .projection import emit_drift_restoration

                emit_drift_restoration(self.ig, "symprk_xu", f"{_num(c)}*dt")

    def close_rattle(self):
        """RATTLE's closing velocity projection, after the last kick or drift (constraints only)."""
        if self.constraints and self.exact_momentum:
            from .projection import emit_constrain_velocities

            emit_constrain_velocities(self.ig)
        elif self.constraints:
            self.ig.addConstrainVelocities()

    def finish(self, check_finite: bool, max_speed: float = 0.0) -> int:
        """End the step (counter, blow-up check); set and return the signature."""
        self.ig.addComputeGlobal(STEP_VAR, f"{STEP_VAR} + 1")
        if check_finite:
            # Count the degrees of freedom whose speed is NaN (every comparison with NaN is false, so
            # step(NaN) = 0), infinite or beyond max_speed, and record the first step where any is found.
            # (Lepton would simplify a NaN self-test s - s to 0.)
            limit2 = repr(float(max_speed) ** 2) if max_speed else NONFINITE_LIMIT2
            self.glob("symprk_bad_dofs")
            self.ig.addComputeSum("symprk_bad_dofs", f"1 - step({limit2} - v*v)")
            self.ig.addComputeGlobal(
                BAD_VAR, f"select({BAD_VAR}, {BAD_VAR}, step(symprk_bad_dofs - 0.5)*{STEP_VAR})")
        signature = program_signature(self.ig)
        self.ig.setGlobalVariableByName(SIGNATURE_VAR, float(signature))
        return signature


def _compile_splitting(integrator, method: ResolvedMethod, constraints: bool, options: IntegratorOptions,
                       thermostat=None) -> ProgramInfo:
    """Emit the program of a resolved kick/drift method: its sub-steps as they run, with a velocity projection
    before every drift flagged for one.  ``constraints``: emit the RATTLE steps (the System has constraints, or
    virtual sites that only ConstrainPositions places on the Common platforms)."""
    em = _Emitter(integrator, constraints, options.exact_momentum, thermostat)
    last = max(i for i, sub in enumerate(method.substeps) if sub.is_kick_or_drift)
    for i, sub in enumerate(method.substeps):
        c = float(sub.coefficient)
        if sub.kind == SubstepKind.THERMOSTAT:
            em.thermostat_event(sub, method.name)
        elif sub.kind == SubstepKind.DRIFT:
            if sub.project_before:
                em.project_velocities()
            em.drift(c)
        else:
            em.kick(c, sub.groups)
        if i == last:
            em.close_rattle()
    return ProgramInfo(method, constraints, em.finish(options.check_finite, options.max_speed))


def _in_step_of_interval(phase: EventPhase, n: int) -> str:
    """The condition (on the step counter, which counts steps from 0) that holds in the step of every interval of
    ``n`` steps that ``phase`` names (:meth:`EventPhase.step_in`)."""
    if phase is EventPhase.FIRST:
        return f"{STEP_VAR} - {n}*floor(({STEP_VAR})/{n}) < 0.5"
    if phase is EventPhase.LAST:  # the counter is advanced after the event: this step's number is counter + 1
        return f"{STEP_VAR} + 1 - {n}*floor(({STEP_VAR} + 1)/{n}) < 0.5"
    return f"abs({STEP_VAR} - {n}*floor({STEP_VAR}/{n}) - {phase.step_in(n)}) < 0.5"


def _lincomb(base: str, coeffs, names) -> str:
    terms = [f"{_num(a)}*{n}" for a, n in zip(coeffs, names) if a != 0]
    if not terms:
        return base
    return f"{base} + dt*({' + '.join(terms)})"


def _compile_tableau(integrator, method: ResolvedMethod, options: IntegratorOptions,
                     place_virtual_sites=False, thermostat=None) -> ProgramInfo:
    """Emit the program of a general PRK pair (unconstrained systems only).

    Per-DOF variables: symprk_x0/v0 (start of step), symprk_k<i> (stage accelerations F(Q_i)/m),
    symprk_p<i> (stage velocities P_i), symprk_q<i> (implicit stage positions).  ``place_virtual_sites``
    ends the step with a ConstrainPositions (which only places virtual sites in an unconstrained System)."""
    em = _Emitter(integrator, False, options.exact_momentum, thermostat)
    # the thermostat's events around the stages: those of the first step of its interval before them, the rest after
    before = [sub for sub in method.substeps if sub.phase is EventPhase.FIRST]
    for sub in before:
        em.thermostat_event(sub, method.name)
    tab = method.tableau
    tolerance, max_iterations = options.tolerance, options.max_iterations
    s = tab.stages
    A, Ah, b, bh = (np.asarray(m, dtype=np.float64) for m in (tab.A, tab.A_hat, tab.b, tab.b_hat))
    for v in ("symprk_x0", "symprk_v0"):
        em.per_dof(v)
    integrator.addComputePerDof("symprk_x0", "x")
    integrator.addComputePerDof("symprk_v0", "v")
    k = [f"symprk_k{i}" for i in range(s)]
    p = [f"symprk_p{i}" for i in range(s)]
    for n in k + p:
        em.per_dof(n)
    order = tab.explicit_order
    notes = []
    need_k = tab.evaluated_stages
    if order is not None:
        x_is_start = True  # x currently holds x_n (forces at x_n may still be cached)
        for i in range(s):
            if order == "p-first":
                integrator.addComputePerDof(p[i], _lincomb("symprk_v0", Ah[i, :i], k[:i]))
                rowA, names = A[i, :i + 1], p[:i + 1]
            else:
                rowA, names = A[i, :i], p[:i]
            if np.any(rowA):
                integrator.addComputePerDof("x", _lincomb("symprk_x0", rowA, names))
                x_is_start = False
            elif not x_is_start:
                integrator.addComputePerDof("x", "symprk_x0")
                x_is_start = True
            if need_k[i]:
                em.acceleration(k[i])
            if order == "q-first":
                integrator.addComputePerDof(p[i], _lincomb("symprk_v0", Ah[i, :i + 1], k[:i + 1]))
    else:
        q = [f"symprk_q{i}" for i in range(s)]
        for n in q:
            em.per_dof(n)
        em.per_dof("symprk_qn")
        for g in (ITER_VAR, "symprk_err", "symprk_dq", "symprk_go", NONCONV_VAR):
            em.glob(g)
        c = A.sum(axis=1)
        for i in range(s):  # predictor: Q_i = x_n + c_i h v_n
            integrator.addComputePerDof(q[i], f"symprk_x0 + {_num(c[i])}*dt*symprk_v0")
        integrator.addComputeGlobal(ITER_VAR, "0")
        integrator.addComputeGlobal("symprk_go", "1")
        integrator.beginWhileBlock("symprk_go > 0.5")
        for i in range(s):
            integrator.addComputePerDof("x", q[i])
            em.acceleration(k[i])
        for i in range(s):
            integrator.addComputePerDof(p[i], _lincomb("symprk_v0", Ah[i], k))
        integrator.addComputeGlobal("symprk_err", "0")
        for i in range(s):
            integrator.addComputePerDof("symprk_qn", _lincomb("symprk_x0", A[i], p))
            integrator.addComputeSum("symprk_dq", f"(symprk_qn - {q[i]})^2")
            integrator.addComputeGlobal("symprk_err", "max(symprk_err, symprk_dq)")
            integrator.addComputePerDof(q[i], "symprk_qn")
        integrator.addComputeGlobal(ITER_VAR, f"{ITER_VAR} + 1")
        # continue while the largest squared change exceeds tol^2 and the cap is not reached
        integrator.addComputeGlobal(
            "symprk_go", f"step(symprk_err - {_num(tolerance ** 2)})*step({max_iterations} - 0.5 - {ITER_VAR})")
        integrator.endBlock()
        integrator.addComputeGlobal(
            NONCONV_VAR, f"{NONCONV_VAR} + step(symprk_err - {_num(tolerance ** 2)})")
        notes.append(f"implicit stages: fixed-point iteration to {tolerance:g} nm (sum over all degrees of "
                     f"freedom of the squared change), at most {max_iterations} iterations; "
                     f"{s} force evaluations per iteration")
    integrator.addComputePerDof("x", _lincomb("symprk_x0", b, p))
    integrator.addComputePerDof("v", _lincomb("symprk_v0", bh, k))
    if place_virtual_sites:
        integrator.addConstrainPositions()
    for sub in method.substeps[len(before):]:
        em.thermostat_event(sub, method.name)
    return ProgramInfo(method, False, em.finish(options.check_finite, options.max_speed), tuple(notes))


def compile_program(integrator, method: ResolvedMethod, options: IntegratorOptions,
                    virtual_sites: bool = False, thermostat=None) -> ProgramInfo:
    """Compile a resolved method (:func:`openmm_symprk.methods.resolved.resolve`) with its ``options`` and the
    ``thermostat``'s settings (:class:`~.thermostat.ThermostatSettings`, None for NVE) into ``integrator``'s program.

    A kick/drift method gets RATTLE steps where it was resolved with constraints or the System has
    ``virtual_sites`` (whose ConstrainPositions places them); a general PRK pair (resolved without constraints)
    ends the step with a ConstrainPositions where there are virtual sites."""
    if method.is_splitting:
        return _compile_splitting(integrator, method, method.constraints or virtual_sites, options, thermostat)
    return _compile_tableau(integrator, method, options, place_virtual_sites=virtual_sites, thermostat=thermostat)
