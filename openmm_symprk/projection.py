"""Exact-momentum kicks: the force of every kick projected onto zero net force and zero net torque.

The exact forces of an isolated system have zero net force and zero net torque, so a kick changes
neither the linear momentum P nor the angular momentum L.  OpenMM's fast platforms sum forces in
single precision (CPU; OpenCL/CUDA single and mixed), which leaves a net force and torque of round-off
size, and P and L drift (THEORY.md section 4).  The projected kick uses, for every particle with mass,

    a_i = F_i/m_i - a_cm - alpha x (r_i - r_cm)
    a_cm = sum F / M,   alpha = I^-1 tau,   tau = sum (r_i - r_cm) x F_i

with r_cm the current centre of mass and I the inertia tensor about it.  This is the mass-weighted
orthogonal projection of F/m onto the complement of the rigid-body motions: it removes exactly the
net force and the net torque, and nothing else.  For forces with zero net force and torque it is the
identity, so on Reference (double) the trajectory is unchanged to round-off.

Precision
---------
Exactness needs the net force and the torque summed precisely, from the same forces and masses the
kick uses.  Errors in r_cm and I only scale the removed correction by a relative amount of their own
size: they leave a residual of (round-off) x (round-off).  The moments are summed about the origin and
shifted to the centre of mass in global (double) expressions.

Masses.  On OpenCL/CUDA in single and mixed precision the per-DOF ``m`` of a CustomIntegrator is a
single-precision reciprocal of the stored inverse mass (measured: relative error 3e-8 on PoCL), so
``f/m`` kicks do not conserve sum(m v) with the System's masses even for exact forces.  The projection
therefore uses a per-DOF variable ``proj_mass`` holding the System's masses in double, filled by
:func:`set_masses` (called with the System before the Context is created; the integrator keeps the
values, and they survive XmlSerializer and checkpoints).  Where it is not filled (or disagrees with
``m`` by more than 1e-5 relative, e.g. after a mass change) the kick falls back to ``m``: still exact on
Reference, CPU and OpenCL/CUDA double, but limited to ~1e-9 relative in P and L on mixed precision.

Cost
----
``addComputeSum`` adds all three components of a per-DOF expression.  Components are selected by
constant per-DOF selector vectors ``proj_ex/ey/ez`` = (1,0,0), (0,1,0), (0,0,1), so 15 of the 16 sums
are plain scalar expressions (the CPU and Reference platforms evaluate vector functions such as
``_x``, ``cross`` and ``vector`` on a slow interpreted path, ~4x a scalar pass); only the torque
density, the permuted coordinates and the final acceleration use vector functions.  A full projection
is 5 per-DOF passes and 16 sums (on OpenCL each sum is a kernel pair plus a download, ~30 us on PoCL).

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
(:class:`~openmm_symprk.integrators.PRKIntegrator` refuses ``exact_momentum=True`` there).
"""
from __future__ import annotations

import openmm as mm

PREFIX = "proj_"

#: Relative Tikhonov shift of the inertia tensor (times its trace) before inversion, so that a linear
#: molecule (one principal moment zero) or a single particle gives a finite alpha.  The shift changes
#: the removed torque by a relative 1e-12 of itself, i.e. of a round-off-sized torque: negligible.
REGULARISATION = 1e-12

#: Relative tolerance within which ``proj_mass`` must agree with OpenMM's per-DOF ``m`` to be used.
MASS_TOLERANCE = 1e-5

_AXES = ("x", "y", "z")
_PAIRS = ("xx", "yy", "zz", "xy", "yz", "zx")

#: Global variables, all prefixed ``proj_``: raw sums (3x the value for M3, see the module docstring)
#: then derived quantities.
GLOBALS = tuple(
    ["chg", "M3"] + [f"mx{a}" for a in _AXES] + [f"f{a}" for a in _AXES] + [f"t{a}" for a in _AXES]
    + [f"q{p}" for p in _PAIRS]
    + ["M"] + [f"c{a}" for a in _AXES] + [f"acm{a}" for a in _AXES] + [f"tau{a}" for a in _AXES]
    + [f"I{p}" for p in _PAIRS] + [f"adj{p}" for p in _PAIRS] + ["det"] + [f"al{a}" for a in _AXES])
#: Per-DOF variables: selectors, masses, masked force, torque density, permuted x, cache.
PER_DOF = ("ex", "ey", "ez", "mass", "fm", "t", "xp", "xref", "aref", "raw")


def _g(name: str) -> str:
    return PREFIX + name


