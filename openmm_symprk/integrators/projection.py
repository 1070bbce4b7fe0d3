"""Exact-momentum kicks: the force of every kick projected onto zero net force and zero net torque.

The exact forces of an isolated system have zero net force and zero net torque, so a kick changes
neither the linear momentum P nor the angular momentum L.  OpenMM's fast platforms sum forces in
single precision (CPU; OpenCL/CUDA single and mixed), which leaves a net force and torque of round-off
size, and P and L drift (docs/theory.md, section 4).  The projected kick uses, for every particle with mass,

    a_i = F_i/m_i - a_cm - alpha x (r_i - r_cm)
    a_cm = sum F / M,   alpha = I^-1 tau,   tau = sum (r_i - r_cm) x F_i

with r_cm the current centre of mass and I the inertia tensor about it.  This is the mass-weighted
orthogonal projection of F/m onto the complement of the rigid-body motions: it removes exactly the
net force and the net torque, and nothing else.  For forces with zero net force and torque it is the
identity, so on Reference (double) the trajectory is unchanged to round-off.

Constraint steps
----------------
On OpenCL/CUDA the SHAKE kernel for hydrogen clusters (HBonds constraints) moves the central and the
peripheral atoms with inverse masses rounded to float, so its impulses do not cancel: P and L change
by ~1e-8 relative per step even in double precision (measured on the villin scene).  In exact
arithmetic a RATTLE drift (x += h v, SHAKE, v += (x - x_u)/h) changes P by sum m (x - x_u)/h and L by
sum m x_old x (x - x_u)/h with x_old = x - h v, both zero.  :func:`emit_drift_restoration` removes
their round-off values with a rigid-body velocity correction w + gamma x (r - r_cm) (which keeps every
distance-constraint velocity condition, since (r_i - r_j).(gamma x (r_i - r_j)) = 0), and
:func:`emit_constrain_velocities` does the same for the velocity projection at the end of a step.
:mod:`openmm_symprk.integrators.program` calls both after every RATTLE drift and at the end of every step when
``exact_momentum=True``.

Precision
---------
Exactness needs the net force and the torque summed precisely, from the same forces and masses the
kick uses.  Errors in r_cm and I only scale the removed correction by a relative amount of their own
size: they leave a residual of (round-off) x (round-off).  The moments are summed about the origin and
shifted to the centre of mass in global (double) expressions; far from the origin that shift cancels, but only
the removed correction's size suffers, so it stays harmless here (measured, an 8-water cluster, 500 Verlet steps
on Reference: |dL|/|L| about the centre of mass 2e-15 at the origin, 2e-11 at 1e4 nm and 3e-10 at 1e5 nm, the
positions' own precision there; summing about the centre of mass instead gave 1e-11 and 5e-10).  The thermostat's
kept rotation, which is not such a correction, is computed about the centre of mass (:mod:`.thermostat_program`).

Masses.  On OpenCL/CUDA in single and mixed precision the per-DOF ``m`` of a CustomIntegrator is a
single-precision reciprocal of the stored inverse mass (measured: relative error 3e-8 on PoCL), so
``f/m`` kicks do not conserve sum(m v) with the System's masses even for exact forces.  The projection
therefore uses a per-DOF variable ``proj_mass`` holding the System's masses in double, filled by
:func:`set_masses` (called by the integrator at its first step, from the masses of its ``system=``; the
values then survive XmlSerializer and checkpoints).  Where it is not filled (or disagrees with
``m`` by more than 1e-5 relative, e.g. after a mass change) the kick falls back to ``m``: still exact on
Reference, CPU and OpenCL/CUDA double, but limited to ~1e-6 relative in L on mixed precision.

Cost
----
``addComputeSum`` adds all three components of a per-DOF expression.  Components are selected by
constant per-DOF selector vectors ``proj_ex/ey/ez`` = (1,0,0), (0,1,0), (0,0,1), and cross products are
written with two cyclically permuted copies of x (xp = (y, z, x), xpp = (z, x, y)): (a x b) =
a_p * b_pp - a_pp * b_p componentwise.  So every sum and every correction is a plain scalar
expression; the CPU and Reference platforms evaluate vector functions (``_x``, ``cross``,
``vector``) on a slow interpreted path, 4-10x a scalar pass, and only the two permutations (once per
set of positions) and the drift torque use them.  A kick projection costs 6 sums, plus 10 sums for
the geometry (total mass, centre of mass, second moments) when the positions changed since the last
correction; on OpenCL each sum is a kernel pair plus a download (~30 us on PoCL), on CPU/Reference each
pass costs ~40 ns per degree of freedom.

Kick-drift-kick splittings evaluate their opening kick at the positions and forces of the previous
step's closing kick.  The first projection of the program therefore checks (one sum) whether
positions, forces and masses are bit-for-bit those of the last projection, and reuses its result if
so, inside one ``if`` block; any change (setPositions, a parameter change, a barostat, a different
stage) recomputes.  When the first call is already inside a block (implicit methods' while loop) the
check is not emitted.

Massless particles (virtual sites) are excluded from every sum and get ``target = 0`` (OpenMM does not
move them with per-DOF updates anyway; their positions come from the parent atoms).

The projection assumes a non-periodic system: with periodic boundary conditions the torque about the
centre of mass is not zero for the exact forces and removing it changes the dynamics
(the integrators refuse ``exact_momentum=True`` there, see
:func:`openmm_symprk.systems.checks.validate_system`).
"""
from __future__ import annotations


