"""Velocities of virtual sites, from their parents' velocities.

OpenMM integrates only real particles: a virtual site's velocity in a State is zero although the site moves with
its parents.  A trajectory that carries velocities (for a velocity autocorrelation, a kinetic energy per site,
or a restart) needs the site's true velocity, the time derivative of its position function:

* TwoParticleAverageSite, ThreeParticleAverageSite: x = sum w_i x_i, linear, so v = sum w_i v_i;
* OutOfPlaneSite: x = x1 + w12 r12 + w13 r13 + wc (r12 x r13) with r1j = xj - x1; the cross term is bilinear, so
  v = v1 + w12 u12 + w13 u13 + wc (u12 x r13 + r12 x u13), u1j = vj - v1;
* LocalCoordinatesSite: origin + rotated local offset, not linear in the positions when the offset is not zero:
  its velocity is the derivative of its position function along the parents' velocities, taken by a central
  difference (step 1e-6 nm, error far below float32 trajectory precision).

A virtual-site type not listed here (a future OpenMM class) keeps OpenMM's zero, and
:attr:`VirtualSiteVelocities.unsupported` names it.
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

__all__ = ["VirtualSiteVelocities"]


class VirtualSiteVelocities:
    """``VirtualSiteVelocities(system)(x, v)``: ``v`` (nm/ps, (N, 3)) with every virtual site's velocity computed
    from its parents' (x in nm).  ``bool(...)`` is False for a System without virtual sites."""

    def __init__(self, system: mm.System):
        self.linear = []  # (site, parents, weights)
        self.out_of_plane = []  # (site, p1, p2, p3, w12, w13, wc)
        self.local = []  # (site, parents, origin w, x w, y w, local position)
        self.unsupported = []  #: virtual sites of a type not listed here: (site, class name)
        for i in range(system.getNumParticles()):
            if not system.isVirtualSite(i):
                continue
            vs = system.getVirtualSite(i)
            n = vs.getNumParticles()
            parents = [vs.getParticle(k) for k in range(n)]
            if isinstance(vs, (mm.TwoParticleAverageSite, mm.ThreeParticleAverageSite)):
                self.linear.append((i, parents, [vs.getWeight(k) for k in range(n)]))
            elif isinstance(vs, mm.OutOfPlaneSite):
                self.out_of_plane.append((i, *parents, vs.getWeight12(), vs.getWeight13(), vs.getWeightCross()))
            elif isinstance(vs, mm.LocalCoordinatesSite):
                local = np.array(vs.getLocalPosition().value_in_unit(unit.nanometer), float)
                self.local.append((i, parents, np.array(vs.getOriginWeights()), np.array(vs.getXWeights()),
                                   np.array(vs.getYWeights()), local))
            else:
                self.unsupported.append((i, type(vs).__name__))

    def __bool__(self):
        return bool(self.linear or self.out_of_plane or self.local or self.unsupported)

    def __call__(self, x, v) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        v = np.array(v, dtype=np.float64)
        for site, parents, weights in self.linear:
            v[site] = np.asarray(weights) @ v[parents]
        for site, p1, p2, p3, w12, w13, wc in self.out_of_plane:
            r12, r13 = x[p2] - x[p1], x[p3] - x[p1]
            u12, u13 = v[p2] - v[p1], v[p3] - v[p1]
            v[site] = v[p1] + w12 * u12 + w13 * u13 + wc * (np.cross(u12, r13) + np.cross(r12, u13))
        for site, parents, wo, wx, wy, local in self.local:
            xp, vp = x[parents], v[parents]
            if not np.any(local):
                v[site] = wo @ vp  # the site sits at its origin: linear
                continue
            speed = float(np.max(np.linalg.norm(vp, axis=1)))
            if speed == 0.0:
                v[site] = 0.0
                continue
            h = 1e-6 / speed  # ps: parents move at most 1e-6 nm
            v[site] = (_local_position(xp + h * vp, wo, wx, wy, local)
                       - _local_position(xp - h * vp, wo, wx, wy, local)) / (2 * h)
        return v


def _local_position(xp, wo, wx, wy, local):
    """OpenMM's LocalCoordinatesSite position: origin plus ``local`` in the orthonormal frame of (xdir, ydir)."""
    origin, xdir, ydir = wo @ xp, wx @ xp, wy @ xp
    zdir = np.cross(xdir, ydir)
    xdir = xdir / np.linalg.norm(xdir)
    zdir = zdir / np.linalg.norm(zdir)
    ydir = np.cross(zdir, xdir)
    return origin + local[0] * xdir + local[1] * ydir + local[2] * zdir
