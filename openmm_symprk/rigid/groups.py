"""Rigid molecules in an openmm.System: distance constraints that make chosen atom groups rigid.

    from openmm_symprk import make_rigid
    groups = make_rigid(system, positions, [[0, 1, 2, 3], [4, 5, 6]])
    integrator = SymplecticIntegrator(2*unit.femtoseconds, "yoshida-4", system=system)  # RATTLE

A rigid group keeps its atoms, their masses and therefore its mass, centre of mass and inertia tensor;
only distance constraints are added, the minimal rigid set (a RATTLE integrator then moves it as a
rigid body, which is the constrained formulation that Reich's Lie-Poisson reduction starts from,
docs/theory.md, section 3):

* 2 atoms: one distance (a rigid rod; no rotation about its own axis).
* 3 atoms, not collinear: the triangle, 3 distances.
* N >= 4 atoms, not coplanar: a tetrahedron of 4 well-spread atoms (6 distances), then 3 distances
  from every further atom to 3 atoms already placed that are not coplanar with it: 3N - 6 in all.
  The constraint Jacobian is checked to have full rank 3N - 6 (infinitesimal rigidity), so the
  constraint solver is well posed.

Coplanar groups of 4 or more atoms, and collinear groups of 3 or more, cannot be made rigid by
distance constraints between their atoms: the constraint gradients all lie in the plane (on the
line), so every out-of-plane (off-line) velocity satisfies the linearised constraints and the solver's
matrix is singular.  Such groups raise :class:`RigidGroupError` unless ``virtual_sites=True``: then 3
atoms (2 for a line) keep mass and carry the constraints, the others become massless virtual sites
(OutOfPlaneSite / TwoParticleAverageSite) that follow them exactly, and their masses move to the
parents so that mass and centre of mass are preserved.  The inertia tensor then changes in general
(3 point masses at fixed places have no freedom left to match it); the change is reported on the
returned :class:`RigidGroup` and in a :class:`RigidGroupWarning`.  Beware also that OpenMM 8.6's
CustomIntegrator (hence SymplecticIntegrator) on Reference/CPU recomputes virtual-site positions only
at the end of a step, so forces on interacting sites are evaluated at stale positions (measured: 55%
relative change of angular momentum in 400 steps of a 4-particle test with a charged site).

For N >= 5 the framework has pairs of constraints that share an atom without a third constraint
closing the triangle; OpenMM's CCMA solver then needs the angle between them, which it reads from a
HarmonicAngleForce, and without it the iteration diverges (measured: NaN after one step for a 5-atom
group).  :func:`make_rigid` therefore adds one HarmonicAngleForce named ``RigidGroupConstraintAngles``
whose terms all have zero force constant: no energy, no force, only the geometry for the solver.
"""
from __future__ import annotations

import itertools
import warnings
from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..physics import momenta
from ..support.errors import InputError

__all__ = ["RigidGroupError", "RigidGroupWarning", "RigidGroup", "make_rigid", "plan_rigid_group", "positions_nm",
           "ANGLE_FORCE_NAME"]

#: Name of the zero-strength HarmonicAngleForce that tells OpenMM's constraint solver the geometry.
ANGLE_FORCE_NAME = "RigidGroupConstraintAngles"


class RigidGroupError(InputError):
    """A group of atoms that cannot be made rigid as asked."""


class RigidGroupWarning(UserWarning):
    """A rigid group was built with virtual sites, which changes its inertia tensor."""


