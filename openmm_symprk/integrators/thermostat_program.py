"""The velocity-rescaling thermostat as CustomIntegrator computations (the CustomIntegrator backend).

One event (:func:`emit_event`, over the fraction of the thermostat's interval its sub-step gives) computes, with ``addComputeSum`` over the degrees of freedom,

    M = sum m,  P = sum m v,  K = sum m v.v / 2
    and, when the rotation is kept (isolated System): sum m x, then, about the centre of mass R = sum m x / M, the
    second moments sum m d_a d_b and L = sum m d x v of d = x - R (about a point near the system: far from the
    origin moments about the origin cancel catastrophically),

then in global expressions the kept field u = V + w x (x - R) (V = P/M; I the inertia tensor about R, w = I^-1 L;
for a linear system, whose I is singular, w = 2 L / tr I: its two rotations), the peculiar kinetic energy K_pec = K - |P|^2/(2M) (- (L - R x P).w/2),
a standard normal r1 (``gaussian``), chi2 = sum gaussian^2 * mask over a per-DOF mask holding exactly
N_f - 1 ones, and (alpha, K') as :func:`openmm_symprk.physics.velocity_rescaling.rescaling_factor` writes them,
sign included.  Then ``v = u + alpha (v - u)`` for every particle with mass, and the heat-bath energy goes
down by K' - K_pec.

Components are selected by per-DOF selector vectors (1,0,0), (0,1,0), (0,0,1) and cross products are formed
from two cyclic permutations of x, so every pass but the two permutations runs on OpenMM's scalar path (see
:mod:`.projection`).  The temperature (K) and the collision time (ps) are global variables, so that
setTemperature/setCollisionTime act on a running Context (and a checkpoint brings back the ones it was
saved with); c = exp(-(n dt/2)/tau) is computed from ``dt`` at every event, so setStepSize is followed.
"""
from __future__ import annotations

import openmm as mm

from ..physics.temperature import R_KJ
from ..physics.velocity_rescaling import ROUNDOFF
from .projection import emit_inertia, emit_rigid_solve
from .thermostat import ThermostatSettings
from ..support.errors import InputError

__all__ = ["PREFIX", "LOST_MASK_VAR", "TEMPERATURE_VAR", "COLLISION_TIME_VAR", "HEAT_BATH_VAR", "MASK_VAR", "ALPHA_VAR",
           "KINETIC_VAR", "NEW_KINETIC_VAR", "add_variables", "emit_event", "mask_values",
           "TOTAL_KINETIC_VAR", "SKIPPED_VAR", "event_kinetic_energy", "emit_noise", "R1_VAR", "CHI2_VAR"]

PREFIX = "symprk_ts_"
TEMPERATURE_VAR = PREFIX + "temperature"  # K
COLLISION_TIME_VAR = PREFIX + "tau"  # ps
HEAT_BATH_VAR = PREFIX + "heat_bath"  # kJ/mol
MASK_VAR = PREFIX + "mask"  # per DOF: exactly dof - 1 ones
ALPHA_VAR = PREFIX + "alpha"  # the last factor applied
KINETIC_VAR = PREFIX + "kpec"  # the last peculiar kinetic energy before the event (kJ/mol)
NEW_KINETIC_VAR = PREFIX + "knew"  # and after
#: set to 1 by an event that found the mask without its dof - 1 ones (a Context reinitialized without its state
#: loses per-DOF values set while bound): the event then does nothing, and the integrator fills the mask again
LOST_MASK_VAR = PREFIX + "lost_mask"
#: the events that found no peculiar kinetic energy to scale (at most ROUNDOFF of the total) and did nothing
SKIPPED_VAR = PREFIX + "skipped"

#: the total kinetic energy before the last event (kJ/mol); with KINETIC_VAR and NEW_KINETIC_VAR it gives the
#: kinetic energy at the thermostat point (:func:`event_kinetic_energy`)
TOTAL_KINETIC_VAR = PREFIX + "K"

