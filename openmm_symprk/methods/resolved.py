"""A method sorted out once: what the user passed, made into the one description of the step that will run.

Everything that runs a method (both OpenMM backends, multiple time stepping, the reference integrators, the
stability scan, restore) takes a :class:`ResolvedMethod` from :func:`resolve` instead of normalising the
user's input itself::

    r = resolve("yoshida-4", constraints=True)            # or a Method, a Splitting, a PRKTableau
    r.form, r.order, r.force_evals, [s.label for s in r.substeps]

``resolve`` takes the method (a catalogue name or alias, a catalogue :class:`~.catalogue.Method`, a
:class:`~.splitting.Splitting` or a :class:`~.tableau.PRKTableau`), plain facts about the System (whether it
has constraints; no OpenMM object, so this layer stays free of OpenMM) and the multiple-time-step groups, and
derives, once: the form of its step (:data:`FORMS`), the kick/drift sequence as it will run (compositions taken
over the RATTLE base under constraints, the r-RESPA sequence of the groups), every sub-step's kind (:class:`SubstepKind`, the same
numbers as the plugin's ``SymPRKIntegrator::SubstepKind``), its velocity projection and cached-force flags
(:class:`SubstepFlag`, the plugin's ``SymPRKIntegrator::SubstepFlag``), the force evaluations per step, and
the catalogue's order, constrained order and stability interval.  The result is frozen and hashable.

``substeps`` is the whole step, in the order it runs: the kicks and drifts and the thermostat's events where they
sit, each event with the fraction of the step it relaxes over and the step of the thermostat's interval it runs in
(:class:`EventPhase`).  With the thermostat in the middle the step runs from its closing kicks, so that between
steps the Context holds the velocities of the thermostat point (velocity Verlet: kick 1, drift 1/2, event,
drift 1/2; see :func:`resolve`).  Under constraints the kicks and drifts are RATTLE's, whose last part is a velocity projection
right after the last kick or drift (before an ends placement's closing event).  (A general PRK pair's stages are its
``tableau``; its sub-steps are only the thermostat's events around them.)

The projection rule (:func:`projected_drifts`), the cached-force rule
(:attr:`~.splitting.Splitting.evaluating_kicks`) and the thermostat's schedule (:func:`resolve` with
``thermostat_position``) are written here and in :mod:`.splitting` only: the CustomIntegrator compiler and the native
kernels are sent the sub-steps with their flags and execute them; neither decides anything about the step.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import IntEnum, IntFlag
from fractions import Fraction

import numpy as np

from .catalogue import Method, get_method
from .placement import THERMOSTAT, best_position, centre, check_position, middle_placement_advice
from .respa import MTSError, evaluations_per_step, label_groups, levels, mts_groups, respa
from .splitting import DRIFT, KICK, Splitting, evaluating_kicks
from .tableau import PRKTableau, TableauError
from ..support.errors import InputError

__all__ = ["resolve", "thermostat_position_for", "placement_of", "placement_advice", "method_steps", "ResolvedMethod",
           "Substep",
           "substep_label",
           "SubstepKind", "SubstepFlag", "EventPhase", "ConstraintSupportError", "projected_drifts", "FORMS"]

#: The form of a step, which decides how it runs: a kick/drift sequence (any splitting or composition, multiple time
#: stepping included), an explicit general PRK pair, or an implicit one (stages solved by fixed-point iteration).
#: (What a catalogue method is, splitting or composition, is its ``family``.)
FORMS = ("splitting", "explicit", "implicit")


class SubstepKind(IntEnum):
    """The kind of one sub-step; the numbers are the plugin's ``SymPRKIntegrator::SubstepKind`` (a test checks
    it).  A later operation is one more member on both sides."""

    KICK = 0  # v += c*dt*F/m
    DRIFT = 1  # x += c*dt*v (RATTLE under constraints)
    THERMOSTAT = 2  # a thermostat event over the fraction c of the step's interval (1/2 at the ends, 1 in the middle)


class SubstepFlag(IntFlag):
    """Per-sub-step flags, the plugin's ``SymPRKIntegrator::SubstepFlag`` bits (a test checks it)."""

    NONE = 0
    PROJECT_BEFORE = 1  # a drift or a thermostat event: project the velocities onto the constraints first
    FORCES_CACHED = 2  # a kick: its force groups' forces are still those of the current positions
    FIRST_OF_INTERVAL = 4  # a thermostat event: runs in the first step of every thermostat interval
    LAST_OF_INTERVAL = 8  # a thermostat event: runs in the last step (neither: in the centre step, (n - 1) // 2)


