#ifndef COMMON_SYMPRK_KERNELS_H_
#define COMMON_SYMPRK_KERNELS_H_

#include "openmm/SymPRKKernels.h"
#include "openmm/common/ComputeArray.h"
#include "openmm/common/ComputeContext.h"
#include "openmm/common/ComputeKernel.h"
#include <map>
#include "openmm/System.h"
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
 * and the drift's apply moves the atoms and adds (x - x_unconstrained)/(c*dt) to the velocities.
 *
 * Fusion (SymPRKIntegrator::KernelFusion).  The kernel runs the plan's operations in order, but groups the per-atom
 * ones into segments (symprkSegment: up to four operations on each atom in one launch): an operation that needs the
 * whole device first (OpenMM's constraints and velocity constraints, a force evaluation, a block reduction: the
 * exact-momentum projection or rigid correction, a thermostat event's sums) ends the segment gathered so far.  So a
 * kick and the drift's delta after it are one launch, a drift's apply and what follows it up to the next force
 * evaluation one more.  A thermostat event is one block launch (symprkEventBlock) with the segment before it and the
 * segment after it (its apply, the next kick or drift's delta) up to getKernelFusionBlockAtoms() atoms, else its
 * sums alone with the apply in the next segment.  Virtual sites are placed before the next force evaluation and at
 * the end of the step rather than after every drift (nothing between reads them).  Across steps, within one step()
 * call (nextStepFollows) and where no force of the System acts between steps: the last kick of a step and the first
 * kick of the next, both on the same cached forces, are one segment at the end of the first step, and the velocity
 * projection between them is left out where the next constrained drift projects those velocities again (the rule of
 * canFuseAcross).  The velocities come back to the step point, projected, at the end of every step() call.
 */
class CommonIntegrateSymPRKStepKernel : public IntegrateSymPRKStepKernel {
public:
    CommonIntegrateSymPRKStepKernel(std::string name, const OpenMM::Platform& platform, OpenMM::ComputeContext& cc) :
            IntegrateSymPRKStepKernel(name, platform), cc(cc), hasInitializedKernels(false), blowUpStep(0),
            hostTransfers(0), launches(0), lastStepSize(0.0), fusion(2), stepsAreSeparable(false), blockPending(false),
            virtualSitesPending(false), projectionValid(false), reorderedThisStep(false), reorderBeforeEvaluation(false),
            projectionForces(NULL), headDoneStep(0), headDoneIndex(-1) {
    }
    void initialize(const OpenMM::System& system, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan);
    void execute(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
                 bool& forcesAreValid, long long stepIndex, bool nextStepFollows);
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
    long long getKernelLaunches() {
        return launches;
    }
    void setKernelFusion(int mode) {
        fusion = mode;
    }
private:
    /** The per-atom operations of a segment (SYMPRK_OP_* in kernels/symprk.cc, which gets these numbers as defines). */
    enum SegmentOpKind {
        OpKick = 1, OpKickProjected = 2, OpDrift = 3, OpDriftDelta = 4, OpDriftApply = 5, OpEventApply = 6,
        OpSaveVelocities = 7, OpRigidApply = 8
    };
    static const int MaxSegmentOps = 4;
    struct SegmentOp {
        int kind;
        double coefficient;  // c*dt of a kick or drift
        int argument;        // a drift's apply: 1 with the rigid correction
        int checkStep;       // > 0: check the velocities for a blow-up, recording this step
        OpenMM::ArrayInterface* forces;  // a kick's forces
    };
    /** Add op to the segment being gathered (launching that segment first where op does not fit in it). */
    void append(const SegmentOp& op);
    /** Launch the segment gathered so far (with the pending thermostat event's block, if any). */
    void flush();
    /** Place the virtual sites if a drift has moved their parents since they were last placed. */
    void placeVirtualSites();
    /** Add the force arrays of ops not yet in slots (a launch has two: force0, force1), in order of first use. */
    static void collectForces(const std::vector<SegmentOp>& ops, std::vector<OpenMM::ArrayInterface*>& slots);
    void setSegmentArgs(OpenMM::ComputeKernel& kernel, int base, const std::vector<SegmentOp>& ops,
                        const std::vector<OpenMM::ArrayInterface*>& slots);
    void setForceSlotArgs(OpenMM::ComputeKernel& kernel, int base, const std::vector<OpenMM::ArrayInterface*>& slots);
    /** Whether this step's last kick and the next step's first may be one launch (see the class comment). */
    bool canFuseAcross(const SymPRKStepPlan& plan, long long stepIndex) const;
    bool canSkipClosingProjection(const SymPRKStepPlan& plan) const;
    /** Run operation k of the plan as part of step stepIndex (recorded in the trace as such). */
    void runOperation(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan, int k,
                      long long stepIndex, bool& forcesAreValid);
    /** Copy the force buffer, which holds the forces of the force groups `groups`, to their copy (multiple time stepping). */
    void copyGroupForces(int groups);
    /** Let the Context reorder the atoms (once a step; what it invalidates). */
    void reorderAtoms(bool& forcesAreValid);
    /** Compute the exact-momentum projection of forces at the current positions unless it is still valid. */
    void ensureProjection(OpenMM::ArrayInterface& forces);
    /** Whether some force of system acts between steps (updateContextState: a barostat, a CMMotionRemover, an
     *  Andersen thermostat, or a force from outside OpenMM, which might). */
    static bool forcesActBetweenSteps(const OpenMM::System& system);
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
    long long hostTransfers, launches;
    double lastStepSize;
    int fusion;
    bool stepsAreSeparable;
    // the segment being gathered, and a thermostat event waiting to run in one block with it (the segment before it in
    // blockPre, its random numbers' index and parameters)
    std::vector<SegmentOp> pending, blockPre;
    bool blockPending;
    int eventRandomIndex;
    double eventTarget, eventDecay;
    bool virtualSitesPending, projectionValid, reorderedThisStep, reorderBeforeEvaluation;
    OpenMM::ArrayInterface* projectionForces;
    // the first kick of step headDoneStep ran (operation headDoneIndex) at the end of the step before
    long long headDoneStep;
    int headDoneIndex;
    OpenMM::ComputeArray projection, badStep, rigid, vBefore, thermostatEventData, thermostatState;
    OpenMM::ComputeKernel segmentKernel, eventBlockKernel, thermostatNoiseKernel, projectionKernel, rigidSumsKernel;
};

} // namespace SymPRKPlugin

#endif /*COMMON_SYMPRK_KERNELS_H_*/
