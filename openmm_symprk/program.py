"""Compile a catalogue method, splitting or PRK tableau into an openmm.CustomIntegrator program.

One compiler for everything (OPENMM_NOTES.md explains each rule):

* Splittings and compositions: kick ``v = v + b*dt*f/m``, drift ``x = x + a*dt*v``.  Adjacent pieces
  are already merged by :class:`~openmm_symprk.splitting.Splitting`; the forces of a closing kick
  stay cached and serve the next step's opening kick, so a step costs exactly
  ``Splitting.force_evaluations()`` evaluations in steady state.
* Constraints (RATTLE): after every drift ``ConstrainPositions`` and ``v += (x - x_unconstrained)/(a*dt)``,
  nothing references forces between a drift and its ConstrainPositions, and velocities are projected
  once at the end of the step.  The velocity projections RATTLE makes after inner kicks are absorbed
  exactly by the next drift's position projection, whose multipliers act along the same bond vectors,
  so they are omitted (each one would cost a constraint solve).
* General tableaux (explicit non-splitting, implicit) for unconstrained systems: stage values live in
  per-DOF variables; implicit stages are solved by fixed-point iteration in a single while block.
* Optional exact momentum (:mod:`openmm_symprk.projection`): projected kicks, and the round-off net
  momentum and torque of every constraint projection removed (after each RATTLE drift and after the
  end-of-step velocity projection), with the System's masses in double; and a blow-up check: the step counter
  and the first step at which the velocities stopped being finite are kept in global variables.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import openmm as mm

from .splitting import DRIFT, KICK, Splitting
from .tableau import PRKTableau, TableauError

#: Global variables the compiled programs maintain (read by the integrator classes).
STEP_VAR = "symprk_step"
BAD_VAR = "symprk_blowup_step"
NONCONV_VAR = "symprk_nonconverged"
ITER_VAR = "symprk_iterations"


class ConstraintSupportError(ValueError):
    """The method cannot be used on a system with constraints."""


@dataclass
class ProgramInfo:
    """What the compiler emitted: used by tests, the CLI and the integrator classes."""

    kind: str  # "splitting", "explicit" or "implicit"
    constraints: bool
    force_evals: int | None  # per step in steady state (implicit: per fixed-point iteration)
    stages: int
    exact_momentum: bool
    notes: list = field(default_factory=list)


def _num(c) -> str:
    """A coefficient as an expression literal that round-trips a float64 exactly."""
    return repr(float(c))


class _Emitter:
    """Appends computations to a CustomIntegrator, with the shared kick and drift rules."""

    def __init__(self, integrator: mm.CustomIntegrator, constraints: bool, exact_momentum: bool, system=None):
        self.ig = integrator
        self.constraints = constraints
        self.exact_momentum = exact_momentum
        self._vars: set = set()
        if exact_momentum:
            from .projection import add_projection_variables

            add_projection_variables(integrator, system)

    def per_dof(self, name: str):
        if name not in self._vars:
            self.ig.addPerDofVariable(name, 0.0)
            self._vars.add(name)

    def glob(self, name: str, value: float = 0.0):
        if name not in self._vars:
            self.ig.addGlobalVariable(name, value)
            self._vars.add(name)

    def acceleration(self, target: str) -> str:
        """Store the (optionally momentum-projected) acceleration F/m in per-DOF ``target``."""
        self.per_dof(target)
        if self.exact_momentum:
            from .projection import emit_projected_acceleration

            emit_projected_acceleration(self.ig, target)
        else:
            self.ig.addComputePerDof(target, "f/m")
        return target

    def kick(self, c):
        if self.exact_momentum:
            a = self.acceleration("symprk_a")
            self.ig.addComputePerDof("v", f"v + {_num(c)}*dt*{a}")
        else:
            self.ig.addComputePerDof("v", f"v + {_num(c)}*dt*f/m")

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

    def finish(self, check_finite: bool):
        if self.constraints and self.exact_momentum:
            from .projection import emit_constrain_velocities

            emit_constrain_velocities(self.ig)
        elif self.constraints:
            self.ig.addConstrainVelocities()
        self.glob(STEP_VAR)
        self.ig.addComputeGlobal(STEP_VAR, f"{STEP_VAR} + 1")
        if check_finite:
            # Count the degrees of freedom whose speed is NaN (every comparison with NaN is false, so
            # step(NaN) = 0) or beyond 1e5 nm/ps (a runaway: no physical system comes near), and record the
            # first step where any is found.  (Lepton would simplify a NaN self-test s - s to 0.)
            self.glob("symprk_bad_dofs")
            self.glob(BAD_VAR)
            self.ig.addComputeSum("symprk_bad_dofs", "1 - step(1e10 - v*v)")
            self.ig.addComputeGlobal(
                BAD_VAR, f"select({BAD_VAR}, {BAD_VAR}, step(symprk_bad_dofs - 0.5)*{STEP_VAR})")


def compile_splitting(integrator, splitting: Splitting, constraints: bool, exact_momentum=False,
                      check_finite=True, update_context_state=True, system=None) -> ProgramInfo:
    """Emit the program of a kick/drift sequence (RATTLE when ``constraints``)."""
    em = _Emitter(integrator, constraints, exact_momentum, system)
    if update_context_state:
        integrator.addUpdateContextState()
    for label, c in splitting.coefficients(np.float64):
        if label == KICK:
            em.kick(c)
        elif label == DRIFT:
            em.drift(c)
        else:
            raise TableauError(f"a kick/drift splitting cannot contain a {label!r} sub-flow")
    em.finish(check_finite)
    return ProgramInfo("splitting", constraints, splitting.force_evaluations(), len(splitting), exact_momentum)


def _lincomb(base: str, coeffs, names) -> str:
    terms = [f"{_num(a)}*{n}" for a, n in zip(coeffs, names) if a != 0]
    if not terms:
        return base
    return f"{base} + dt*({' + '.join(terms)})"


def compile_tableau(integrator, tab: PRKTableau, exact_momentum=False, check_finite=True,
                    update_context_state=True, tolerance=1e-12, max_iterations=60, system=None) -> ProgramInfo:
    """Emit the program of a general PRK pair (unconstrained systems only).

    Per-DOF variables: symprk_x0/v0 (start of step), symprk_k<i> (stage accelerations F(Q_i)/m),
    symprk_p<i> (stage velocities P_i), symprk_q<i> (implicit stage positions)."""
    em = _Emitter(integrator, False, exact_momentum, system)
    s = tab.stages
    A, Ah, b, bh = (np.asarray(m, dtype=np.float64) for m in (tab.A, tab.A_hat, tab.b, tab.b_hat))
    if update_context_state:
        integrator.addUpdateContextState()
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
    need_k = [bool(np.any(Ah[:, i]) or bh[i]) for i in range(s)]
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
        kind = "explicit"
        evals = int(sum(need_k))
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
        kind = "implicit"
        evals = s
        notes.append(f"implicit stages: fixed-point iteration to {tolerance:g} nm (sum over all degrees of "
                     f"freedom of the squared change), at most {max_iterations} iterations; "
                     f"{s} force evaluations per iteration")
    integrator.addComputePerDof("x", _lincomb("symprk_x0", b, p))
    integrator.addComputePerDof("v", _lincomb("symprk_v0", bh, k))
    em.finish(check_finite)
    return ProgramInfo(kind, False, evals, s, exact_momentum, notes)


def compile_program(integrator, method, constraints: bool, **options) -> ProgramInfo:
    """Compile a catalogue Method, a Splitting or a PRKTableau into ``integrator``'s program."""
    from .catalogue import Method

    if isinstance(method, Method):
        name = method.name
        if method.is_splitting:
            method = method.constrained_splitting if constraints else method.splitting
        else:
            method = method.tableau()
    else:
        name = getattr(method, "name", "user tableau")
    if isinstance(method, PRKTableau):
        try:
            method = method.to_splitting()
        except TableauError:
            pass
    if isinstance(method, Splitting):
        keep = {k: v for k, v in options.items()
                if k in ("exact_momentum", "check_finite", "update_context_state", "system")}
        return compile_splitting(integrator, method, constraints, **keep)
    if constraints:
        raise ConstraintSupportError(
            f"method {name!r} is a general (non-splitting) PRK tableau and cannot keep constraints: the "
            f"system has constraints (rigid water, HBonds, ...). Use a kick/drift method instead, e.g. "
            f"'verlet' (RATTLE), 'yoshida-4' or 'blanes-moan-srkn6b-4', or create the system with "
            f"constraints=None and rigidWater=False.")
    return compile_tableau(integrator, method, **options)