@dataclass(frozen=True)
class RigidGroup:
    """What :func:`make_rigid` did to one group."""

    atoms: tuple  # particle indices, as given
    kind: str  # "rod", "triangle", "framework", "planar-virtual-sites", "linear-virtual-sites"
    constraints: tuple  # ((i, j, distance_nm), ...) added to the System
    virtual_sites: tuple  # particle indices turned into massless virtual sites
    masses_before: tuple  # daltons, per atom of ``atoms``
    masses_after: tuple
    inertia_before: np.ndarray  # 3x3 inertia tensor about the centre of mass (dalton nm²)
    inertia_after: np.ndarray
    com_before: np.ndarray
    com_after: np.ndarray
    max_site_error: float = 0.0  # nm: largest distance between a virtual site's rule and its position
    #: ((i, j, geometric distance, constraint distance), ...): distances moved by one float32 ulp so that
    #: OpenMM does not apply SETTLE to an isosceles triangle with unequal base masses (see make_rigid)
    adjusted_constraints: tuple = ()

    @property
    def n_constraints(self) -> int:
        return len(self.constraints)

    @property
    def inertia_change(self) -> float:
        """Relative change of the inertia tensor (Frobenius norm); 0 unless virtual sites were used."""
        return float(np.linalg.norm(self.inertia_after - self.inertia_before) /
                     np.linalg.norm(self.inertia_before))


def positions_nm(positions) -> np.ndarray:
    """Positions as a finite (N, 3) float array in nm (from an array of nm or a Quantity)."""
    if unit.is_quantity(positions):
        positions = positions.value_in_unit(unit.nanometer)
    try:
        if isinstance(positions, np.ndarray):
            pos = np.asarray(positions, dtype=float)
        else:
            pos = np.array([[float(c) for c in row] for row in positions])
    except (TypeError, ValueError):
        raise InputError("positions must be an (N, 3) array of nm or a Quantity of positions") from None
    if pos.ndim != 2 or pos.shape[1] != 3 or not np.all(np.isfinite(pos)):
        raise InputError(f"positions must be a finite (N, 3) array (nm), got shape {pos.shape}")
    return pos



# -- planning ----------------------------------------------------------------------------------------
def _spread(points: np.ndarray) -> np.ndarray:
    """Singular values of the centred point cloud (descending)."""
    return np.linalg.svd(points - points.mean(0), compute_uv=False)


def _rigidity_matrix(points: np.ndarray, pairs) -> np.ndarray:
    """Jacobian of the distance constraints (rows) w.r.t. the 3N coordinates."""
    n = len(points)
    G = np.zeros((len(pairs), 3 * n))
    for row, (i, j) in enumerate(pairs):
        d = points[i] - points[j]
        G[row, 3 * i:3 * i + 3] = d
        G[row, 3 * j:3 * j + 3] = -d
    return G


def _check_rigidity(points, pairs, expected_rank, label):
    G = _rigidity_matrix(points, pairs)
    s = np.linalg.svd(G, compute_uv=False)
    size = max(np.ptp(points, axis=0).max(), 1e-300)
    rank = int(np.sum(s > 1e-8 * size))
    if rank < expected_rank or len(pairs) != expected_rank:
        raise RigidGroupError(
            f"group {label}: the {len(pairs)} distance constraints have rank {rank} < {expected_rank}; "
            f"the group is (nearly) degenerate and cannot be made rigid by constraints")
    return s[-1] / s[0]


def _tetrahedron(p: np.ndarray):
    c = p.mean(0)
    a = int(np.argmax(np.linalg.norm(p - c, axis=1)))
    b = int(np.argmax(np.linalg.norm(p - p[a], axis=1)))
    u = (p[b] - p[a]) / np.linalg.norm(p[b] - p[a])
    off = p - p[a]
    off = off - np.outer(off @ u, u)
    c3 = int(np.argmax(np.linalg.norm(off, axis=1)))
    nrm = np.cross(p[b] - p[a], p[c3] - p[a])
    nrm /= np.linalg.norm(nrm)
    d = int(np.argmax(np.abs((p - p[a]) @ nrm)))
    return [a, b, c3, d]


def _best_anchors(p, k, placed):
    """3 placed atoms for atom k, maximising the normalised volume |det(p_i - p_k)| / Π |p_i - p_k|."""
    placed = list(placed)
    near = sorted(placed[4:], key=lambda i: np.linalg.norm(p[i] - p[k]))[:6]
    cands = placed[:4] + near
    best, best_score = None, -1.0
    for trio in itertools.combinations(cands, 3):
        vs = p[list(trio)] - p[k]
        score = abs(np.linalg.det(vs)) / np.prod(np.linalg.norm(vs, axis=1))
        if score > best_score:
            best, best_score = trio, score
    return best, best_score