def _names(integrator):
    out = {integrator.getGlobalVariableName(i) for i in range(integrator.getNumGlobalVariables())}
    out |= {integrator.getPerDofVariableName(i) for i in range(integrator.getNumPerDofVariables())}
    return out


def add_projection_variables(integrator: mm.CustomIntegrator, system: mm.System | None = None) -> None:
    """Declare the global and per-DOF variables the projection uses (once per integrator).

    The selector vectors are set as one-element per-DOF values, which OpenMM's
    ``CustomIntegrator::initialize`` broadcasts to every particle.  With ``system`` the exact masses
    are filled in too (see :func:`set_masses`)."""
    existing = _names(integrator)
    for n in GLOBALS:
        if _g(n) not in existing:
            integrator.addGlobalVariable(_g(n), 0.0)
    for n in PER_DOF:
        if _g(n) not in existing:
            integrator.addPerDofVariable(_g(n), 0.0)
    for n, e in (("ex", (1, 0, 0)), ("ey", (0, 1, 0)), ("ez", (0, 0, 1))):
        integrator.setPerDofVariableByName(_g(n), [mm.Vec3(*e)])
    if system is not None:
        set_masses(integrator, system)


def set_masses(integrator: mm.CustomIntegrator, system: mm.System) -> None:
    """Store the System's masses (double) in the integrator's ``proj_mass`` variable.

    Call it before the Context is created (or any time after: the values are then uploaded at once).
    Needed for exact momentum on mixed precision (see the module docstring); harmless elsewhere."""
    if _g("mass") not in _names(integrator):
        raise ValueError("this integrator has no exact-momentum projection (compile with exact_momentum=True)")
    ms = [system.getParticleMass(i) for i in range(system.getNumParticles())]
    ms = [m._value if hasattr(m, "_value") else float(m) for m in ms]  # dalton
    integrator.setPerDofVariableByName(_g("mass"), [mm.Vec3(m, m, m) for m in ms])


def _first_call(integrator) -> tuple:
    """(first projection in this program?, inside an open block?) from the computations so far."""
    first = True
    depth = 0
    for i in range(integrator.getNumComputations()):
        kind, var, _ = integrator.getComputationStep(i)
        if var.startswith(PREFIX):
            first = False
        if kind in (mm.CustomIntegrator.IfBlockStart, mm.CustomIntegrator.WhileBlockStart):
            depth += 1
        elif kind == mm.CustomIntegrator.BlockEnd:
            depth -= 1
    return first, depth > 0


def emit_projected_acceleration(integrator: mm.CustomIntegrator, target: str, reuse: bool | None = None) -> None:
    """Append the computations that set per-DOF ``target`` to the projected acceleration.

    References only ``f`` (all force groups), ``m`` and ``x``: one force evaluation if the forces are
    not cached, as for a plain ``f/m`` kick.  ``target`` must already be a per-DOF variable.
    ``reuse`` (default: the first call of a program outside any block) emits the cache check."""
    ig = integrator
    g = _g
    first, in_block = _first_call(ig)
    if reuse is None:
        reuse = first and not in_block
    mass, fm = g("mass"), g("fm")
    # Exact masses where they were provided and still agree with OpenMM's (else m); 0 for virtual sites.
    ig.addComputePerDof(mass, f"select(step({MASS_TOLERANCE!r}*m - abs({mass} - m)), {mass}, m)")
    ig.addComputePerDof(fm, f"select({mass}, f, 0)")
    raw = f"select({mass}, {fm}/{mass}, 0)"
    if reuse:
        ig.addComputeSum(g("chg"), f"(x - {g('xref')})^2 + ({raw} - {g('raw')})^2")
        ig.beginIfBlock(f"{g('chg')} != 0")
    _emit_full(ig, target)
    if reuse:
        ig.endBlock()
        ig.addComputePerDof(target, f"select({g('chg')}, {target}, {g('aref')})")
    # Remember where and from what this acceleration was computed, for the next step's first kick.
    ig.addComputePerDof(g("xref"), "x")
    ig.addComputePerDof(g("raw"), raw)
    ig.addComputePerDof(g("aref"), target)


