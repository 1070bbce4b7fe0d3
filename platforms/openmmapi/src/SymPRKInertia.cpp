/* openmm_symprk native plugin: the inertia-tensor solve (see SymPRKInertia.h). */

#include "openmm/internal/SymPRKInertia.h"
#include <cmath>

using OpenMM::Vec3;

namespace {

/** The adjugate of the symmetric tensor I times rhs, and its determinant: I^-1 rhs = adj(I) rhs / det. */
Vec3 adjugateTimes(double Ixx, double Iyy, double Izz, double Ixy, double Ixz, double Iyz, Vec3 rhs, double& det) {
    double axx = Iyy*Izz-Iyz*Iyz, ayy = Ixx*Izz-Ixz*Ixz, azz = Ixx*Iyy-Ixy*Ixy;
    double axy = Ixz*Iyz-Izz*Ixy, axz = Ixy*Iyz-Iyy*Ixz, ayz = Ixy*Ixz-Ixx*Iyz;
    det = Ixx*axx+Ixy*axy+Ixz*axz;
    return Vec3(axx*rhs[0]+axy*rhs[1]+axz*rhs[2], axy*rhs[0]+ayy*rhs[1]+ayz*rhs[2], axz*rhs[0]+ayz*rhs[1]+azz*rhs[2]);
}

}

Vec3 SymPRKPlugin::solveInertia(Vec3 d, Vec3 o, Vec3 rhs, bool regularise) {
    double Ixx = d[1]+d[2], Iyy = d[0]+d[2], Izz = d[0]+d[1];
    double Ixy = -o[0], Ixz = -o[1], Iyz = -o[2];
    const double trace = Ixx+Iyy+Izz;
    double det;
    if (!regularise) {
        // The thermostat's kept rotation: the exact inverse, or for a linear system (det below 1e-10 trace^3, the
        // custom backend's LINEAR), whose moment about its axis is 0, w = 2 rhs/trace: its two equal moments are
        // trace/2 and its angular momentum is perpendicular to the axis.
        Vec3 exact = adjugateTimes(Ixx, Iyy, Izz, Ixy, Ixz, Iyz, rhs, det);
        if (std::isfinite(det) && fabs(det) > 1e-10*trace*trace*trace)
            return exact/det;
        if (std::isfinite(trace) && trace > 0)
            return rhs*(2.0/trace);
        return Vec3();
    }
    double shift = 1e-12*trace;
    Vec3 shifted = adjugateTimes(Ixx+shift, Iyy+shift, Izz+shift, Ixy, Ixz, Iyz, rhs, det);
    if (det == 0.0 || !std::isfinite(det))
        return Vec3();
    return shifted/det;
}