import openmm as mm

from ..support.errors import InputError

PREFIX = "proj_"

#: Relative Tikhonov shift of the inertia tensor (times its trace) before inversion, so that a linear
#: molecule (one principal moment zero) or a single particle gives a finite alpha.  The shift changes
#: the removed torque by a relative 1e-12 of itself, i.e. of a round-off-sized torque: negligible.
REGULARISATION = 1e-12

#: Relative tolerance within which ``proj_mass`` must agree with OpenMM's per-DOF ``m`` to be used.
MASS_TOLERANCE = 1e-5

_AXES = ("x", "y", "z")
_PAIRS = ("xx", "yy", "zz", "xy", "yz", "zx")

#: Global variables, all prefixed ``proj_``: raw sums, then derived quantities.
GLOBALS = tuple(
    ["chg", "M3"] + [f"mx{a}" for a in _AXES] + [f"q{p}" for p in _PAIRS]
    + [f"f{a}" for a in _AXES] + [f"t{a}" for a in _AXES]
    + ["M"] + [f"c{a}" for a in _AXES] + [f"I{p}" for p in _PAIRS] + [f"adj{p}" for p in _PAIRS] + ["det"]
    + [f"acm{a}" for a in _AXES] + [f"tau{a}" for a in _AXES] + [f"al{a}" for a in _AXES]
    + [f"k{a}" for a in _AXES])
#: Per-DOF variables: selectors, masses, force/impulse, torque density, permuted x, cache, saved v.
PER_DOF = ("ex", "ey", "ez", "mass", "fm", "t", "xp", "xpp", "xref", "aref", "raw", "vb")



def _g(name: str) -> str:
    return PREFIX + name


#: The per-DOF variable holding the System's masses (set while bound: :func:`set_masses`).
MASS_VAR = _g("mass")


def _names(integrator):
    out = {integrator.getGlobalVariableName(i) for i in range(integrator.getNumGlobalVariables())}
    out |= {integrator.getPerDofVariableName(i) for i in range(integrator.getNumPerDofVariables())}
    return out


