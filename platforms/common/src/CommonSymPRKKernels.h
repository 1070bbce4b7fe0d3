#ifndef COMMON_SYMPRK_KERNELS_H_
#define COMMON_SYMPRK_KERNELS_H_

#include "openmm/SymPRKKernels.h"
#include "openmm/common/ComputeArray.h"
#include "openmm/common/ComputeContext.h"
#include "openmm/common/ComputeKernel.h"
#include <map>
#include <memory>
#include <initializer_list>
#include <string>
#include <vector>

namespace SymPRKPlugin {

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
    CommonIntegrateSymPRKStepKernel(std::string name, const OpenMM::Platform& platform, OpenMM::ComputeContext& cc) :
            IntegrateSymPRKStepKernel(name, platform), cc(cc), hasInitializedKernels(false), blowUpStep(0),
            hostTransfers(0), lastStepSize(0.0) {
    }
    void initialize(const OpenMM::System& system, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan);
    void execute(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
                 bool& forcesAreValid, long long stepIndex);
    double computeKineticEnergy(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator);
    long long getBlowUpStep(OpenMM::ContextImpl& context);
    void setBlowUpStep(OpenMM::ContextImpl& context, long long step);
    /** The thermostat's state lives on the device (state[] of symprkThermostatEvent); its random numbers come from
     *  OpenMM's IntegrationUtilities generator, which the Context's own checkpoint carries. */
    void initializeThermostat(int seed);
    std::vector<double> sampleThermostatNoise(OpenMM::ContextImpl& context, int dof, int count);
    SymPRKThermostat::RunState getThermostatRunState();
    void setThermostatRunState(const SymPRKThermostat::RunState& run);
    std::string getRandomState();
    void setRandomState(const std::string& state);
    long long getHostTransfers() {
        return hostTransfers;
    }
private:
    /** The thermostat's device state (heat-bath energy, kinetic energy after the last event, skipped events). */
    void setAccArg(OpenMM::ComputeKernel& kernel, int index, double value);
    void setKernelArguments(const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan);
    void addArrayArgs(OpenMM::ComputeKernel& kernel, std::initializer_list<OpenMM::ArrayInterface*> arrays);
    /** Add the arguments posq and posqCorrection (null unless in mixed precision) to kernel. */
    void addPositionArgs(OpenMM::ComputeKernel& kernel);
    void setMixedArg(OpenMM::ComputeKernel& kernel, int index, double value);
    OpenMM::ArrayInterface& kickForces(OpenMM::ContextImpl& context, const SymPRKStepPlan::Operation& kick, bool& forcesAreValid,
                                       int& evaluated);
    void kick(OpenMM::ArrayInterface& forces, double cdt, bool exact, int checkStep);
    void drift(double cdt, double tol, bool exact, int checkStep);
    void projectVelocities(double tol, bool exact);
    void thermostatEvent(const SymPRKIntegrator& integrator, double decay);
    OpenMM::ComputeContext& cc;
    bool hasInitializedKernels, hasConstraints;
    std::map<int, std::unique_ptr<OpenMM::ComputeArray> > groupForces;  // multiple time stepping: forces per group mask
    std::map<int, bool> groupForcesValid;
    int projectionBlockSize;
    long long blowUpStep;
    long long hostTransfers;
    double lastStepSize;
    OpenMM::ComputeArray projection, badStep, rigid, vBefore, thermostatEventData, thermostatState;
    OpenMM::ComputeKernel thermostatEventKernel, thermostatApplyKernel, thermostatNoiseKernel;
    OpenMM::ComputeKernel kickKernel, kickProjectedKernel, driftKernel, driftDeltaKernel, driftApplyKernel, projectionKernel,
            rigidSumsKernel, rigidApplyKernel;
};

} // namespace SymPRKPlugin

#endif /*COMMON_SYMPRK_KERNELS_H_*/