def _emit_full(ig, target):
    g = _g
    mass, fm = g("mass"), g("fm")
    e = {a: g(f"e{a}") for a in _AXES}
    # Torque density about the origin and cyclically permuted coordinates (y, z, x).
    ig.addComputePerDof(g("t"), f"cross(x, {fm})")
    ig.addComputePerDof(g("xp"), "vector(_y(x), _z(x), _x(x))")
    # -- sums: 16 scalar passes --
    ig.addComputeSum(g("M3"), mass)  # 3M: a scalar per-DOF value counts once per component
    for a in _AXES:
        ig.addComputeSum(g(f"mx{a}"), f"{mass}*x*{e[a]}")
    for a in _AXES:
        ig.addComputeSum(g(f"f{a}"), f"{fm}*{e[a]}")
    for a in _AXES:
        ig.addComputeSum(g(f"t{a}"), f"{g('t')}*{e[a]}")
    for a in _AXES:
        ig.addComputeSum(g(f"q{a}{a}"), f"{mass}*x*x*{e[a]}")
    # x * xp selects x_x x_y, x_y x_z, x_z x_x on the three components
    for a, p in zip(_AXES, ("xy", "yz", "zx")):
        ig.addComputeSum(g(f"q{p}"), f"{mass}*x*{g('xp')}*{e[a]}")
    # -- globals (double precision on every platform) --
    M = g("M")
    ig.addComputeGlobal(M, f"{g('M3')}/3")
    inv = f"select({M}, 1/{M}, 0)"
    for a in _AXES:
        ig.addComputeGlobal(g(f"c{a}"), f"{g(f'mx{a}')}*{inv}")
        ig.addComputeGlobal(g(f"acm{a}"), f"{g(f'f{a}')}*{inv}")
    c = {a: g(f"c{a}") for a in _AXES}
    F = {a: g(f"f{a}") for a in _AXES}
    # torque about the centre of mass: tau = tau_origin - c x F
    for a, b, d in (("x", "y", "z"), ("y", "z", "x"), ("z", "x", "y")):
        ig.addComputeGlobal(g(f"tau{a}"), f"{g(f't{a}')} - ({c[b]}*{F[d]} - {c[d]}*{F[b]})")
    # second moments about the centre of mass C_ab = sum m x_a x_b - M c_a c_b; I = tr(C) 1 - C
    C = {p: f"({g(f'q{p}')} - {M}*{c[p[0]]}*{c[p[1]]})" for p in _PAIRS}
    ig.addComputeGlobal(g("Ixx"), f"{C['yy']} + {C['zz']}")
    ig.addComputeGlobal(g("Iyy"), f"{C['xx']} + {C['zz']}")
    ig.addComputeGlobal(g("Izz"), f"{C['xx']} + {C['yy']}")
    for p in ("xy", "yz", "zx"):
        ig.addComputeGlobal(g(f"I{p}"), f"-{C[p]}")
    # regularised inverse through the adjugate (I is symmetric)
    shift = f"{REGULARISATION!r}*({g('Ixx')} + {g('Iyy')} + {g('Izz')})"
    A, B, Z = (f"({g(f'I{p}')} + {shift})" for p in ("xx", "yy", "zz"))
    D, E, Fy = g("Ixy"), g("Izx"), g("Iyz")
    ig.addComputeGlobal(g("adjxx"), f"{B}*{Z} - {Fy}*{Fy}")
    ig.addComputeGlobal(g("adjyy"), f"{A}*{Z} - {E}*{E}")
    ig.addComputeGlobal(g("adjzz"), f"{A}*{B} - {D}*{D}")
    ig.addComputeGlobal(g("adjxy"), f"{E}*{Fy} - {Z}*{D}")
    ig.addComputeGlobal(g("adjzx"), f"{D}*{Fy} - {B}*{E}")
    ig.addComputeGlobal(g("adjyz"), f"{D}*{E} - {A}*{Fy}")
    det = g("det")
    ig.addComputeGlobal(det, f"{A}*{g('adjxx')} + {D}*{g('adjxy')} + {E}*{g('adjzx')}")
    adj = {p: g(f"adj{p}") for p in _PAIRS}
    adj.update({"yx": adj["xy"], "xz": adj["zx"], "zy": adj["yz"]})
    tau = {a: g(f"tau{a}") for a in _AXES}
    for a in _AXES:
        row = " + ".join(f"{adj[a + b]}*{tau[b]}" for b in _AXES)
        ig.addComputeGlobal(g(f"al{a}"), f"select({det}, ({row})/{det}, 0)")
    # -- the projected acceleration (massless particles: 0) --
    def vec(stem):
        return f"vector({g(stem + 'x')}, {g(stem + 'y')}, {g(stem + 'z')})"

    ig.addComputePerDof(
        target, f"select({mass}, {fm}/{mass} - {vec('acm')} - cross({vec('al')}, x - {vec('c')}), 0)")
