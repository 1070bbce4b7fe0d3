#ifndef OPENMM_SYMPRK_KERNELS_H_
#define OPENMM_SYMPRK_KERNELS_H_

#include "openmm/KernelImpl.h"
#include "openmm/Platform.h"
#include "openmm/System.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/internal/SymPRKThermostat.h"
#include <cmath>
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
    /**
     * The host side of the thermostat (random state, heat-bath energy), per Context.  execute() runs an event
     * before a step whose 0-based index is a multiple of the interval and after a step that completes one.
     */
    SymPRKThermostat& getThermostat() {
        return thermostat;
    }
    /** Whether a thermostat event comes before / after step stepIndex (1-based, as execute() gets it). */
    static bool thermostatBefore(const SymPRKIntegrator& integrator, long long stepIndex) {
        return integrator.hasThermostat() && (stepIndex-1) % integrator.getThermostatInterval() == 0;
    }
    static bool thermostatAfter(const SymPRKIntegrator& integrator, long long stepIndex) {
        return integrator.hasThermostat() && stepIndex % integrator.getThermostatInterval() == 0;
    }
    /** c = exp(-interval*dt/(2 tau)) of a half event. */
    static double thermostatDecay(const SymPRKIntegrator& integrator) {
        return std::exp(-0.5*integrator.getThermostatInterval()*integrator.getStepSize()/integrator.getCollisionTime());
    }
protected:
    SymPRKThermostat thermostat;
};

} // namespace OpenMM

#endif /*OPENMM_SYMPRK_KERNELS_H_*/