def add_projection_variables(integrator: mm.CustomIntegrator) -> None:
    """Declare the global and per-DOF variables the projection uses (once per integrator).

    The selector vectors are set as one-element per-DOF values, which OpenMM's
    ``CustomIntegrator::initialize`` broadcasts to every particle.  The exact masses are filled in by
    :func:`set_masses` once the integrator knows the Context has the System's particle count."""
    existing = _names(integrator)
    for n in GLOBALS:
        if _g(n) not in existing:
            integrator.addGlobalVariable(_g(n), 0.0)
    for n in PER_DOF:
        if _g(n) not in existing:
            integrator.addPerDofVariable(_g(n), 0.0)
    for n, e in (("ex", (1, 0, 0)), ("ey", (0, 1, 0)), ("ez", (0, 0, 1))):
        integrator.setPerDofVariableByName(_g(n), [mm.Vec3(*e)])


def set_masses(integrator: mm.CustomIntegrator, masses) -> None:
    """Store the System's masses (Da, double) in the integrator's ``proj_mass`` variable.

    The integrator classes call it at the first step, once the Context is known to have as many particles
    as there are masses (a per-DOF variable of another length would be read out of bounds).  Needed for
    exact momentum on single/mixed precision OpenCL/CUDA (see the module docstring); harmless elsewhere."""
    if _g("mass") not in _names(integrator):
        raise InputError("this integrator has no exact-momentum projection (compile with exact_momentum=True)")
    integrator.setPerDofVariableByName(_g("mass"), [mm.Vec3(m, m, m) for m in map(float, masses)])


# -- static analysis of the program emitted so far -------------------------------------------------
_BLOCKS = (mm.CustomIntegrator.IfBlockStart, mm.CustomIntegrator.WhileBlockStart)


def _steps(ig):
    return [ig.getComputationStep(i) for i in range(ig.getNumComputations())]


def _first_call(steps) -> tuple:
    """(no projection emitted yet in this program?, inside an open block?)."""
    first = not any(var.startswith(PREFIX) for _, var, _ in steps)
    depth = 0
    for kind, _, _ in steps:
        if kind in _BLOCKS:
            depth += 1
        elif kind == mm.CustomIntegrator.BlockEnd:
            depth -= 1
    return first, depth > 0


def _geometry_current(steps) -> bool:
    """True if the centre of mass and inertia were computed since x last changed (same block level)."""
    for kind, var, _ in reversed(steps):
        if kind == mm.CustomIntegrator.ComputeGlobal and var == _g("det"):
            return True
        if kind in _BLOCKS or kind in (mm.CustomIntegrator.BlockEnd, mm.CustomIntegrator.ConstrainPositions,
                                       mm.CustomIntegrator.UpdateContextState):
            return False
        if kind == mm.CustomIntegrator.ComputePerDof and var == "x":
            return False
    return False


def _mass_current(steps) -> bool:
    return any(k == mm.CustomIntegrator.ComputePerDof and v == _g("mass") for k, v, _ in steps)


# -- building blocks --------------------------------------------------------------------------------
def _emit_mass(ig):
    """proj_mass: the exact masses where provided and still agreeing with OpenMM's m, else m."""
    mass = _g("mass")
    ig.addComputePerDof(mass, f"select(step({MASS_TOLERANCE!r}*m - abs({mass} - m)), {mass}, m)")


def emit_second_moments(ig, name, mass: str) -> None:
    """The sums name('mx<a>') = sum mass x_a and name('q<ab>') = sum mass x_a x_b (the pairs of _PAIRS), on the
    scalar path: ``name('e<a>')`` are the unit vectors and ``name('xp')`` the per-DOF cyclic permutation
    (x_y, x_z, x_x) of x, both already set.  ``name`` maps a short name to the program's variable."""
    e = {a: name(f"e{a}") for a in _AXES}
    for a in _AXES:
        ig.addComputeSum(name(f"mx{a}"), f"{mass}*x*{e[a]}")
    for a in _AXES:
        ig.addComputeSum(name(f"q{a}{a}"), f"{mass}*x*x*{e[a]}")
    for a, p in zip(_AXES, ("xy", "yz", "zx")):  # x * xp = (x_x x_y, x_y x_z, x_z x_x)
        ig.addComputeSum(name(f"q{p}"), f"{mass}*x*{name('xp')}*{e[a]}")


