#ifndef OPENMM_SYMPRK_KERNELS_H_
#define OPENMM_SYMPRK_KERNELS_H_

#include "openmm/KernelImpl.h"
#include "openmm/Platform.h"
#include "openmm/System.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/internal/ContextImpl.h"
#include "openmm/internal/SymPRKStepPlan.h"
#include "openmm/internal/SymPRKThermostat.h"
#include <string>
#include <vector>

namespace SymPRKPlugin {

/**
 * For tests: what a kernel executed, three numbers per operation run (step, operation index in the plan, force
 * groups evaluated or 0), recorded only while enabled (SymPRKIntegrator::setExecutionTraceEnabled).
 */
class SymPRKExecutionTrace {
public:
    SymPRKExecutionTrace() : enabled(false) {
    }
    /** Start (clearing the record) or stop recording. */
    void setEnabled(bool record) {
        enabled = record;
        if (record)
            entries.clear();
    }
    void record(long long step, int operation, int evaluatedGroups) {
        if (enabled)
            entries.insert(entries.end(), {(int) step, operation, evaluatedGroups});
    }
    const std::vector<int>& getEntries() const {
        return entries;
    }
private:
    bool enabled;
    std::vector<int> entries;
};

/**
 * Executes one step of a SymPRKIntegrator: the operations of its SymPRKStepPlan, in order.  Implemented by the
 * Reference kernel (also serving the CPU platform) and the Common kernel (OpenCL; CUDA and HIP by the same source).
 */
class IntegrateSymPRKStepKernel : public OpenMM::KernelImpl {
public:
    static std::string Name() {
        return "IntegrateSymPRKStep";
    }
    IntegrateSymPRKStepKernel(std::string name, const OpenMM::Platform& platform) : OpenMM::KernelImpl(name, platform) {
    }
    virtual void initialize(const OpenMM::System& system, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan) = 0;
    /**
     * Advance one step: run the operations of plan.  forcesAreValid says whether the Context's forces belong to the
     * current positions (and the integrator's force groups); the kernel updates it.  stepIndex is the 1-based number
     * of this step: it decides which thermostat events run, and is recorded as the first non-finite one.
     * nextStepFollows: the same SymPRKIntegrator::step call runs step stepIndex+1 right after this one, with nothing
     * outside the Context's own updateContextState between them, so a kernel may begin that step's operations at the
     * end of this one (the Common kernel's fusion across steps); when false the step must end at the step point.
     */
    virtual void execute(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
                         bool& forcesAreValid, long long stepIndex, bool nextStepFollows) = 0;
    /** Kinetic energy of the current (full-step) velocities. */
    virtual double computeKineticEnergy(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator) = 0;
    /**
     * True if an energy-only evaluation (Context::getState(getEnergy=True)) leaves the force buffer intact, so
     * cached forces survive it (Reference/CPU restore them; the Common platforms clear them).
     */
    virtual bool energyEvaluationKeepsForces() const {
        return false;
    }
    /** First step recorded as non-finite by execute(), or 0. */
    virtual long long getBlowUpStep(OpenMM::ContextImpl& context) = 0;
    /** Restore the value returned by getBlowUpStep() (checkpoints). */
    virtual void setBlowUpStep(OpenMM::ContextImpl& context, long long step) = 0;
    /**
     * The thermostat's run-time state, per Context.  The defaults hold it in the host-side SymPRKThermostat
     * (Reference/CPU); a kernel that runs the events on the device keeps it there and overrides these.
     */
    virtual void initializeThermostat(int seed) {
        thermostat.initialize(seed);
    }
    /** The heat-bath energy, the kinetic energy after the last event and the skipped events (SymPRKThermostat::RunState). */
    virtual SymPRKThermostat::RunState getThermostatRunState() {
        return thermostat.getRunState();
    }
    virtual void setThermostatRunState(const SymPRKThermostat::RunState& state) {
        thermostat.setRunState(state);
    }
    /** The random state a checkpoint of the integrator carries (text), and back. */
    virtual std::string getRandomState() {
        return thermostat.getRandomState();
    }
    virtual void setRandomState(const std::string& state) {
        thermostat.setRandomState(state);
    }
    /**
     * The noise of `count` thermostat events of `dof` degrees of freedom, drawn as the events draw it and from the
     * stream they use (which it advances): r1, chi2 for each, 2*count values.  The host default is
     * SymPRKThermostat::drawNoise; a kernel whose events draw on the device draws these there, event by event.
     */
    virtual std::vector<double> sampleThermostatNoise(OpenMM::ContextImpl& context, int dof, int count) {
        std::vector<double> values(2*(size_t) count);
        for (int i = 0; i < count; i++)
            thermostat.drawNoise(dof, values[2*i], values[2*i+1]);
        return values;
    }
    /** Host-device transfers the kernel has made (0 where the data is on the host). */
    virtual long long getHostTransfers() {
        return 0;
    }
    /** Device launches (kernels and device-side copies) the kernel has enqueued itself (0 where it runs on the host). */
    virtual long long getKernelLaunches() {
        return 0;
    }
    /** How a kernel that launches device work groups the plan's operations into launches (SymPRKIntegrator::KernelFusion);
     *  a kernel that runs on the host ignores it. */
    virtual void setKernelFusion(int mode) {
    }
    SymPRKExecutionTrace& getTrace() {
        return trace;
    }
protected:
    /**
     * Whether kick must evaluate its forces: it does not reuse cached forces, or they no longer belong to the
     * positions, or they are another set of groups' (the run-time half of the plan's reuse decision).
     */
    static bool mustEvaluateForces(const SymPRKStepPlan::Operation& kick, bool forcesAreValid, OpenMM::ContextImpl& context) {
        return !kick.reuseForces || !forcesAreValid || context.getLastForceGroups() != kick.forceGroups;
    }
    SymPRKThermostat thermostat;
    SymPRKExecutionTrace trace;
};

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_KERNELS_H_*/