def _barycentric(p3: np.ndarray, x: np.ndarray):
    """OutOfPlaneSite weights (w12, w13, wcross) with x = p1 + w12 r12 + w13 r13 + wcross r12×r13 (exact)."""
    r12, r13 = p3[1] - p3[0], p3[2] - p3[0]
    A = np.column_stack([r12, r13, np.cross(r12, r13)])
    return np.linalg.solve(A, x - p3[0])


@dataclass
class _Plan:
    atoms: tuple
    kind: str
    pairs: list  # local index pairs
    parents: tuple = ()  # local indices that keep mass (virtual-site plans)
    sites: tuple = ()  # (local index, weights)
    new_masses: np.ndarray | None = None


def plan_rigid_group(positions, masses, atoms=None, virtual_sites=False, degenerate_tol=1e-3, label=None) -> _Plan:
    """Decide the constraints (and virtual sites) that make one group rigid; changes nothing.

    ``positions`` (nm) and ``masses`` (daltons) are those of the group's atoms."""
    p = np.asarray(positions, float)
    m = np.asarray(masses, float)
    n = len(p)
    atoms = tuple(range(n)) if atoms is None else tuple(atoms)
    label = label if label is not None else list(atoms)
    if n < 2:
        raise RigidGroupError(f"group {label}: a rigid group needs at least 2 atoms, got {n}")
    dmin = min(np.linalg.norm(p[i] - p[j]) for i, j in itertools.combinations(range(n), 2))
    s = _spread(p)
    if dmin <= 1e-9 * max(s[0], 1e-300):
        raise RigidGroupError(f"group {label}: two atoms sit at the same position; no rigid geometry is defined")
    if n == 2:
        return _Plan(atoms, "rod", [(0, 1)])
    collinear = s[1] <= degenerate_tol * s[0]
    planar = s[2] <= degenerate_tol * s[0]
    if collinear:
        if not virtual_sites:
            raise RigidGroupError(
                f"group {label}: its {n} atoms are collinear (spread {s[1] / s[0]:.1e} off the line). Distance "
                f"constraints between collinear atoms cannot stop the inner atoms from moving off the line "
                f"(the constraint matrix is singular). Pass virtual_sites=True to keep the two end atoms "
                f"as a rigid rod and make the others virtual sites (mass and centre of mass kept; the "
                f"moment of inertia changes), or split the group.")
        return _plan_linear_sites(p, m, atoms, label)
    if n == 3:
        return _Plan(atoms, "triangle", [(0, 1), (0, 2), (1, 2)])
    if planar:
        if not virtual_sites:
            raise RigidGroupError(
                f"group {label}: its {n} atoms are coplanar (spread {s[2] / s[0]:.1e} off the plane). Distance "
                f"constraints between coplanar atoms leave {n - 3} out-of-plane motions free (the constraint "
                f"matrix is singular), so 4 or more coplanar atoms cannot be made rigid by constraints alone. "
                f"Pass virtual_sites=True to keep 3 atoms as a rigid triangle and make the others virtual "
                f"sites (mass and centre of mass kept; the inertia tensor changes), or split the group.")
        return _plan_planar_sites(p, m, atoms, label)
    order = _tetrahedron(p)
    pairs = list(itertools.combinations(order, 2))
    placed = list(order)
    for k in range(n):
        if k in placed:
            continue
        trio, score = _best_anchors(p, k, placed)
        if score < 1e-3:
            raise RigidGroupError(
                f"group {label}: atom {atoms[k]} is (nearly) coplanar with every choice of 3 anchor atoms; "
                f"the group is too close to planar to be made rigid by constraints")
        pairs += [(k, t) for t in trio]
        placed.append(k)
    _check_rigidity(p, pairs, 3 * n - 6, label)
    return _Plan(atoms, "framework", pairs)