class EventPhase(IntEnum):
    """In which step of the thermostat's interval of n steps an event runs: the first (the ends placement's half event
    before the step), the centre one, (n - 1) // 2 counted from 0 (the middle placement's event, at the centre of its n
    steps), or the last (the ends placement's half event after the step)."""

    FIRST = 0
    CENTRE = 1
    LAST = 2

    def step_in(self, interval: int) -> int:
        """The step, counted from 0 within an interval of ``interval`` steps, in which such an event runs."""
        n = int(interval)
        return 0 if self is EventPhase.FIRST else (n - 1 if self is EventPhase.LAST else (n - 1) // 2)

    @classmethod
    def of_flags(cls, flags) -> "EventPhase":
        """The phase a thermostat sub-step's flags (:class:`SubstepFlag`, the plugin's) name."""
        flags = SubstepFlag(int(flags))
        if flags & SubstepFlag.FIRST_OF_INTERVAL:
            return cls.FIRST
        return cls.LAST if flags & SubstepFlag.LAST_OF_INTERVAL else cls.CENTRE


def placement_of(phases) -> str | None:
    """Where a step's thermostat sits, read back from the :class:`EventPhase` of its events: "middle" (one event in
    the centre step of the interval), "ends" (half events in its first and last steps), or None (no event: no
    thermostat).  The one reading of a placement: a resolved method's (:attr:`ResolvedMethod.thermostat_position`) and
    a plugin's read from XML (its sub-steps' flags, :meth:`EventPhase.of_flags`)."""
    phases = set(phases)
    if not phases:
        return None
    return "middle" if EventPhase.CENTRE in phases else "ends"


class ConstraintSupportError(InputError):
    """The method cannot be used on a system with constraints."""


@dataclass(frozen=True)
class Substep:
    """One sub-step of the step as it will run."""

    kind: SubstepKind
    coefficient: Fraction  # fraction of the step size (exact)
    groups: tuple | None = None  # kicks: the force groups (None: all the integrator's forces)
    project_before: bool = False  # drifts and thermostat events: project the velocities first
    forces_cached: bool = False  # kicks: no force evaluation (no drift since the last kick of these groups)
    phase: EventPhase | None = None  # thermostat events: the step of the thermostat's interval it runs in

    @property
    def label(self) -> str:
        """"drift", "kick", or "kick:<groups>" (the labels of :class:`~.splitting.Splitting`), or "thermostat"."""
        return substep_label(self.kind, self.groups)

    @property
    def is_kick_or_drift(self) -> bool:
        return self.kind in (SubstepKind.KICK, SubstepKind.DRIFT)

    @property
    def flags(self) -> SubstepFlag:
        return ((SubstepFlag.PROJECT_BEFORE if self.project_before else SubstepFlag.NONE)
                | (SubstepFlag.FORCES_CACHED if self.forces_cached else SubstepFlag.NONE)
                | (SubstepFlag.FIRST_OF_INTERVAL if self.phase is EventPhase.FIRST else SubstepFlag.NONE)
                | (SubstepFlag.LAST_OF_INTERVAL if self.phase is EventPhase.LAST else SubstepFlag.NONE))

    @property
    def group_mask(self) -> int:
        """The force groups as a bit mask, -1 for drifts and for kicks of all forces."""
        return -1 if self.groups is None else sum(1 << g for g in self.groups)


def substep_label(kind, groups=None) -> str:
    """The label of a sub-step of ``kind`` (a :class:`SubstepKind` or its number) and, for a kick, its force ``groups``
    (None: all): "drift", "thermostat", "kick" or "kick:<groups>"."""
    kind = SubstepKind(kind)
    if kind == SubstepKind.DRIFT:
        return DRIFT
    if kind == SubstepKind.THERMOSTAT:
        return THERMOSTAT
    return KICK if groups is None else KICK + ":" + ",".join(map(str, groups))


def projected_drifts(splitting: Splitting) -> list:
    """Indices (into ``steps``) of the drifts before which a constrained step projects the velocities.

    Under constraints a drift x += c h v is followed by SHAKE and v += (x - x_u)/(c h): a constraint solver that
    stops at its tolerance leaves a residual delta in x and so delta/(c h) in v along the bonds, which the next
    drift c' turns into a position error (c'/c) delta.  Where |c'| > |c| (pefrl: 0.775 after -0.066, a factor
    11.7) that grows from drift to drift faster than the solver, which does nothing below its tolerance, removes
    it.  A velocity projection at the current (constrained) positions just before such a drift removes the
    along-bond velocity; in exact arithmetic it changes nothing, since the drift's own position projection acts
    along the same bond vectors and absorbs it.  So: every drift whose |coefficient| exceeds the previous
    drift's within the step.  (The one statement of the rule: the backends receive it as a flag.)"""
    out, previous = [], None
    for i, (label, c) in enumerate(splitting.steps):
        if label == DRIFT:
            if previous is not None and abs(c) > abs(previous):
                out.append(i)
            previous = c
    return out


def _substeps(splitting: Splitting, constraints: bool) -> tuple:
    projected = set(projected_drifts(splitting)) if constraints else set()
    evaluating = splitting.evaluating_kicks
    out = []
    for i, (label, c) in enumerate(splitting.steps):
        if label == DRIFT:
            out.append(Substep(SubstepKind.DRIFT, c, project_before=i in projected))
        else:
            try:
                groups = label_groups(label)
            except ValueError:
                raise TableauError(f"a kick/drift splitting cannot contain a {label!r} sub-flow") from None
            out.append(Substep(SubstepKind.KICK, c, groups, forces_cached=i not in evaluating))
    return tuple(out)


@dataclass(frozen=True)
class ResolvedMethod:
    """One method as it will run (see the module docstring).  Build it with :func:`resolve`."""

    name: str
    form: str  # one of FORMS
    constraints: bool  # RATTLE steps (kick/drift methods only)
    stages: int | None  # PRK stages of the method's tableau (None: multiple time stepping)
    order: int | None  # catalogue order (None: not a catalogue method)
    constrained_order: int | None  # catalogue order under RATTLE constraints
    stability: float | None  # catalogue: largest stable h*omega (multiple time stepping: the outer method's)
    splitting: Splitting | None  # the kick/drift sequence as it runs (None: a general PRK pair)
    tableau: PRKTableau | None  # the method's own PRK pair (None: multiple time stepping)
    substeps: tuple = ()  # Substep, in order (empty for a general PRK pair)
    force_evals: int | None = None  # per step in a long run (implicit: per fixed-point iteration)
    evals_per_group: tuple = ()  # multiple time stepping: ((force groups, evaluations per step), ...)
    levels: tuple = ()  # multiple time stepping: Level, slowest first
    groups: tuple | None = None  # multiple time stepping: ((force group, substeps), ...) as given
    inner_name: str | None = None  # multiple time stepping: the inner levels' method
    entry: Method | None = field(default=None, repr=False)  # the catalogue entry, when there is one

    # -- views ----------------------------------------------------------------------------------------------
    @property
    def thermostat_position(self) -> str | None:
        """Where the thermostat's events sit in ``substeps``: "ends", "middle" or None (resolved without a thermostat):
        :func:`placement_of` their phases."""
        return placement_of(s.phase for s in self.substeps if s.kind == SubstepKind.THERMOSTAT)

    @property
    def family(self) -> str | None:
        """The catalogue family (splitting, composition, implicit, reference), None for user methods."""
        return self.entry.family if self.entry is not None else None

    @property
    def is_splitting(self) -> bool:
        """A kick/drift sequence: runs on both backends and keeps constraints (RATTLE)."""
        return self.splitting is not None

    @property
    def is_mts(self) -> bool:
        return bool(self.levels)

    @property
    def evaluations(self) -> dict:
        """{force groups (tuple, or None for all forces): evaluations per step} of a kick/drift method."""
        return dict(self.evals_per_group)

    def tableau_in(self, dtype=np.float64) -> PRKTableau:
        """The method's PRK pair in ``dtype`` (float64 or long double), from the exact data where there is some."""
        if self.tableau is None:
            raise TableauError(f"{self.name}: a multiple-time-step method has no single PRK tableau")
        if np.dtype(dtype) == self.tableau.dtype:
            return self.tableau
        if self.entry is not None:
            return self.entry.tableau(dtype)
        if self.is_splitting and set(self.splitting.labels) <= {KICK, DRIFT}:
            return PRKTableau.from_splitting(self.splitting, name=self.name, dtype=dtype)
        t = self.tableau
        return PRKTableau(t.A, t.b, t.A_hat, t.b_hat, name=t.name, dtype=dtype)

    def check_symplectic(self, allow_nonsymplectic: bool = False):
        """TableauError naming Reich's residuals unless the method is symplectic (kick/drift sequences are)."""
        if self.tableau is not None:
            self.tableau.check_symplectic(allow_nonsymplectic)

    def describe_levels(self) -> str:
        """One line: each level's groups, substeps and evaluations per step ("" without multiple time stepping)."""
        if not self.levels:
            return ""
        evals = self.evaluations
        parts = [f"groups {','.join(map(str, lv.groups))} x{lv.substeps}"
                 + (f" ({evals[tuple(lv.groups)]} evaluations per step)" if tuple(lv.groups) in evals else "")
                 for lv in self.levels]
        return "multiple time stepping, slowest first: " + "; ".join(parts)


def _normalise(method):
    """(catalogue entry or None, splitting or None, tableau or None) of what the user passed."""
    if isinstance(method, ResolvedMethod):
        method = method.entry if method.entry is not None else (
            method.tableau if method.tableau is not None else method.splitting)
    if isinstance(method, str):
        method = get_method(method)
    if isinstance(method, Method):
        return method, method.splitting, method.tableau()
    if isinstance(method, Splitting):
        return None, method, None  # its tableau is built once the name is known
    if isinstance(method, PRKTableau):
        return None, method.splitting, method
    raise TypeError(f"expected a method name, a catalogue Method, a Splitting or a PRKTableau, got {method!r}")


def _form(splitting, tableau) -> str:
    if splitting is not None:
        return "splitting"
    return "explicit" if tableau.is_explicit else "implicit"


def _with_middle_thermostat(substeps: tuple, constrained: bool) -> tuple:
    """``substeps`` with one whole thermostat event at the step's centre (in the centre step of the thermostat's
    interval): the central kick or drift (a drift, or a kick of BABAB schemes and of multiple time stepping with an
    even number of inner steps) split in two equal halves around it.  The first half keeps the sub-step's flags; the
    second half of a kick finds its forces cached (no drift between), that of a drift needs no projection (the same
    coefficient as the drift before it, see :func:`projected_drifts`).

    Under constraints an event that follows a kick projects the velocities first: a kick leaves each constraint's
    share of the force in the velocities (RATTLE removes it only before the next drift), a kinetic energy along the
    bonds that is no degree of freedom; rescaled with the rest, it would hold the real degrees of freedom below the
    target (216 SPC/E waters, ``verlet 4/2 fs``: 264 K at 300 K).  After a drift the velocities already follow the
    constrained positions (SHAKE's correction)."""
    i = centre([(s.label, s.coefficient) for s in substeps])
    sub = substeps[i]
    half = sub.coefficient / 2
    first = Substep(sub.kind, half, sub.groups, sub.project_before, sub.forces_cached)
    second = Substep(sub.kind, half, sub.groups, False, sub.kind == SubstepKind.KICK)
    event = Substep(SubstepKind.THERMOSTAT, Fraction(1), project_before=constrained and sub.kind == SubstepKind.KICK,
                    phase=EventPhase.CENTRE)
    return (*substeps[:i], first, event, second, *substeps[i + 1:])


def _from_closing_kicks(substeps: tuple) -> tuple:
    """The step of ``substeps`` (a symmetric sequence with the middle event) run from its closing kicks: the kicks it
    ends with (the mirror of those it begins with, at the same positions) are taken off its end and added to the
    kicks it begins with, those of the next step.  Both use the forces at the positions the step ends with, so a
    long run is the same sequence of operations and force evaluations; between steps the Context then holds the
    positions at the end of the step and the velocities before its closing kicks, half a kick behind them (as
    OpenMM's LangevinMiddleIntegrator holds them), and a new run's velocities are taken as such.  Where only drifts
    lie between the event and the closing kicks (velocity Verlet, multiple time stepping whose outer step is one
    inner step) those are the velocities at the thermostat point; elsewhere they are the leapfrog velocities of the
    inner Verlet steps (multiple time stepping: canonical for the fast modes too) or of the method.  A step that
    begins with a drift (position Verlet) is left as it is: its on-step velocities are what it holds.  The kicks'
    cached-force flags follow :func:`~.splitting.evaluating_kicks` on the new sequence."""
    n = 0
    while substeps[n].kind == SubstepKind.KICK:
        n += 1
    if n == 0:
        return substeps
    opening, closing = substeps[:n], substeps[len(substeps) - n:]
    if [(s.groups, s.coefficient) for s in opening] != [(s.groups, s.coefficient) for s in reversed(closing)]:
        raise ValueError("the step does not close with the mirror of its opening kicks")  # symmetric by construction
    steps = (*(replace(s, coefficient=2 * s.coefficient) for s in opening), *substeps[n:len(substeps) - n])
    evaluating = evaluating_kicks([s.label for s in steps], others=(THERMOSTAT,))
    return tuple(replace(s, forces_cached=i not in evaluating) if s.kind == SubstepKind.KICK else s
                 for i, s in enumerate(steps))


def method_steps(steps, position: str | None) -> list:
    """The method's own kick/drift sequence, as (label, coefficient), from ``steps`` (the (label, coefficient) of the
    sub-steps as they run, e.g. a plugin's read from XML) with the thermostat at ``position``: the events left out and
    the halves they split joined again, and for the middle placement the kicks the step begins with split back into
    its opening and closing kicks (:func:`_from_closing_kicks`)."""
    out = []
    for i, (label, c) in enumerate(steps):
        if label == THERMOSTAT:
            continue
        if i > 0 and steps[i - 1][0] == THERMOSTAT and out and out[-1][0] == label:
            out[-1] = (label, out[-1][1] + c)
        else:
            out.append((label, c))
    if position == "middle":
        n = 0
        while n < len(out) and out[n][0] != DRIFT:
            n += 1
        if n:
            halves = [(label, c / 2) for label, c in out[:n]]
            out = [*halves, *out[n:], *reversed(halves)]
    return out


def _with_end_events(substeps: tuple) -> tuple:
    """``substeps`` with the ends placement's two half events: one before them, in the first step of the thermostat's
    interval, and one after them (after RATTLE's closing velocity projection under constraints), in its last step."""
    half = Fraction(1, 2)
    return (Substep(SubstepKind.THERMOSTAT, half, phase=EventPhase.FIRST), *substeps,
            Substep(SubstepKind.THERMOSTAT, half, phase=EventPhase.LAST))


def placement_advice(resolved: ResolvedMethod, position: str | None) -> str | None:
    """Why the thermostat placement asked for (``position``) is the worse one for ``resolved``, or None: only
    ``"middle"`` on a splitting on one time scale whose middle samples worse than its ends can be
    (:func:`.placement.middle_placement_advice`); the backends warn with it."""
    if position != "middle" or not resolved.is_splitting or resolved.is_mts:
        return None
    return middle_placement_advice(resolved.name, resolved.splitting.steps, resolved.stability)


def thermostat_position_for(resolved: ResolvedMethod, position: str) -> str:
    """"ends" or "middle": ``position`` as given (:func:`.placement.check_position`), "auto" being
    :func:`.placement.best_position` of the method's kick/drift sequence (on multiple time stepping: the inner,
    fastest level's kicks carry the oscillator's force); a general PRK pair has no centre sub-step: "ends"."""
    if check_position(position) != "auto":
        return position
    if not resolved.is_splitting:
        return "ends"
    forced = None
    if resolved.is_mts:
        fastest = resolved.levels[-1].groups
        forced = [s.label for s in resolved.substeps if s.kind == SubstepKind.KICK and s.groups is not None
                  and set(s.groups) & set(fastest)]
    return best_position(resolved.splitting.steps, resolved.stability, forced=forced)


def resolve(method, constraints: bool | None = False, groups=None, inner_method=None,
            name: str | None = None, thermostat_position: str | None = None) -> ResolvedMethod:
    """The one description of ``method`` as it will run (see the module docstring).

    ``constraints``: the System has constraints (True), has none (False, the default: model problems), or is
    not known (None: kick/drift methods then get RATTLE steps, which are correct, and cheap, without
    constraints too).  ``groups``/``inner_method``: multiple time stepping in the form of OpenMM's
    ``MTSIntegrator`` (:mod:`.respa`).  ``name`` overrides the method's name.  Raises UnknownMethodError (with
    close names), TypeError for something that is not a method, ConstraintSupportError for a general PRK pair
    under constraints and MTSError for a malformed ``groups``.

    ``thermostat_position``: None (no thermostat), "ends", "middle" or "auto" (:func:`thermostat_position_for`).
    With "middle" the sub-steps get one :attr:`SubstepKind.THERMOSTAT` event at the exact centre of the step (of the
    outer step with multiple time stepping), splitting the central drift or kick in two halves, in the centre step of
    the thermostat's interval, and the step runs from its closing kicks (:func:`_from_closing_kicks`: velocity
    Verlet becomes kick 1, drift 1/2, event, drift 1/2, so that a State holds the velocities at the thermostat
    point); ValueError for a general PRK pair or a sequence that is not symmetric (no one centre).  With "ends" they
    get a half event before the first sub-step (in the first step of the interval) and one after the last (in its
    last step): :class:`EventPhase`.  ``splitting`` and ``tableau`` stay the method's own."""
    if thermostat_position is not None:
        plain = resolve(method, constraints, groups, inner_method, name)
        where = thermostat_position_for(plain, thermostat_position)
        if where == "ends":
            return replace(plain, substeps=_with_end_events(plain.substeps))
        if not plain.is_splitting:
            raise InputError(f"thermostat_position='middle' needs a kick/drift method, whose step has a centre "
                             f"sub-step; {plain.name!r} is a general ({plain.family or plain.form}) PRK tableau: use "
                             f"thermostat_position='ends' (or 'auto')")
        try:
            substeps = _with_middle_thermostat(plain.substeps, plain.constraints)
        except InputError as exc:
            raise InputError(f"{plain.name}: {exc}") from None
        return replace(plain, substeps=_from_closing_kicks(substeps))
    entry, splitting, tableau = _normalise(method)
    form = _form(splitting, tableau)
    name = name or (entry.name if entry is not None else None) or (
        tableau.name if tableau is not None else "user splitting")
    if tableau is None and set(splitting.labels) <= {KICK, DRIFT}:
        tableau = PRKTableau.from_splitting(splitting, name=name)
    if inner_method is not None and groups is None:
        raise InputError("inner_method= needs groups= (the force groups of the levels of multiple time stepping)")
    constrained = splitting is not None if constraints is None else bool(constraints)
    if constrained and splitting is None:
        raise ConstraintSupportError(
            f"method {name!r} is a general (non-splitting) PRK tableau and cannot keep constraints: the "
            f"system has constraints (rigid water, HBonds, ...). Use a kick/drift method instead, e.g. "
            f"'verlet' (RATTLE), 'yoshida-4' or 'blanes-moan-srkn6b-4', or create the system with "
            f"constraints=None and rigidWater=False.")
    common = dict(name=name, form=form, constraints=constrained,
                  order=entry.order if entry is not None else None,
                  constrained_order=entry.constrained_order if entry is not None else None,
                  stability=entry.stability if entry is not None else None, entry=entry)
    if splitting is None:
        if groups is not None:
            raise MTSError(f"multiple time stepping needs kick/drift methods at every level; {name!r} is a general "
                           f"({entry.family if entry is not None else form}) PRK tableau")
        return ResolvedMethod(stages=tableau.stages, splitting=None, tableau=tableau,
                              force_evals=tableau.force_evaluations, **common)
    run = entry.constrained_splitting if (entry is not None and constrained) else splitting
    lv, inner_name, given = (), None, None
    if groups is not None:
        inner_given = method if inner_method is None else inner_method
        inner = resolve(inner_given)
        if not inner.is_splitting:
            raise MTSError(f"multiple time stepping needs kick/drift methods at every level; {inner.name!r} is a "
                           f"general ({inner.family or inner.form}) PRK tableau")
        if constrained:
            inner = resolve(inner_given, constraints=True)
        lv = tuple(levels(groups, run, inner.splitting))
        given = mts_groups(groups)
        inner_name = inner.name
        run = respa(list(lv))
        tableau = None
    substeps = _substeps(run, constrained)  # (refuses labels that are neither kicks nor drifts)
    evals = evaluations_per_step(run)
    return ResolvedMethod(stages=tableau.stages if tableau is not None else None, splitting=run, tableau=tableau,
                          substeps=substeps, force_evals=sum(evals.values()),
                          evals_per_group=tuple(evals.items()) if list(evals) != [None] else (),
                          levels=lv, groups=given, inner_name=inner_name, **common)
