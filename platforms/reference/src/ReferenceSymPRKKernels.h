#ifndef REFERENCE_SYMPRK_KERNELS_H_
#define REFERENCE_SYMPRK_KERNELS_H_

#include "openmm/SymPRKKernels.h"
#include "ReferencePlatform.h"
#include <functional>
#include <map>
#include <vector>

namespace OpenMM {

/**
 * The SymPRKIntegrator step on the Reference platform, also serving the CPU platform (CpuPlatform derives
 * from ReferencePlatform and shares its PlatformData: positions, velocities, forces, the constraint
 * algorithms -- with the CPU's threaded SETTLE -- and the virtual sites).  Per-atom loops run on the
 * platform's thread pool when the system is large enough to pay for the hand-off.
 */
class ReferenceIntegrateSymPRKStepKernel : public IntegrateSymPRKStepKernel {
public:
    ReferenceIntegrateSymPRKStepKernel(std::string name, const Platform& platform, ReferencePlatform::PlatformData& data) :
            IntegrateSymPRKStepKernel(name, platform), data(data), blowUpStep(0) {
    }
    void initialize(const System& system, const SymPRKIntegrator& integrator);
    void execute(ContextImpl& context, const SymPRKIntegrator& integrator, bool& forcesAreValid, long long stepIndex);
    double computeKineticEnergy(ContextImpl& context, const SymPRKIntegrator& integrator);
    bool energyEvaluationKeepsForces() const {
        return true;
    }
    long long getBlowUpStep(ContextImpl& context) {
        return blowUpStep;
    }
    void setBlowUpStep(ContextImpl& context, long long step) {
        blowUpStep = step;
    }
private:
    void parallelFor(const std::function<void(int, int, int)>& task);
    void computeProjection(const std::vector<Vec3>& pos, const std::vector<Vec3>& force);
    void removeRigidChange(const std::vector<Vec3>& pos, std::vector<Vec3>& vel, Vec3 dP, Vec3 dL);
    void projectVelocities(std::vector<Vec3>& pos, std::vector<Vec3>& vel, double tol, bool exact);
    static Vec3 solveInertia(Vec3 diag, Vec3 offdiag, Vec3 rhs);
    void thermostatEvent(const SymPRKIntegrator& integrator);
    ReferencePlatform::PlatformData& data;
    const System* system;
    std::vector<double> masses, inverseMasses;
    std::vector<Vec3> xRef, xUnconstrained, vBefore;
    std::vector<int> threadStart;
    bool hasConstraints, hasVirtualSites, useThreads, multipleGroups;
    std::map<int, std::vector<Vec3> > groupForces;  // multiple time stepping: forces per group mask
    int numParticles;
    long long blowUpStep;
    // exact-momentum projection: centre of mass, acceleration of the centre of mass, angular acceleration
    Vec3 com, acm, alpha;
};

} // namespace OpenMM

#endif /*REFERENCE_SYMPRK_KERNELS_H_*/
