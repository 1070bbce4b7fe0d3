#ifndef COMMON_SYMPRK_KERNELS_H_
#define COMMON_SYMPRK_KERNELS_H_

#include "openmm/SymPRKKernels.h"
#include "openmm/common/ComputeArray.h"
#include "openmm/common/ComputeContext.h"
#include "openmm/common/ComputeKernel.h"
#include <map>
#include <memory>
#include <string>

namespace OpenMM {

/** Kernel source (platforms/common/src/kernels/symprk.cc, embedded at build time). */
class CommonSymPRKKernelSources {
public:
    static const std::string symprk;
};

/**
 * The SymPRKIntegrator step on the Common compute framework (OpenCL here; CUDA and HIP by the same source).
 * Constraints and virtual sites go through the platform's IntegrationUtilities: a constrained drift writes
 * the displacement to posDelta, applyConstraints() corrects it with the pre-drift positions as reference,
 * and a second kernel moves the atoms and adds (x - x_unconstrained)/(c*dt) to the velocities.
 */
class CommonIntegrateSymPRKStepKernel : public IntegrateSymPRKStepKernel {
public:
    CommonIntegrateSymPRKStepKernel(std::string name, const Platform& platform, ComputeContext& cc) :
            IntegrateSymPRKStepKernel(name, platform), cc(cc), hasInitializedKernels(false), multipleGroups(false), blowUpStep(0) {
    }
    void initialize(const System& system, const SymPRKIntegrator& integrator);
    void execute(ContextImpl& context, const SymPRKIntegrator& integrator, bool& forcesAreValid, long long stepIndex);
    double computeKineticEnergy(ContextImpl& context, const SymPRKIntegrator& integrator);
    long long getBlowUpStep(ContextImpl& context);
    void setBlowUpStep(ContextImpl& context, long long step);
private:
    void setMixedArg(ComputeKernel& kernel, int index, double value);
    void projectVelocities(double tol, bool exact);
    void thermostatEvent(const SymPRKIntegrator& integrator);
    ComputeContext& cc;
    bool hasInitializedKernels, hasConstraints, multipleGroups;
    std::map<int, std::unique_ptr<ComputeArray> > groupForces;  // multiple time stepping: forces per group mask
    std::map<int, bool> groupForcesValid;
    int projectionBlockSize;
    long long blowUpStep;
    ComputeArray projection, badStep, rigid, vBefore, thermostatSums;
    ComputeKernel thermostatSumsKernel, thermostatApplyKernel;
    ComputeKernel kickKernel, kickProjectedKernel, driftKernel, driftDeltaKernel, driftApplyKernel, projectionKernel, rigidSumsKernel, rigidApplyKernel;
};

} // namespace OpenMM

#endif /*COMMON_SYMPRK_KERNELS_H_*/