def _plan_planar_sites(p, m, atoms, label) -> _Plan:
    com = momenta.centre_of_mass(p, m)
    best, best_score = None, 0.0
    n = len(p)
    for trio in itertools.combinations(range(n), 3):
        q = p[list(trio)]
        area = 0.5 * np.linalg.norm(np.cross(q[1] - q[0], q[2] - q[0]))
        if area <= 0:
            continue
        w12, w13, _ = _barycentric(q, com)
        bary = np.array([1 - w12 - w13, w12, w13])
        score = bary.min() * area  # parents with positive masses, well spread
        if score > best_score:
            best, best_score = trio, score
    if best is None:
        raise RigidGroupError(
            f"group {label}: no 3 of its atoms form a triangle around the centre of mass, so the mass cannot "
            f"be moved onto 3 parent atoms with positive masses")
    q = p[list(best)]
    sites = tuple((k, tuple(_barycentric(q, p[k]))) for k in range(n) if k not in best)
    w12, w13, _ = _barycentric(q, com)
    new = np.zeros(n)
    new[list(best)] = m.sum() * np.array([1 - w12 - w13, w12, w13])
    return _Plan(atoms, "planar-virtual-sites", [(best[0], best[1]), (best[0], best[2]), (best[1], best[2])],
                 parents=best, sites=sites, new_masses=new)


def _plan_linear_sites(p, m, atoms, label) -> _Plan:
    u = p[-1] - p[0]
    t = (p - p[0]) @ u / (u @ u)
    a, b = int(np.argmin(t)), int(np.argmax(t))
    com = momenta.centre_of_mass(p, m)
    seg = p[b] - p[a]
    wb = float((com - p[a]) @ seg / (seg @ seg))
    new = np.zeros(len(p))
    new[a], new[b] = m.sum() * (1 - wb), m.sum() * wb
    sites = tuple((k, (float((p[k] - p[a]) @ seg / (seg @ seg)),)) for k in range(len(p)) if k not in (a, b))
    return _Plan(atoms, "linear-virtual-sites", [(a, b)], parents=(a, b), sites=sites, new_masses=new)