def emit_inertia(ig, name, M: str, centre: dict, shift: str | None = None) -> None:
    """From the second moments of :func:`emit_second_moments`, the total mass ``M`` and the point ``centre``
    (axis -> variable): the inertia tensor about the centre, name('I<ab>'), and the adjugate name('adj<ab>') and
    determinant name('det') of I (plus ``shift`` on its diagonal, a regularisation, when given).  With the
    second moments about the centre C_ab = sum m x_a x_b - M c_a c_b, I = tr(C) 1 - C."""
    C = {p: f"({name(f'q{p}')} - {M}*{centre[p[0]]}*{centre[p[1]]})" for p in _PAIRS}
    ig.addComputeGlobal(name("Ixx"), f"{C['yy']} + {C['zz']}")
    ig.addComputeGlobal(name("Iyy"), f"{C['xx']} + {C['zz']}")
    ig.addComputeGlobal(name("Izz"), f"{C['xx']} + {C['yy']}")
    for p in ("xy", "yz", "zx"):
        ig.addComputeGlobal(name(f"I{p}"), f"-{C[p]}")
    if shift is None:
        A, B, Z = (name(f"I{p}") for p in ("xx", "yy", "zz"))
    else:
        A, B, Z = (f"({name(f'I{p}')} + {shift})" for p in ("xx", "yy", "zz"))
    D, E, Fy = name("Ixy"), name("Izx"), name("Iyz")
    ig.addComputeGlobal(name("adjxx"), f"{B}*{Z} - {Fy}*{Fy}")
    ig.addComputeGlobal(name("adjyy"), f"{A}*{Z} - {E}*{E}")
    ig.addComputeGlobal(name("adjzz"), f"{A}*{B} - {D}*{D}")
    ig.addComputeGlobal(name("adjxy"), f"{E}*{Fy} - {Z}*{D}")
    ig.addComputeGlobal(name("adjzx"), f"{D}*{Fy} - {B}*{E}")
    ig.addComputeGlobal(name("adjyz"), f"{D}*{E} - {A}*{Fy}")
    ig.addComputeGlobal(name("det"), f"{A}*{name('adjxx')} + {D}*{name('adjxy')} + {E}*{name('adjzx')}")


def emit_rigid_solve(ig, name, centre: dict, *, linear: str, moment: str, about: str, angular: str, base: str,
                     scale: str | None = None) -> None:
    """The rigid-body field base + angular x (x - centre) = k + angular x x, from the inertia tensor of
    :func:`emit_inertia` (its adjugate and determinant): the moment about the centre
    name(about) = name(moment) - centre x name(linear) (a moment taken about the origin), angular = I^-1 of it
    (times ``scale`` when given; 0 for a singular I), and k = name(base) - angular x centre."""
    cyclic = (("x", "y", "z"), ("y", "z", "x"), ("z", "x", "y"))
    lin = {a: name(f"{linear}{a}") for a in _AXES}
    for a, b, d in cyclic:
        ig.addComputeGlobal(name(f"{about}{a}"),
                            f"{name(f'{moment}{a}')} - ({centre[b]}*{lin[d]} - {centre[d]}*{lin[b]})")
    adj = {p: name(f"adj{p}") for p in _PAIRS}
    adj.update({"yx": adj["xy"], "xz": adj["zx"], "zy": adj["yz"]})
    det = name("det")
    for a in _AXES:
        row = " + ".join(f"{adj[a + b]}*{name(f'{about}{b}')}" for b in _AXES)
        solved = f"({row})/{det}" if scale is None else f"{scale}*({row})/{det}"
        ig.addComputeGlobal(name(f"{angular}{a}"), f"select({det}, {solved}, 0)")
    w = {a: name(f"{angular}{a}") for a in _AXES}
    for a, b, d in cyclic:
        ig.addComputeGlobal(name(f"k{a}"), f"{name(f'{base}{a}')} - ({w[b]}*{centre[d]} - {w[d]}*{centre[b]})")


