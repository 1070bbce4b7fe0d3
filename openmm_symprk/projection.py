"""Exact-momentum kicks: the force of every kick projected onto zero net force and zero net torque.

The exact forces of an isolated system have zero net force and zero net torque, so a kick changes
neither the linear momentum P nor the angular momentum L.  OpenMM's fast platforms sum forces in
single precision (CPU; OpenCL/CUDA single and mixed), which leaves a net force and torque of round-off
size, and P and L drift (THEORY.md section 4).  The projected kick uses, for every particle with mass,

    a_i = F_i/m_i - a_cm - alpha x (r_i - r_cm)
    a_cm = sum F / M,   alpha = I^-1 tau,   tau = sum (r_i - r_cm) x F_i

with r_cm the current centre of mass and I the inertia tensor about it.  This is the mass-weighted
orthogonal projection of F/m onto the complement of the rigid-body motions: it removes exactly the
net force and net torque, and nothing else.  For forces with zero net force and torque it is the
identity, so on Reference (double) the trajectory is unchanged to round-off.

Precision.  Exactness needs only that the net force and the torque ``tau`` are summed precisely and
consistently with the forces used in the kick; errors in r_cm and I change the correction by a
relative amount of their own size, i.e. they leave a residual of (round-off) x (round-off).  The sums
are formed about the origin and shifted to the centre of mass in global (double) expressions.

Program (appended to a CustomIntegrator by :mod:`openmm_symprk.program` when ``exact_momentum=True``):
one pass computing a per-DOF copy of the force with massless particles masked out, then 15 sums
(mass, first and second mass moments of x, net force, torque about the origin), global expressions
for r_cm, a_cm, tau, I and the regularised inverse (adjugate / determinant), and one per-DOF pass
for ``target``.  ``addComputeSum`` adds all three components of a per-DOF expression, so every
component is selected with ``_x``/``_y``/``_z`` and its scalar value, broadcast to x, y and z, is
summed three times: the globals divide by 3 (exact in binary floating point up to one rounding).

Massless particles (virtual sites) are excluded from every sum and get ``target = 0`` (OpenMM does
not move them with per-DOF updates anyway; their positions come from the parent atoms).

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

_AXES = ("x", "y", "z")
_PAIRS = ("xx", "yy", "zz", "xy", "xz", "yz")

#: Global variables (name -> meaning), all prefixed ``proj_``.
GLOBALS = (
    ["M3"] + [f"mx{a}" for a in _AXES] + [f"f{a}" for a in _AXES] + [f"t{a}" for a in _AXES]
    + [f"q{p}" for p in _PAIRS]  # raw sums (3x the value, see the module docstring)
    + ["M"] + [f"c{a}" for a in _AXES] + [f"acm{a}" for a in _AXES] + [f"tau{a}" for a in _AXES]
    + [f"I{p}" for p in _PAIRS] + [f"adj{p}" for p in _PAIRS] + ["det"] + [f"al{a}" for a in _AXES]
)
PER_DOF = ("fm",)  # the force with massless particles masked out


def _g(name: str) -> str:
    return PREFIX + name


def add_projection_variables(integrator: mm.CustomIntegrator) -> None:
    """Declare the global and per-DOF variables the projection uses (once per integrator)."""
    existing = {integrator.getGlobalVariableName(i) for i in range(integrator.getNumGlobalVariables())}
    existing |= {integrator.getPerDofVariableName(i) for i in range(integrator.getNumPerDofVariables())}
    for n in GLOBALS:
        if _g(n) not in existing:
            integrator.addGlobalVariable(_g(n), 0.0)
    for n in PER_DOF:
        if _g(n) not in existing:
            integrator.addPerDofVariable(_g(n), 0.0)


def emit_projected_acceleration(integrator: mm.CustomIntegrator, target: str) -> None:
    """Append the computations that set per-DOF ``target`` to the projected acceleration.

    References only ``f`` (all force groups), ``m`` and ``x``: one force evaluation if the forces are
    not cached, as for a plain ``f/m`` kick.  ``target`` must already be a per-DOF variable."""
    ig = integrator
    g = _g
    fm = g("fm")
    # Forces of particles with mass only (a virtual site's own force entry is not counted twice).
    ig.addComputePerDof(fm, "select(m, f, 0)")
    # -- sums (each is 3x the quantity: a scalar per-DOF expression is broadcast to x, y and z) --
    ig.addComputeSum(g("M3"), "m")
    for a in _AXES:
        ig.addComputeSum(g(f"mx{a}"), f"m*_{a}(x)")
    for a in _AXES:
        ig.addComputeSum(g(f"f{a}"), f"_{a}({fm})")
    for a in _AXES:
        ig.addComputeSum(g(f"t{a}"), f"_{a}(cross(x, {fm}))")
    for p in _PAIRS:
        ig.addComputeSum(g(f"q{p}"), f"m*_{p[0]}(x)*_{p[1]}(x)")
    # -- globals (double precision on every platform) --
    M = g("M")
    ig.addComputeGlobal(M, f"{g('M3')}/3")
    inv = f"select({M}, 1/(3*{M}), 0)"
    for a in _AXES:
        ig.addComputeGlobal(g(f"c{a}"), f"{g(f'mx{a}')}*{inv}")
        ig.addComputeGlobal(g(f"acm{a}"), f"{g(f'f{a}')}*{inv}")
    c = {a: g(f"c{a}") for a in _AXES}
    F = {a: f"({g(f'f{a}')}/3)" for a in _AXES}
    # torque about the centre of mass: tau = tau_origin - c x F
    for a, b, d in (("x", "y", "z"), ("y", "z", "x"), ("z", "x", "y")):
        ig.addComputeGlobal(g(f"tau{a}"), f"{g(f't{a}')}/3 - ({c[b]}*{F[d]} - {c[d]}*{F[b]})")
    # second moments about the centre of mass C_ab = sum m x_a x_b - M c_a c_b; I = tr(C) 1 - C
    C = {p: f"({g(f'q{p}')}/3 - {M}*{c[p[0]]}*{c[p[1]]})" for p in _PAIRS}
    ig.addComputeGlobal(g("Ixx"), f"{C['yy']} + {C['zz']}")
    ig.addComputeGlobal(g("Iyy"), f"{C['xx']} + {C['zz']}")
    ig.addComputeGlobal(g("Izz"), f"{C['xx']} + {C['yy']}")
    for p in ("xy", "xz", "yz"):
        ig.addComputeGlobal(g(f"I{p}"), f"-{C[p]}")
    # regularised inverse through the adjugate
    shift = f"{REGULARISATION!r}*({g('Ixx')} + {g('Iyy')} + {g('Izz')})"
    A, B, Cz = (f"({g(f'I{p}')} + {shift})" for p in ("xx", "yy", "zz"))
    D, E, Fy = g("Ixy"), g("Ixz"), g("Iyz")
    ig.addComputeGlobal(g("adjxx"), f"{B}*{Cz} - {Fy}*{Fy}")
    ig.addComputeGlobal(g("adjyy"), f"{A}*{Cz} - {E}*{E}")
    ig.addComputeGlobal(g("adjzz"), f"{A}*{B} - {D}*{D}")
    ig.addComputeGlobal(g("adjxy"), f"{E}*{Fy} - {Cz}*{D}")
    ig.addComputeGlobal(g("adjxz"), f"{D}*{Fy} - {B}*{E}")
    ig.addComputeGlobal(g("adjyz"), f"{D}*{E} - {A}*{Fy}")
    det = g("det")
    ig.addComputeGlobal(det, f"{A}*{g('adjxx')} + {D}*{g('adjxy')} + {E}*{g('adjxz')}")
    adj = {p: g(f"adj{p}") for p in _PAIRS}
    adj.update({"yx": adj["xy"], "zx": adj["xz"], "zy": adj["yz"]})
    tau = {a: g(f"tau{a}") for a in _AXES}
    for a in _AXES:
        row = " + ".join(f"{adj[a + b]}*{tau[b]}" for b in _AXES)
        ig.addComputeGlobal(g(f"al{a}"), f"select({det}, ({row})/{det}, 0)")
    # -- the projected acceleration (massless particles: 0) --
    vec = lambda stem: f"vector({g(stem + 'x')}, {g(stem + 'y')}, {g(stem + 'z')})"  # noqa: E731
    ig.addComputePerDof(
        target, f"select(m, {fm}/m - {vec('acm')} - cross({vec('al')}, x - {vec('c')}), 0)")
