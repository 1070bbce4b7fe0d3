#ifndef OPENMM_SYMPRK_INERTIA_H_
#define OPENMM_SYMPRK_INERTIA_H_

/* openmm_symprk native plugin: the inertia-tensor solve of the host code (the exact-momentum projections of the
 * Reference kernel and the thermostat's kept rotation).  The device code has its own, symprkSolveInertia in
 * common/src/kernels/symprk.cc, with the same operations. */

#include "openmm/Vec3.h"
#include "openmm/internal/windowsExportSymPRK.h"

namespace SymPRKPlugin {

/**
 * I^-1 rhs for the inertia tensor I about the centre of mass given by d = (sum m x^2, sum m y^2, sum m z^2) and
 * o = (sum m xy, sum m xz, sum m yz) (positions relative to the centre of mass).
 * regularise true: I shifted by 1e-12 of its trace (a linear molecule or a single particle then gives a finite
 * result; the shift changes a round-off-sized torque by 1e-12 of itself); 0 if still singular.
 * regularise false (the thermostat's kept rotation): the exact inverse, unless the determinant is below 1e-10 trace^3:
 * a linear system, whose rotation is 2 rhs/trace (its two equal moments are trace/2), 0 for a zero trace.
 */
OPENMM_EXPORT_SYMPRK OpenMM::Vec3 solveInertia(OpenMM::Vec3 d, OpenMM::Vec3 o, OpenMM::Vec3 rhs, bool regularise = true);

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_INERTIA_H_*/