def _emit_geometry(ig):
    """Centre of mass, inertia tensor about it and its regularised adjugate/determinant, at x."""
    g = _g
    mass = g("mass")
    # cyclic permutations (y, z, x) and (z, x, y): the only vector-function passes of a correction
    ig.addComputePerDof(g("xp"), "vector(_y(x), _z(x), _x(x))")
    ig.addComputePerDof(g("xpp"), "vector(_z(x), _x(x), _y(x))")
    ig.addComputeSum(g("M3"), mass)  # 3M: the scalar mass counts once per component
    emit_second_moments(ig, g, mass)
    M = g("M")
    ig.addComputeGlobal(M, f"{g('M3')}/3")
    inv = f"select({M}, 1/{M}, 0)"
    for a in _AXES:
        ig.addComputeGlobal(g(f"c{a}"), f"{g(f'mx{a}')}*{inv}")
    c = {a: g(f"c{a}") for a in _AXES}
    shift = f"{REGULARISATION!r}*({g('Ixx')} + {g('Iyy')} + {g('Izz')})"
    emit_inertia(ig, g, M, c, shift)


def _emit_solve(ig, scale: str = "1"):
    """From the sums proj_f* (net force or momentum change) and proj_t* (torque about the origin):
    proj_acm = F/M and proj_al = I^-1 (tau_origin - c x F), both times ``scale``."""
    g = _g
    M = g("M")
    inv = f"select({M}, 1/{M}, 0)"
    c = {a: g(f"c{a}") for a in _AXES}
    F = {a: g(f"f{a}") for a in _AXES}
    for a in _AXES:
        ig.addComputeGlobal(g(f"acm{a}"), f"{scale}*{F[a]}*{inv}")
    emit_rigid_solve(ig, g, c, linear="f", moment="t", about="tau", angular="al", base="acm", scale=scale)


def _rigid():
    """The rigid-body field acm + al x (x - c) = k + al x x as a scalar-path expression:
    (al x x) = (al_y, al_z, al_x) * xpp - (al_z, al_x, al_y) * xp componentwise."""
    g = _g

    def comb(a, b, c):
        return f"({g(a)}*{g('ex')} + {g(b)}*{g('ey')} + {g(c)}*{g('ez')})"

    return (f"{comb('kx', 'ky', 'kz')} + {comb('aly', 'alz', 'alx')}*{g('xpp')}"
            f" - {comb('alz', 'alx', 'aly')}*{g('xp')}")


def _emit_net(ig, vector_var: str, torque_expr: str | None = None):
    """Sums proj_f* = sum of per-DOF ``vector_var`` and proj_t* = its torque about the origin.

    Without ``torque_expr`` the torque sum x x j is formed on the scalar path from the permuted
    coordinates of the current geometry: (x x j)_x = [xpp j]_z - [xp j]_y and cyclically."""
    g = _g
    e = {a: g(f"e{a}") for a in _AXES}
    for a in _AXES:
        ig.addComputeSum(g(f"f{a}"), f"{vector_var}*{e[a]}")
    if torque_expr is not None:
        ig.addComputePerDof(g("t"), torque_expr)
        for a in _AXES:
            ig.addComputeSum(g(f"t{a}"), f"{g('t')}*{e[a]}")
    else:
        xp, xpp = g("xp"), g("xpp")
        for a, b, d in (("x", "z", "y"), ("y", "x", "z"), ("z", "y", "x")):
            ig.addComputeSum(g(f"t{a}"), f"{vector_var}*({xpp}*{e[b]} - {xp}*{e[d]})")