_AXES = ("x", "y", "z")
_PAIRS = ("xx", "yy", "zz", "xy", "yz", "zx")


def _v(name: str) -> str:
    return PREFIX + name


def _globals(keep_rotation: bool) -> tuple:
    names = ["M", *(f"P{a}" for a in _AXES), "K", *(f"V{a}" for a in _AXES), "c", "s", "r1", "chi2", "nmask", "ok",
             "sgn"]
    if keep_rotation:
        names += [*(f"mx{a}" for a in _AXES), *(f"q{p}" for p in _PAIRS), *(f"L{a}" for a in _AXES),
                  *(f"R{a}" for a in _AXES), *(f"I{p}" for p in _PAIRS), *(f"adj{p}" for p in _PAIRS), "det",
                  *(f"Lc{a}" for a in _AXES), *(f"w{a}" for a in _AXES), *(f"k{a}" for a in _AXES)]
    return tuple(_v(n) for n in names)


def _per_dof(keep_rotation: bool) -> tuple:
    return tuple(_v(n) for n in ("ex", "ey", "ez", *(("d", "xp", "xpp", "u") if keep_rotation else ())))


def add_variables(integrator: mm.CustomIntegrator, settings: ThermostatSettings) -> None:
    """Declare the thermostat's variables (the settings' temperature and collision time as initial values,
    the heat-bath energy at 0, the selector vectors broadcast from one value).  The mask is filled by
    :func:`mask_values` once the Context is known to have the System's particle count."""
    ig = integrator
    for name, value in ((TEMPERATURE_VAR, settings.temperature), (COLLISION_TIME_VAR, settings.collision_time),
                        (HEAT_BATH_VAR, 0.0), (ALPHA_VAR, 1.0), (KINETIC_VAR, 0.0), (NEW_KINETIC_VAR, 0.0),
                        (LOST_MASK_VAR, 0.0), (SKIPPED_VAR, 0.0)):
        ig.addGlobalVariable(name, float(value))
    for name in _globals(settings.keep_rotation):
        ig.addGlobalVariable(name, 0.0)
    for name in (*_per_dof(settings.keep_rotation), MASK_VAR):
        ig.addPerDofVariable(name, 0.0)
    for name, e in (("ex", (1, 0, 0)), ("ey", (0, 1, 0)), ("ez", (0, 0, 1))):
        ig.setPerDofVariableByName(_v(name), [mm.Vec3(*e)])


def mask_values(masses, dof: int) -> list:
    """The per-DOF mask: ones on the first ``dof - 1`` degrees of freedom of the particles with mass (in
    particle order, x, y, z), zeros elsewhere; summing gaussian^2 over it gives a chi-squared variable of
    dof - 1 degrees of freedom."""
    ones = max(int(dof) - 1, 0)
    out = []
    for m in masses:
        row = [0.0, 0.0, 0.0]
        if m > 0:
            for k in range(3):
                if ones > 0:
                    row[k] = 1.0
                    ones -= 1
        out.append(mm.Vec3(*row))
    if ones:
        raise InputError(f"the System's particles with mass have fewer than {dof - 1} degrees of freedom")
    return out


def _num(c) -> str:
    return repr(float(c))


def _comb(a: str, b: str, c: str) -> str:
    """The global vector (a, b, c) as a per-DOF expression on the scalar path."""
    return f"({_v(a)}*{_v('ex')} + {_v(b)}*{_v('ey')} + {_v(c)}*{_v('ez')})"


