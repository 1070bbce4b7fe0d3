"""Where a velocity thermostat sits in a kick/drift step, and what that does to sampling (pure numerics).

A thermostat O that acts on velocities only can sit at the ends of the symplectic step (half an event before
and half after: O_{h/2} . step . O_{h/2}) or at its exact centre (one whole event there). On N independent
harmonic oscillators q'' = -w^2 q the choice decides how far the sampled configurations are from the canonical
ones: velocity Verlet with O at the ends samples <q^2> w^2/kT = 1/(1 - h^2 w^2/4) (configurations hot), with O in
the middle (between its two half drifts: BAOAB) exactly 1, while its on-step velocities then read
<v^2>/kT = 1 - h^2 w^2/4 and those at O exactly 1 (docs/theory.md, section 6; the integrators' State holds the
latter: :func:`openmm_symprk.methods.resolved.resolve` runs such a step from its closing kick).  Higher-order splittings behave otherwise (omelyan-2's ends
placement is already within 0.4% of exact at h w <= 1, its middle one 6% off), so the package does not assume
which placement helps a method: :func:`harmonic_sampling` computes the stationary moments of a step with its
thermostat exactly, and :func:`best_position` picks the placement for ``thermostat_position="auto"``.

Everything here works on plain sequences of ``(label, coefficient)``: labels "kick" (or "kick:<groups>" of a
multiple-time-step sequence), "drift" and :data:`THERMOSTAT`, coefficients as fractions of the step (a
thermostat entry's coefficient is the fraction of the step whose relaxation it applies).
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..support.errors import InputError

__all__ = ["THERMOSTAT", "POSITIONS", "PLACEMENT_TEXT", "check_position", "centre", "with_thermostat", "harmonic_sampling", "placement_errors",
           "best_position", "H_OMEGA_GRID", "middle_placement_advice", "MEASURED_MIDDLE"]

#: The label of a thermostat event in a step sequence.
THERMOSTAT = "thermostat"
#: The placements a user can ask for ("auto": the one :func:`best_position` picks for the method).
POSITIONS = ("ends", "middle", "auto")
#: How each placement reads in an integrator's description (of the outer step with multiple time stepping).
PLACEMENT_TEXT = {"ends": "half events around the step", "middle": "one event at the centre of the step",
                  "auto": "placement: auto"}
#: The h*omega values over which "auto" compares the placements: water's librations at 1-4 fs span about
#: 0.13-0.5, an O-H stretch at 1 fs about 0.9.
H_OMEGA_GRID = (0.25, 0.5, 0.75, 1.0)


def check_position(position) -> str:
    """``position`` if it is one of :data:`POSITIONS` ("ends": half an event before and after the step; "middle": one
    event at the exact centre of the step; "auto": the one :func:`best_position` picks for the method); ValueError
    naming the accepted values otherwise.  The one check of a placement, for the integrators' option and
    :func:`openmm_symprk.methods.resolved.resolve` alike."""
    if not isinstance(position, str) or position not in POSITIONS:
        raise InputError(f"thermostat_position must be one of {', '.join(map(repr, POSITIONS))}, got {position!r}")
    return position


def centre(steps) -> int:
    """Index of the middle sub-step of a symmetric (self-adjoint) sequence, the one the step's time centre lies
    in.  ValueError for a sequence that does not read the same backwards: its centre in time is not one point."""
    steps = [(label, Fraction(c)) for label, c in steps]
    if len(steps) % 2 == 0 or steps != steps[::-1]:
        raise InputError("the thermostat can only sit in the middle of a symmetric (self-adjoint) step, whose "
                         "sequence reads the same backwards; this one does not (use thermostat_position='ends')")
    return len(steps) // 2


def with_thermostat(steps, position: str) -> list:
    """``steps`` with the thermostat where ``position`` ("ends" or "middle") puts it: half an event at each end,
    or the middle sub-step split in two equal halves with one whole event between them."""
    steps = [(label, Fraction(c)) for label, c in steps]
    if position == "ends":
        half = Fraction(1, 2)
        return [(THERMOSTAT, half), *steps, (THERMOSTAT, half)]
    if position == "middle":
        i = centre(steps)
        label, c = steps[i]
        return [*steps[:i], (label, c / 2), (THERMOSTAT, Fraction(1)), (label, c / 2), *steps[i + 1:]]
    raise InputError(f"thermostat position must be 'ends' or 'middle', got {position!r}")


def harmonic_sampling(steps, h_omega: float, decay: float = 0.5, forced=None) -> tuple:
    """(<q^2> w^2/kT, <v^2>/kT) that a step with its thermostat samples, exactly, for q'' = -w^2 q.

    ``steps`` includes the thermostat entries (:func:`with_thermostat`); each is a Langevin (Ornstein-Uhlenbeck)
    velocity update over its fraction f of the step, v <- a v + sqrt(1 - a^2) sqrt(kT/m) xi with a = decay**f
    (``decay`` = exp(-h/tau) per step, 0 < decay < 1).  Velocity rescaling of the whole kinetic energy gives the same
    moments to 3 digits (docs/theory.md, section 6).  ``forced``: the kick labels that carry the oscillator's force
    (default: every kick; for a multiple-time-step sequence the fast level's label).  The moments are the
    stationary covariance of the linear stochastic map of one step (the discrete Lyapunov equation S = A S A^T + Q), taken at the
    step's end: given the sub-steps as they run (``[(s.label, s.coefficient) for s in resolve(...).substeps]``, whose
    middle placement runs the step from its closing kick), <v^2> is what a State's velocities read.  ValueError when the step is unstable at h_omega
    (no stationary distribution)."""
    if not 0.0 < decay < 1.0:
        raise InputError(f"decay must lie strictly between 0 and 1, got {decay!r}")
    x = float(h_omega)
    A, Q = np.eye(2), np.zeros((2, 2))
    for label, c in steps:
        c = float(c)
        noise = np.zeros((2, 2))
        if label == THERMOSTAT:
            a = decay ** c
            M = np.array([[1.0, 0.0], [0.0, a]])
            noise[1, 1] = 1.0 - a * a
        elif label == "drift":
            M = np.array([[1.0, c * x], [0.0, 1.0]])
        elif forced is None or label in forced:
            M = np.array([[1.0, 0.0], [-c * x, 1.0]])
        else:
            continue  # a kick of a force group the oscillator does not feel
        A, Q = M @ A, M @ Q @ M.T + noise
    if max(abs(np.linalg.eigvals(A))) >= 1.0:
        raise InputError(f"the step is not stable at h*omega = {x:g}: no stationary distribution")
    # S = A S A^T + Q, as (I - A (x) A) vec(S) = vec(Q): a 4x4 solve
    S = np.linalg.solve(np.eye(4) - np.kron(A, A), Q.reshape(4)).reshape(2, 2)
    return float(S[0, 0]), float(S[1, 1])


def placement_errors(steps, h_omegas=H_OMEGA_GRID, decay: float = 0.5, forced=None) -> dict:
    """{position: largest |<q^2> w^2/kT - 1| over ``h_omegas``} for "ends" and "middle" (inf where the step is
    unstable at one of them, or where the middle is not one point)."""
    out = {}
    for position in ("ends", "middle"):
        try:
            seq = with_thermostat(steps, position)
            out[position] = max(abs(harmonic_sampling(seq, x, decay, forced)[0] - 1.0) for x in h_omegas)
        except ValueError:
            out[position] = float("inf")
    return out


def best_position(steps, stability: float | None = None, forced=None) -> str:
    """The placement "auto" gives: "middle" where it samples the harmonic oscillators' configurations closer to
    canonical than "ends" over :data:`H_OMEGA_GRID` (cut at 90% of the method's stability limit ``stability``),
    by at least a factor of 2, else "ends" (the package's placement before the middle one existed)."""
    grid = tuple(x for x in H_OMEGA_GRID if stability is None or x < 0.9 * stability) or (H_OMEGA_GRID[0],)
    err = placement_errors(steps, grid, forced=forced)
    return "middle" if err["middle"] < 0.5 * err["ends"] else "ends"


def placement_table(names=("verlet", "omelyan-2", "pefrl", "yoshida-4", "blanes-moan-srkn6b-4"),
                    h_omegas=(0.25, 0.5, 1.0), decay: float = 0.5) -> str:
    """A text table of w^2<q^2>/kT (1 is exact) for the catalogue methods ``names`` with the thermostat at the ends
    and in the middle, over ``h_omegas``, and the placement "auto" gives each (docs/thermostat.md quotes it)."""
    from .catalogue import get_method

    head = "method".ljust(22) + "".join(f"ends {x:<6g}" for x in h_omegas) + \
        "".join(f"middle {x:<6g}" for x in h_omegas) + "auto"
    lines = [head]
    for name in names:
        method = get_method(name)
        steps = method.splitting.steps
        row = name.ljust(22)
        for position in ("ends", "middle"):
            for x in h_omegas:
                try:
                    value = f"{harmonic_sampling(with_thermostat(steps, position), x, decay)[0]:.4f}"
                except ValueError:
                    value = "-"
                row += value.ljust(len(position) + 7)
        lines.append(row + best_position(steps, method.stability))
    return "\n".join(lines)



#: What the middle placement measured against the ends in water, per method: 216 rigid SPC/E waters with PME, the
#: thermostat at collision time 0.1 ps, 12 replicas paired with a Verlet 0.5-fs reference (the frontier study's side
#: rows: ``symprk fidelity --preset frontier --out docs/data/fidelity/frontier-spce --report-only``).
MEASURED_MIDDLE = {
    "omelyan-2": "in 216 rigid SPC/E waters at 6 fs the middle ran the translational temperature 4.4 +- 0.7 K and "
                 "the potential energy 0.29 +- 0.03 kJ/mol per molecule above the reference",
    "predescu-3": "in 216 rigid SPC/E waters at 12 fs the middle ran the translational temperature 6.7 +- 0.9 K and "
                  "the potential energy 0.32 +- 0.04 kJ/mol per molecule below the reference",
}


def middle_placement_advice(name: str, steps, stability: float | None = None, h_omega: float = 0.5) -> str | None:
    """Why ``thermostat_position="middle"`` is the worse placement for the method ``name`` (its kick/drift
    ``steps``), or None where the middle is the better one (:func:`best_position`: verlet).  Names where the middle
    falls (inside a kick: no drift between its halves), the harmonic oscillator's configurational temperature at
    ``h_omega`` in both placements, and what was measured in water (:data:`MEASURED_MIDDLE`) where it was."""
    if best_position(steps, stability) == "middle":
        return None
    try:
        i = centre(steps)
    except ValueError:
        return None  # no middle: check_position / resolve refuse it with their own error
    where = "inside its central kick" if steps[i][0] != "drift" else "in its central drift"
    ends = harmonic_sampling(with_thermostat(steps, "ends"), h_omega)[0]
    middle = harmonic_sampling(with_thermostat(steps, "middle"), h_omega)[0]
    measured = MEASURED_MIDDLE.get(name)
    return (f"thermostat_position='middle' puts {name}'s thermostat {where}, where it samples configurations further "
            f"from canonical than at the ends (a harmonic mode at h*omega = {h_omega:g}: w^2<q^2>/kT = {middle:.4f} "
            f"in the middle, {ends:.4f} at the ends; 1 is exact)"
            + (f"; {measured}" if measured else "")
            + f". thermostat_position='auto' (the ends for {name}) is the better placement.")