# -- applying to a System --------------------------------------------------------------------------
def make_rigid(system: mm.System, positions, groups, virtual_sites: bool = False,
               replace_constraints: bool = False, degenerate_tol: float = 1e-3) -> list:
    """Make each atom group of ``system`` rigid with distance constraints (in place).

    Parameters
    ----------
    system : openmm.System, modified in place (constraints added; with ``virtual_sites`` also masses
        and virtual sites changed).  Nothing is changed when an error is raised.
    positions : (N, 3) array in nm or a Quantity: the geometry the groups keep.
    groups : iterable of iterables of particle indices; groups must not overlap.
    virtual_sites : allow coplanar (>= 4 atoms) and collinear (>= 3 atoms) groups, built from a
        rigid triangle (rod) of parent atoms plus massless virtual sites; mass and centre of mass are
        kept, the inertia tensor is not (a RigidGroupWarning says by how much).
    replace_constraints : remove existing constraints *between atoms of one group* (the rigid set
        replaces them); without it, atoms that already take part in a constraint raise an error.
    degenerate_tol : relative spread below which a group counts as coplanar / collinear.

    Returns a list of :class:`RigidGroup`, one per group.  Intramolecular forces are left in place: they
    do no work on a rigid group (remove them to save time if you like)."""
    if not isinstance(system, mm.System):
        raise TypeError(f"system must be an openmm.System, got {type(system).__name__}")
    pos = positions_nm(positions)
    n_part = system.getNumParticles()
    if len(pos) != n_part:
        raise InputError(f"positions has {len(pos)} rows but the System has {n_part} particles")
    groups = [list(g) for g in groups]
    if not groups:
        raise InputError("no groups given")
    seen: dict = {}
    for gi, g in enumerate(groups):
        for a in g:
            if isinstance(a, bool) or not isinstance(a, (int, np.integer)) or not 0 <= a < n_part:
                raise RigidGroupError(f"group {g}: {a!r} is not a particle index of this System (0..{n_part - 1})")
            if a in seen:
                where = "twice in this group" if seen[a] == gi else f"also in group {groups[seen[a]]}"
                raise RigidGroupError(f"group {g}: atom {a} appears {where}; rigid groups must not overlap")
            seen[a] = gi
    masses = np.array([system.getParticleMass(i).value_in_unit(unit.dalton) for i in range(n_part)])
    for g in groups:
        for a in g:
            if system.isVirtualSite(a):
                raise RigidGroupError(f"group {g}: atom {a} is a virtual site; a rigid group must consist of "
                                      f"massive atoms (leave the site out: it follows its parents)")
            if masses[a] <= 0:
                raise RigidGroupError(f"group {g}: atom {a} is massless; a rigid group must consist of massive "
                                      f"atoms (massless particles do not move under the integrator)")
    # existing constraints touching group atoms
    remove = []
    for ci in range(system.getNumConstraints()):
        i, j, _ = system.getConstraintParameters(ci)
        gi, gj = seen.get(i), seen.get(j)
        if gi is None and gj is None:
            continue
        if replace_constraints and gi is not None and gi == gj:
            remove.append(ci)
            continue
        g = groups[gi if gi is not None else gj]
        hint = ("; pass replace_constraints=True to replace constraints inside the group"
                if gi == gj else "; a rigid group cannot also be constrained to atoms outside it")
        raise RigidGroupError(f"group {g}: atoms {i} and {j} are already held by constraint {ci}{hint}")
    # atoms that existing virtual sites hang on cannot become virtual sites themselves
    parents_of_sites = set()
    for k in range(n_part):
        if system.isVirtualSite(k):
            vs = system.getVirtualSite(k)
            parents_of_sites.update(vs.getParticle(t) for t in range(vs.getNumParticles()))

    plans = [plan_rigid_group(pos[g], masses[g], g, virtual_sites=virtual_sites,
                              degenerate_tol=degenerate_tol, label=g) for g in groups]
    for plan in plans:
        for k, _ in plan.sites:
            if plan.atoms[k] in parents_of_sites:
                raise RigidGroupError(
                    f"group {list(plan.atoms)}: atom {plan.atoms[k]} would become a virtual site but is the "
                    f"parent of an existing virtual site (OpenMM does not chain virtual sites)")

    # -- all checks passed: modify the System --------------------------------------------------
    for ci in sorted(remove, reverse=True):
        system.removeConstraint(ci)
    results = []
    for plan in plans:
        g = list(plan.atoms)
        p, m = pos[g], masses[g]
        dists = [float(np.linalg.norm(p[a] - p[b])) for a, b in plan.pairs]
        new_m = plan.new_masses if plan.sites else m
        adjusted = ()
        if len(plan.pairs) == 3:
            dists, adjusted = _avoid_settle_with_unequal_masses(plan.pairs, dists, new_m)
        cons = []
        for (a, b), d in zip(plan.pairs, dists):
            system.addConstraint(g[a], g[b], d)
            cons.append((g[a], g[b], d))
        new_m = m.copy()
        site_err = 0.0
        if plan.sites:
            new_m = plan.new_masses.copy()
            for k in range(len(g)):
                system.setParticleMass(g[k], float(new_m[k]))
            par = [g[i] for i in plan.parents]
            for k, w in plan.sites:
                if len(par) == 3:
                    vs = mm.OutOfPlaneSite(par[0], par[1], par[2], *w)
                    q = p[list(plan.parents)]
                    r12, r13 = q[1] - q[0], q[2] - q[0]
                    rule = q[0] + w[0] * r12 + w[1] * r13 + w[2] * np.cross(r12, r13)
                else:
                    vs = mm.TwoParticleAverageSite(par[0], par[1], 1.0 - w[0], w[0])
                    q = p[list(plan.parents)]
                    rule = (1.0 - w[0]) * q[0] + w[0] * q[1]
                system.setVirtualSite(g[k], vs)
                site_err = max(site_err, float(np.linalg.norm(rule - p[k])))
        keep = new_m > 0
        res = RigidGroup(
            atoms=tuple(g), kind=plan.kind, constraints=tuple(cons),
            virtual_sites=tuple(g[k] for k, _ in plan.sites),
            masses_before=tuple(float(v) for v in m), masses_after=tuple(float(v) for v in new_m),
            inertia_before=momenta.inertia_tensor(p, m, about="com"),
            inertia_after=momenta.inertia_tensor(p[keep], new_m[keep], about="com"),
            com_before=momenta.centre_of_mass(p, m),
            com_after=(new_m[keep, None] * p[keep]).sum(0) / new_m.sum(),
            max_site_error=site_err,
            adjusted_constraints=tuple((g[plan.pairs[k][0]], g[plan.pairs[k][1]], old, new) for k, old, new in adjusted))
        if plan.sites:
            warnings.warn(
                f"rigid group {g} ({plan.kind}): mass and centre of mass kept, inertia tensor changed by "
                f"{100 * res.inertia_change:.1f}% (3 point masses cannot carry a general inertia tensor). Note: "
                f"OpenMM 8.6 CustomIntegrators (so SymplecticIntegrator) on Reference/CPU evaluate forces "
                f"with virtual-site positions from the start of the step, so sites that carry interactions get "
                f"wrong forces and angular momentum is not conserved; use this mode for non-interacting sites "
                f"or with OpenMM's built-in integrators.", RigidGroupWarning, stacklevel=2)
        results.append(res)
    open_angles = [t for plan, res in zip(plans, results) for t in _open_angles(pos, res.constraints)]
    if open_angles:
        # OpenMM's CCMA (Reference, CPU and the GPU platforms) builds its coupling matrix from the angle
        # between two constraints that share an atom, found either from a third constraint closing the
        # triangle or from a HarmonicAngleForce term.  A framework of N >= 5 atoms has coupled constraint
        # pairs with no closing constraint; without the angle the iteration can diverge.  These terms have
        # zero force constant: they change no energy or force, only inform the constraint solver.
        angles = mm.HarmonicAngleForce()
        angles.setName(ANGLE_FORCE_NAME)
        for a, b, c, theta in open_angles:
            angles.addAngle(a, b, c, theta, 0.0)
        system.addForce(angles)
    return results