def _emit_sums(ig, keep_rotation: bool):
    v = _v
    e = {a: v(f"e{a}") for a in _AXES}
    ig.addComputeSum(v("M"), f"m*{e['x']}")
    for a in _AXES:
        ig.addComputeSum(v(f"P{a}"), f"m*v*{e[a]}")
    ig.addComputeSum(v("K"), "0.5*m*v*v")
    if not keep_rotation:
        return
    # the moments about the centre of mass R (a first pass), not about the origin: far from the origin
    # sum m x x^T - M R R^T and L - R x P cancel catastrophically (a cluster 1e4 nm away lost L to 1e-6)
    M = v("M")
    inv = f"select({M}, 1/{M}, 0)"
    for a in _AXES:
        ig.addComputeSum(v(f"mx{a}"), f"m*x*{e[a]}")
    for a in _AXES:
        ig.addComputeGlobal(v(f"R{a}"), f"{v(f'mx{a}')}*{inv}")
    d, xp, xpp = v("d"), v("xp"), v("xpp")
    ig.addComputePerDof(d, f"x - {_comb('Rx', 'Ry', 'Rz')}")
    ig.addComputePerDof(xp, f"vector(_y({d}), _z({d}), _x({d}))")
    ig.addComputePerDof(xpp, f"vector(_z({d}), _x({d}), _y({d}))")
    for a in _AXES:
        ig.addComputeSum(v(f"q{a}{a}"), f"m*{d}*{d}*{e[a]}")
    for a, p in zip(_AXES, ("xy", "yz", "zx")):  # d * dp = (d_x d_y, d_y d_z, d_z d_x)
        ig.addComputeSum(v(f"q{p}"), f"m*{d}*{xp}*{e[a]}")
    # L about R: (d X v)_x = [dpp v]_z - [dp v]_y and cyclically
    for a, b, c in (("x", "z", "y"), ("y", "x", "z"), ("z", "y", "x")):
        ig.addComputeSum(v(f"L{a}"), f"m*v*({xpp}*{e[b]} - {xp}*{e[c]})")


#: det I below this fraction of (tr I)^3: the system is linear (I about its axis is 0; a bent triatomic of 1 degree
#: is 1e-5), and its rotation is w = L / (tr I / 2), its two equal moments being tr I / 2 and L perpendicular to it
LINEAR = 1e-10


def _emit_rotation(ig):
    """The inertia tensor about R, its adjugate and determinant, and w = I^-1 L with L about R (for a linear system,
    whose I is singular, w = 2 L / tr I, its two rotations); k = V, so that the kept field is k + w x (x - R)."""
    v = _v
    zero = {a: "0" for a in _AXES}
    emit_inertia(ig, v, v("M"), zero)
    emit_rigid_solve(ig, v, zero, linear="P", moment="L", about="Lc", angular="w", base="V")
    tr = "(" + " + ".join(v(f"I{a}{a}") for a in _AXES) + ")"
    linear = f"step({_num(LINEAR)}*{tr}^3 - abs({v('det')}))"
    for a in _AXES:
        ig.addComputeGlobal(v(f"w{a}"), f"select({linear}, select({tr}, 2*{v(f'Lc{a}')}/{tr}, 0), {v(f'w{a}')})")


