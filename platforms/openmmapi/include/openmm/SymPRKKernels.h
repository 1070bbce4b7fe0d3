#ifndef OPENMM_SYMPRK_KERNELS_H_
#define OPENMM_SYMPRK_KERNELS_H_

#include "openmm/KernelImpl.h"
#include "openmm/Platform.h"
#include "openmm/System.h"
#include "openmm/SymPRKIntegrator.h"
#include <string>

namespace OpenMM {

/**
 * Executes one step of a SymPRKIntegrator.  Implemented by the Reference kernel (also serving the CPU
 * platform) and the Common kernel (OpenCL; CUDA and HIP by the same source).
 */
class IntegrateSymPRKStepKernel : public KernelImpl {
public:
    static std::string Name() {
        return "IntegrateSymPRKStep";
    }
    IntegrateSymPRKStepKernel(std::string name, const Platform& platform) : KernelImpl(name, platform) {
    }
    virtual void initialize(const System& system, const SymPRKIntegrator& integrator) = 0;
    /**
     * Advance one step.  forcesAreValid says whether the Context's forces belong to the current positions
     * (and the integrator's force groups); the kernel updates it.  stepIndex is the 1-based number of this
     * step, used to record the first non-finite one.
     */
    virtual void execute(ContextImpl& context, const SymPRKIntegrator& integrator, bool& forcesAreValid, long long stepIndex) = 0;
    /** Kinetic energy of the current (full-step) velocities. */
    virtual double computeKineticEnergy(ContextImpl& context, const SymPRKIntegrator& integrator) = 0;
    /**
     * True if an energy-only evaluation (Context::getState(getEnergy=True)) leaves the force buffer intact, so
     * cached forces survive it (Reference/CPU restore them; the Common platforms clear them).
     */
    virtual bool energyEvaluationKeepsForces() const {
        return false;
    }
    /** First step recorded as non-finite by execute(), or 0. */
    virtual long long getBlowUpStep(ContextImpl& context) = 0;
    /** Restore the value returned by getBlowUpStep() (checkpoints). */
    virtual void setBlowUpStep(ContextImpl& context, long long step) = 0;
};

} // namespace OpenMM

#endif /*OPENMM_SYMPRK_KERNELS_H_*/