# -- public emitters -------------------------------------------------------------------------------
def emit_projected_acceleration(integrator: mm.CustomIntegrator, target: str, reuse: bool | None = None,
                                force: str = "f") -> None:
    """Append the computations that set per-DOF ``target`` to the projected acceleration.

    References only ``force`` (``f``: all force groups; ``f1``: force group 1), ``m`` and ``x``: one force
    evaluation if those forces are not cached, as for a plain ``f/m`` kick.  ``target`` must already be a
    per-DOF variable.  ``reuse`` (default: the first call of a program outside any block) emits the cache
    check."""
    ig = integrator
    g = _g
    steps = _steps(ig)
    first, in_block = _first_call(steps)
    if reuse is None:
        reuse = first and not in_block
    if not _mass_current(steps):
        _emit_mass(ig)
    mass, fm = g("mass"), g("fm")
    ig.addComputePerDof(fm, f"select({mass}, {force}, 0)")
    raw = f"select({mass}, {fm}/{mass}, 0)"
    if reuse:
        ig.addComputeSum(g("chg"), f"(x - {g('xref')})^2 + ({raw} - {g('raw')})^2")
        ig.beginIfBlock(f"{g('chg')} != 0")
    if not _geometry_current(_steps(ig)):
        _emit_geometry(ig)
    _emit_net(ig, fm)
    _emit_solve(ig)
    ig.addComputePerDof(target, f"select({mass}, {fm}/{mass} - ({_rigid()}), 0)")
    # Remember where and from what this acceleration was computed, for the next step's first kick.
    ig.addComputePerDof(g("xref"), "x")
    ig.addComputePerDof(g("raw"), raw)
    ig.addComputePerDof(g("aref"), target)
    if reuse:
        ig.endBlock()
        ig.addComputePerDof(target, f"select({g('chg')}, {target}, {g('aref')})")


def emit_drift_restoration(integrator: mm.CustomIntegrator, unconstrained: str = "symprk_xu",
                           substep: str = "dt") -> None:
    """After a RATTLE drift ``x += h v; xu = x; ConstrainPositions; v += (x - xu)/h``: remove the
    round-off net momentum and torque of the constraint impulses m (x - xu)/h (about the positions
    before the drift, x - h v) with a rigid-body velocity correction at the current positions.

    ``unconstrained``: the per-DOF variable holding the positions before ConstrainPositions;
    ``substep``: the drift's substep h as an expression (e.g. ``0.5*dt``)."""
    ig = integrator
    g = _g
    if not _mass_current(_steps(ig)):
        _emit_mass(ig)
    mass, j = g("mass"), g("fm")
    h = f"({substep})"
    ig.addComputePerDof(j, f"select({mass}, {mass}*(x - {unconstrained})/{h}, 0)")
    if not _geometry_current(_steps(ig)):
        _emit_geometry(ig)
    _emit_net(ig, j, f"cross(x - {h}*v, {j})")  # torque about the positions before the drift
    _emit_solve(ig)
    ig.addComputePerDof("v", f"v - select({mass}, {_rigid()}, 0)")


def emit_constrain_velocities(integrator: mm.CustomIntegrator) -> None:
    """``addConstrainVelocities`` followed by the removal of the round-off net momentum and torque of
    the velocity-constraint impulses (a rigid-body correction; distance constraints stay satisfied)."""
    ig = integrator
    g = _g
    if not _mass_current(_steps(ig)):
        _emit_mass(ig)
    mass, j, vb = g("mass"), g("fm"), g("vb")
    ig.addComputePerDof(vb, "v")
    ig.addConstrainVelocities()
    ig.addComputePerDof(j, f"select({mass}, {mass}*(v - {vb}), 0)")
    if not _geometry_current(_steps(ig)):
        _emit_geometry(ig)
    _emit_net(ig, j)
    _emit_solve(ig)
    ig.addComputePerDof("v", f"v - select({mass}, {_rigid()}, 0)")