def emit_event(integrator: mm.CustomIntegrator, settings: ThermostatSettings, fraction: float) -> None:
    """Append one thermostat event over ``fraction`` of the thermostat's interval of n steps (c = exp(-fraction n
    dt/tau)): the coefficient of its THERMOSTAT sub-step (:mod:`openmm_symprk.methods.resolved`)."""
    ig = integrator
    v = _v
    rot = settings.keep_rotation
    dof = int(settings.dof)
    _emit_sums(ig, rot)
    M = v("M")
    inv = f"select({M}, 1/{M}, 0)"
    for a in _AXES:
        ig.addComputeGlobal(v(f"V{a}"), f"{v(f'P{a}')}*{inv}")
    kept = f"0.5*({v('Px')}*{v('Px')} + {v('Py')}*{v('Py')} + {v('Pz')}*{v('Pz')})*{inv}"
    if rot:
        _emit_rotation(ig)
        kept += " + 0.5*(" + " + ".join(f"{v(f'Lc{a}')}*{v(f'w{a}')}" for a in _AXES) + ")"
    K = KINETIC_VAR
    ig.addComputeGlobal(K, f"{v('K')} - ({kept})")
    # the noise, and (alpha, K') as physics.velocity_rescaling.rescaling_factor writes them
    emit_noise(ig)
    ig.addComputeGlobal(v("c"), f"exp(-{_num(fraction * settings.interval)}*dt/{COLLISION_TIME_VAR})")
    ig.addComputeGlobal(v("s"), f"{_num(0.5 * dof * R_KJ)}*{TEMPERATURE_VAR}/{dof}")  # target / dof
    c, s, r1, chi2 = v("c"), v("s"), v("r1"), v("chi2")
    # the mask holds its dof - 1 ones (else the Context lost it: do nothing and say so), and K_pec > 0
    ig.addComputeSum(v("nmask"), MASK_VAR)
    ig.addComputeGlobal(LOST_MASK_VAR, f"max({LOST_MASK_VAR}, 1 - delta({v('nmask')} - {dof - 1}))")
    # no peculiar motion (K_pec round-off of K: at rest, or a rigid motion): no event, counted
    still = f"step({_num(ROUNDOFF)}*{v('K')} - {K})"
    ig.addComputeGlobal(SKIPPED_VAR, f"{SKIPPED_VAR} + {still}")
    ig.addComputeGlobal(v("ok"), f"(1 - {still})*delta({v('nmask')} - {dof - 1})")
    new = (f"{c}*{K} + (1 - {c})*{s}*({r1}*{r1} + {chi2}) + 2*{r1}*sqrt({c}*(1 - {c})*{K}*{s})")
    ig.addComputeGlobal(NEW_KINETIC_VAR, f"select({v('ok')}, {new}, {K})")
    # the velocity came out reversed along itself: r1 + sqrt(c K / ((1 - c) s)) < 0
    ig.addComputeGlobal(v("sgn"), f"2*step({r1} + sqrt({c}*{K}/((1 - {c})*{s}))) - 1")
    ig.addComputeGlobal(ALPHA_VAR, f"select({v('ok')}, {v('sgn')}*sqrt(max({NEW_KINETIC_VAR}, 0)/{K}), 1)")
    ig.addComputeGlobal(HEAT_BATH_VAR, f"{HEAT_BATH_VAR} - ({NEW_KINETIC_VAR} - {K})")
    alpha = ALPHA_VAR
    if rot:
        u = v("u")
        ig.addComputePerDof(u, f"{_comb('kx', 'ky', 'kz')} + {_comb('wy', 'wz', 'wx')}*{v('xpp')}"
                               f" - {_comb('wz', 'wx', 'wy')}*{v('xp')}")
    else:
        u = _comb("Vx", "Vy", "Vz")
    ig.addComputePerDof("v", f"select(m, {u} + {alpha}*(v - {u}), v)")


#: the global variables holding the last event's noise: a standard normal, and a chi-squared variate of dof - 1
R1_VAR, CHI2_VAR = _v("r1"), _v("chi2")


def emit_noise(integrator: mm.CustomIntegrator) -> None:
    """Append the noise of one event: ``R1_VAR`` a standard normal, ``CHI2_VAR`` the sum of squared standard normals
    over the per-DOF mask (:func:`mask_values`: dof - 1 of them, a chi-squared variate of dof - 1 degrees of freedom).
    Every event draws it so; :mod:`.noise` draws it alone, to check the numbers."""
    integrator.addComputeGlobal(R1_VAR, "gaussian")
    integrator.addComputeSum(CHI2_VAR, f"gaussian*gaussian*{MASK_VAR}")


def event_kinetic_energy(integrator: mm.CustomIntegrator) -> float:
    """The total kinetic energy (kJ/mol) just after the last thermostat event: the kept part (centre-of-mass
    motion, and rigid rotation of an isolated System), which an event leaves alone, plus the peculiar part the event
    drew.  0 before the first event."""
    get = integrator.getGlobalVariableByName
    return float(get(TOTAL_KINETIC_VAR) - get(KINETIC_VAR) + get(NEW_KINETIC_VAR))