def _avoid_settle_with_unequal_masses(pairs, dists, masses):
    """Keep OpenMM from treating an isosceles constraint triangle with unequal base masses by SETTLE.

    OpenMM 8.6 (Reference/CPU) hands every triangle of 3 atoms with exactly 2 constraints each to SETTLE
    when two of its distances are equal in single precision, and SETTLE assumes the two atoms at the
    base have equal masses: with unequal masses (HOD, an equilateral triangle of unequal atoms) the
    positions become NaN within a step (measured).  One of the two equal distances is moved to the
    nearest different float32 value (a relative change below 1e-7), so that CCMA solves the triangle."""
    dists = list(dists)
    adjusted = []
    for _ in range(3):
        f = [np.float32(d) for d in dists]
        bad = None
        for k1, k2 in itertools.combinations(range(3), 2):
            if f[k1] != f[k2]:
                continue
            shared = set(pairs[k1]) & set(pairs[k2])
            a = (set(pairs[k1]) - shared).pop()
            b = (set(pairs[k2]) - shared).pop()
            if masses[a] != masses[b]:
                bad = k2
                break
        if bad is None:
            break
        d = dists[bad]
        cands = [float(np.nextafter(f[bad], np.float32(np.inf))), float(np.nextafter(f[bad], np.float32(-np.inf)))]
        cands = [c for c in cands if all(np.float32(c) != f[k] for k in range(3) if k != bad)]
        new = min(cands, key=lambda c: abs(c - d))
        adjusted.append((bad, d, new))
        dists[bad] = new
    return dists, adjusted


def _open_angles(pos, constraints):
    """(a, b, c, angle) for every two constraints (a, b), (b, c) with no constraint (a, c)."""
    nbr: dict = {}
    for i, j, _ in constraints:
        nbr.setdefault(i, set()).add(j)
        nbr.setdefault(j, set()).add(i)
    out = []
    for b, ns in nbr.items():
        for a, c in itertools.combinations(sorted(ns), 2):
            if c in nbr[a]:
                continue
            u, v = pos[a] - pos[b], pos[c] - pos[b]
            cosang = float(u @ v / (np.linalg.norm(u) * np.linalg.norm(v)))
            out.append((a, b, c, float(np.arccos(np.clip(cosang, -1.0, 1.0)))))
    return out
