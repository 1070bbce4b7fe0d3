/* openmm_symprk native plugin: the Common compute framework SymPRKIntegrator kernel.  It runs the operations of
 * the step plan (SymPRKStepPlan) in order, grouping the per-atom ones into as few device launches as the plan
 * allows (CommonSymPRKKernels.h says how). */

#include "CommonSymPRKKernels.h"
#include "openmm/common/ContextSelector.h"
#include "openmm/common/IntegrationUtilities.h"
#include "openmm/AndersenThermostat.h"
#include "openmm/CMMotionRemover.h"
#include "openmm/MonteCarloAnisotropicBarostat.h"
#include "openmm/MonteCarloBarostat.h"
#include "openmm/MonteCarloFlexibleBarostat.h"
#include "openmm/MonteCarloMembraneBarostat.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <typeinfo>
#include <vector>

using namespace SymPRKPlugin;
using namespace OpenMM;
using namespace std;

// Arguments of symprkSegment: the segment (count, then an int4 and a coefficient per operation) from index 0, then the
// buffers; of symprkEventBlock: the segments before and after the event, the buffers, the event's own.
static const int SEGMENT_ARGS = 1+2*4;
static const int BUFFER_FORCE0 = 4;  // offset of force0 (then force1) among the buffers
static const int BUFFER_ARGS = 12;
static const int EVENT_BLOCK_OWN = 2*SEGMENT_ARGS+BUFFER_ARGS;  // random, its index, dof, target, decay, state

bool CommonIntegrateSymPRKStepKernel::forcesActBetweenSteps(const System& system) {
    for (int i = 0; i < system.getNumForces(); i++) {
        const Force& force = system.getForce(i);
        if (dynamic_cast<const CMMotionRemover*>(&force) != NULL || dynamic_cast<const AndersenThermostat*>(&force) != NULL ||
                dynamic_cast<const MonteCarloBarostat*>(&force) != NULL ||
                dynamic_cast<const MonteCarloAnisotropicBarostat*>(&force) != NULL ||
                dynamic_cast<const MonteCarloFlexibleBarostat*>(&force) != NULL ||
                dynamic_cast<const MonteCarloMembraneBarostat*>(&force) != NULL)
            return true;
        // every other force of OpenMM 8.6 leaves the state alone between steps (its ForceImpl's updateContextState is
        // empty); a force of another library (another namespace) might not
        const char* name = typeid(force).name();
        if (strncmp(name, "N6OpenMM", 8) != 0 && strncmp(name, "class OpenMM::", 14) != 0)
            return true;
    }
    return false;
}

void CommonIntegrateSymPRKStepKernel::initialize(const System& system, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan) {
    cc.initializeContexts();
    ContextSelector selector(cc);
    hasConstraints = plan.hasConstraints();
    stepsAreSeparable = !forcesActBetweenSteps(system);
    projectionBlockSize = 1;
    while (projectionBlockSize*2 <= min(128, cc.getMaxThreadBlockSize()))
        projectionBlockSize *= 2;
    // The thermostat's reduction leaves its 10 sums in the first 10 threads' slots (kernels/symprk.cc).
    if (plan.hasThermostatEvents() && projectionBlockSize < 32)
        throw OpenMMException("SymPRKIntegrator: the thermostat's device reduction needs work groups of at least 32 "
                              "threads; this device allows " + cc.intToString(cc.getMaxThreadBlockSize()) +
                              ". Use the Reference or CPU platform, or backend='custom'.");
    map<string, string> defines;
    defines["NUM_ATOMS"] = cc.intToString(cc.getNumAtoms());
    defines["PADDED_NUM_ATOMS"] = cc.intToString(cc.getPaddedNumAtoms());
    defines["WORK_GROUP_SIZE"] = cc.intToString(projectionBlockSize);
    const map<string, int> ops = {{"KICK", OpKick}, {"KICK_PROJECTED", OpKickProjected}, {"DRIFT", OpDrift},
            {"DRIFT_DELTA", OpDriftDelta}, {"DRIFT_APPLY", OpDriftApply}, {"EVENT_APPLY", OpEventApply},
            {"SAVE_VELOCITIES", OpSaveVelocities}, {"RIGID_APPLY", OpRigidApply}};
    for (const auto& op : ops)
        defines["SYMPRK_OP_"+op.first] = cc.intToString(op.second);
    // Squared blow-up speed: the given one, or the largest finite value of the velocity type (so that only NaN
    // and infinity count, as every comparison with NaN is false and inf <= max is false).
    const bool doubleVelocities = (cc.getUseDoublePrecision() || cc.getUseMixedPrecision());
    const double maxSpeed = integrator.getMaxSpeed();
    if (maxSpeed > 0)
        defines["MAX_SPEED2"] = cc.doubleToString(maxSpeed*maxSpeed, true);
    else
        defines["MAX_SPEED2"] = (doubleVelocities ? "1.7976931348623157e308" : "3.402823466e38f");
    ComputeProgram program = cc.compileProgram(CommonSymPRKKernelSources::symprk, defines);
    segmentKernel = program->createKernel("symprkSegment");
    eventBlockKernel = program->createKernel("symprkEventBlock");
    projectionKernel = program->createKernel("symprkProjection");
    rigidSumsKernel = program->createKernel("symprkRigidSums");
    const int mixedSize = (doubleVelocities ? sizeof(double) : sizeof(float));
    projection.initialize(cc, 9, mixedSize, "symprkProjection");
    rigid.initialize(cc, 9, mixedSize, "symprkRigid");
    vBefore.initialize(cc, cc.getPaddedNumAtoms(), 4*mixedSize, "symprkVelocitiesBefore");
    badStep.initialize<int>(cc, 1, "symprkBadStep");
    // double where the device has it (symprk_acc in the device source); the event's data is a segment argument even
    // without a thermostat
    const int accSize = (cc.getSupportsDoublePrecision() ? sizeof(double) : sizeof(float));
    thermostatEventData.initialize(cc, 11, accSize, "symprkThermostatEvent");
    if (plan.hasThermostatEvents()) {
        thermostatNoiseKernel = program->createKernel("symprkThermostatNoise");
        for (int i = 0; i < 5; i++)
            thermostatNoiseKernel->addArg();  // random, its index, dof, the output, the sample: set per call
        thermostatState.initialize(cc, 5, accSize, "symprkThermostatState");
    }
    groupForces.clear();
    groupForcesValid.clear();
    pending.clear();
    blockPre.clear();
    blockPending = virtualSitesPending = projectionValid = false;
    headDoneStep = 0;
    int zero = 0;
    badStep.upload(&zero);
    hostTransfers++;
    if (blowUpStep != 0)
        setBlowUpStep(*cc.getContextImpl(), blowUpStep);
}

void CommonIntegrateSymPRKStepKernel::addPositionArgs(ComputeKernel& kernel) {
    kernel->addArg(cc.getPosq());
    if (cc.getUseMixedPrecision())
        kernel->addArg(cc.getPosqCorrection());
    else
        kernel->addArg(nullptr);
}

void CommonIntegrateSymPRKStepKernel::addArrayArgs(ComputeKernel& kernel, initializer_list<ArrayInterface*> arrays) {
    for (ArrayInterface* array : arrays)
        kernel->addArg(*array);
}

void CommonIntegrateSymPRKStepKernel::setKernelArguments(const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan) {
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    ArrayInterface* velm = &cc.getVelm();
    ArrayInterface* posDelta = &integration.getPosDelta();
    ArrayInterface* forces = &cc.getLongForceBuffer();
    const int withPositions = (plan.hasThermostatEvents() && integrator.getThermostatKeepsRotation()) ? 1 : 0;
    // the segments' operations are set per launch (SEGMENT_ARGS each), then the buffers (BUFFER_ARGS; force0 and force1
    // per launch too)
    auto addBuffers = [&] (ComputeKernel& kernel) {
        addPositionArgs(kernel);
        addArrayArgs(kernel, {velm, posDelta, forces, forces, &projection, &thermostatEventData, &rigid, &vBefore, &badStep});
        kernel->addArg(withPositions);
    };
    for (int i = 0; i < SEGMENT_ARGS; i++)
        segmentKernel->addArg();
    addBuffers(segmentKernel);
    for (int i = 0; i < 2*SEGMENT_ARGS; i++)
        eventBlockKernel->addArg();
    addBuffers(eventBlockKernel);
    for (int i = 0; i < 5; i++)
        eventBlockKernel->addArg();  // random, its index, dof, target, decay: set per event
    if (thermostatState.isInitialized())
        eventBlockKernel->addArg(thermostatState);
    else
        eventBlockKernel->addArg(thermostatEventData);  // (never launched without a thermostat)
    addPositionArgs(projectionKernel);
    addArrayArgs(projectionKernel, {velm, forces, &projection});
    rigidSumsKernel->addArg();
    rigidSumsKernel->addArg();
    addPositionArgs(rigidSumsKernel);
    addArrayArgs(rigidSumsKernel, {velm, posDelta, &vBefore, &rigid});
}

void CommonIntegrateSymPRKStepKernel::setAccArg(ComputeKernel& kernel, int index, double value) {
    if (cc.getSupportsDoublePrecision())
        kernel->setArg(index, value);
    else
        kernel->setArg(index, (float) value);
}

void CommonIntegrateSymPRKStepKernel::setMixedArg(ComputeKernel& kernel, int index, double value) {
    if (cc.getUseDoublePrecision() || cc.getUseMixedPrecision())
        kernel->setArg(index, value);
    else
        kernel->setArg(index, (float) value);
}

// -- segments --------------------------------------------------------------------------------------------------------

void CommonIntegrateSymPRKStepKernel::collectForces(const vector<SegmentOp>& ops, vector<ArrayInterface*>& slots) {
    for (const SegmentOp& op : ops)
        if (op.forces != NULL && find(slots.begin(), slots.end(), op.forces) == slots.end())
            slots.push_back(op.forces);
}

void CommonIntegrateSymPRKStepKernel::append(const SegmentOp& op) {
    vector<ArrayInterface*> slots;
    if (blockPending)
        collectForces(blockPre, slots);
    collectForces(pending, slots);
    collectForces({op}, slots);
    if (pending.size() == MaxSegmentOps || slots.size() > 2)
        flush();
    pending.push_back(op);
    if (fusion == SymPRKIntegrator::FuseNone)
        flush();
}

void CommonIntegrateSymPRKStepKernel::setSegmentArgs(ComputeKernel& kernel, int base, const vector<SegmentOp>& ops,
        const vector<ArrayInterface*>& slots) {
    kernel->setArg(base, (int) ops.size());
    for (int j = 0; j < MaxSegmentOps; j++) {
        mm_int4 op(0, 0, 0, 0);
        double c = 0.0;
        if (j < (int) ops.size()) {
            op.x = ops[j].kind;
            op.y = ops[j].argument;
            if (ops[j].forces != NULL)
                op.y = (int) (find(slots.begin(), slots.end(), ops[j].forces)-slots.begin());
            op.z = ops[j].checkStep;
            c = ops[j].coefficient;
        }
        kernel->setArg(base+1+2*j, op);
        setMixedArg(kernel, base+2+2*j, c);
    }
}

void CommonIntegrateSymPRKStepKernel::setForceSlotArgs(ComputeKernel& kernel, int base, const vector<ArrayInterface*>& slots) {
    for (int j = 0; j < 2; j++)
        kernel->setArg(base+BUFFER_FORCE0+j, j < (int) slots.size() ? *slots[j] : slots.empty() ? cc.getLongForceBuffer() : *slots[0]);
}

void CommonIntegrateSymPRKStepKernel::flush() {
    if (blockPending) {
        // the pending thermostat event with the segments before and after it, in one block
        IntegrationUtilities& integration = cc.getIntegrationUtilities();
        vector<ArrayInterface*> slots;
        collectForces(blockPre, slots);
        collectForces(pending, slots);
        setSegmentArgs(eventBlockKernel, 0, blockPre, slots);
        setSegmentArgs(eventBlockKernel, SEGMENT_ARGS, pending, slots);
        setForceSlotArgs(eventBlockKernel, 2*SEGMENT_ARGS, slots);
        eventBlockKernel->setArg(EVENT_BLOCK_OWN, integration.getRandom());
        eventBlockKernel->setArg(EVENT_BLOCK_OWN+1, eventRandomIndex);
        setAccArg(eventBlockKernel, EVENT_BLOCK_OWN+3, eventTarget);
        setAccArg(eventBlockKernel, EVENT_BLOCK_OWN+4, eventDecay);
        eventBlockKernel->execute(projectionBlockSize, projectionBlockSize);
        launches++;
        blockPending = false;
        blockPre.clear();
    }
    else if (!pending.empty()) {
        vector<ArrayInterface*> slots;
        collectForces(pending, slots);
        setSegmentArgs(segmentKernel, 0, pending, slots);
        setForceSlotArgs(segmentKernel, SEGMENT_ARGS, slots);
        segmentKernel->execute(cc.getNumAtoms());
        launches++;
    }
    pending.clear();
}

void CommonIntegrateSymPRKStepKernel::placeVirtualSites() {
    if (!virtualSitesPending)
        return;
    flush();
    cc.getIntegrationUtilities().computeVirtualSites();
    virtualSitesPending = false;
}

// -- the step ---------------------------------------------------------------------------------------------------------

bool CommonIntegrateSymPRKStepKernel::canFuseAcross(const SymPRKStepPlan& plan, long long stepIndex) const {
    // The last kick of this step (the tail) and the first of the next (the head) are one launch where only these lie
    // between them: velocity projections, and thermostat events that run in neither step; and the head kicks with the
    // tail's forces (cached: nothing moves the atoms between).
    if (fusion == SymPRKIntegrator::FuseNone || !stepsAreSeparable)
        return false;
    const vector<SymPRKStepPlan::Operation>& ops = plan.getOperations();
    const int n = ops.size();
    int tail = -1, head = -1, lastDrift = -1;
    for (int k = 0; k < n; k++) {
        if (ops[k].kind == SymPRKStepPlan::Kick) {
            tail = k;
            if (head < 0)
                head = k;
        }
    }
    if (tail < 0 || !ops[head].reuseForces || ops[head].forceGroups != ops[tail].forceGroups)
        return false;
    bool skipsProjection = false;
    for (int k = 0; k < n; k++) {
        if (k >= head && k <= tail)
            continue;  // the operations between the kicks are this step's own
        const SymPRKStepPlan::Operation& op = ops[k];
        if (op.kind == SymPRKStepPlan::ProjectVelocities)
            skipsProjection = true;
        else if (op.kind != SymPRKStepPlan::ThermostatEvent || op.runsInStep(k < head ? stepIndex+1 : stepIndex))
            return false;
    }
    if (!skipsProjection)
        return true;
    // A projection left out: the velocities differ from the projected ones along the constraints at these positions
    // only.  The next constrained drift's position projection acts along the same directions and absorbs that
    // (kicks between add to the velocities at the same positions), a projection removes it; an event would read it.
    // And the drift must be no larger than the last drift before the tail, or it would grow the constraint solver's
    // residual, which the projection removes (the rule openmm_symprk.methods.resolved.projected_drifts states
    // within a step; across steps the closing projection does it).
    for (int k = 0; k < tail; k++)
        if (ops[k].kind == SymPRKStepPlan::Drift)
            lastDrift = k;
    int next = head+1;
    while (next < n && ops[next].kind == SymPRKStepPlan::Kick)
        next++;
    if (next == n)
        return false;
    if (ops[next].kind == SymPRKStepPlan::ProjectVelocities)
        return true;
    return ops[next].kind == SymPRKStepPlan::Drift && lastDrift >= 0 && fabs(ops[next].coefficient) <= fabs(ops[lastDrift].coefficient);
}

bool CommonIntegrateSymPRKStepKernel::canSkipClosingProjection(const SymPRKStepPlan& plan) const {
    // A step that ends on a velocity projection after its last drift (the middle placement, position Verlet), where
    // the next step begins with kicks and then a constrained drift: the kicks add to the velocities at the same
    // positions, and the drift's position projection acts along the directions the velocity projection would remove,
    // so it absorbs what was left (the same positions and velocities after it; canFuseAcross states the rule).  The
    // projection then runs once, at the call's end, where the State is read.  The drift must be no larger than the
    // step's last one (the constraint solver's residual) and nothing may read the velocities in between.
    if (fusion == SymPRKIntegrator::FuseNone || !stepsAreSeparable)
        return false;
    const vector<SymPRKStepPlan::Operation>& ops = plan.getOperations();
    const int n = ops.size();
    if (n < 2 || ops[n-1].kind != SymPRKStepPlan::ProjectVelocities || ops[n-2].kind != SymPRKStepPlan::Drift)
        return false;
    int next = 0;
    while (next < n && ops[next].kind == SymPRKStepPlan::Kick)
        next++;
    return next < n-1 && ops[next].kind == SymPRKStepPlan::Drift
        && fabs(ops[next].coefficient) <= fabs(ops[n-2].coefficient);
}

void CommonIntegrateSymPRKStepKernel::execute(ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
        bool& forcesAreValid, long long stepIndex, bool nextStepFollows) {
    ContextSelector selector(cc);
    if (!hasInitializedKernels) {
        hasInitializedKernels = true;
        setKernelArguments(integrator, plan);
    }
    const double dt = integrator.getStepSize();
    if (dt != lastStepSize) {
        cc.getIntegrationUtilities().setNextStepSize(dt);  // an upload (OpenMM's constraint kernels read it)
        lastStepSize = dt;
        hostTransfers++;
    }
    if (context.updateContextState())
        forcesAreValid = false;
    if (!forcesAreValid) {
        for (auto& entry : groupForcesValid)
            entry.second = false;  // cached forces of a multiple-time-step method belong to old positions
        projectionValid = false;
    }
    const vector<SymPRKStepPlan::Operation>& ops = plan.getOperations();
    const int n = ops.size();
    const int first = (headDoneStep == stepIndex ? headDoneIndex+1 : 0);
    headDoneStep = 0;
    const bool across = (nextStepFollows && canFuseAcross(plan, stepIndex));
    int tail = n-1, head = -1;
    if (across) {
        while (ops[tail].kind != SymPRKStepPlan::Kick)
            tail--;
        head = 0;
        while (ops[head].kind != SymPRKStepPlan::Kick)
            head++;
    }
    reorderedThisStep = false;
    const bool skipClosing = (nextStepFollows && !across && canSkipClosingProjection(plan));
    for (int k = first; k < n; k++) {
        if (skipClosing && k == n-1) {
            trace.record(stepIndex, k, 0);  // absorbed by the next step's first drift (canSkipClosingProjection)
            continue;
        }
        if (k > tail) {
            // left out by the fusion across steps: a projection (the trace keeps it, as the plan's), or an event that
            // does not run in this step
            if (ops[k].kind == SymPRKStepPlan::ProjectVelocities)
                trace.record(stepIndex, k, 0);
            continue;
        }
        runOperation(context, integrator, plan, k, stepIndex, forcesAreValid);
    }
    if (across) {
        // the next step's operations up to its first kick, which joins this step's last in the segment being gathered;
        // the rest of the next step's per-atom operations up to its first constraint or force evaluation join it there
        for (int k = 0; k < head; k++)
            if (ops[k].kind == SymPRKStepPlan::ProjectVelocities)
                trace.record(stepIndex+1, k, 0);
        runOperation(context, integrator, plan, head, stepIndex+1, forcesAreValid);
        headDoneStep = stepIndex+1;
        headDoneIndex = head;
    }
    else {
        flush();
        placeVirtualSites();
    }
    cc.setTime(cc.getTime()+dt);
    cc.setStepCount(cc.getStepCount()+1);
    if (!reorderedThisStep)
        reorderAtoms(forcesAreValid);
}

void CommonIntegrateSymPRKStepKernel::reorderAtoms(bool& forcesAreValid) {
    // OpenMM reorders the atoms (every 250 steps, on the host) at the end of a step; the fused kernel does it before the
    // step's force evaluation that follows its last drift, where nothing is pending and the positions are those of
    // the step's end, so that a segment may continue into the next step.  Either way once a step.
    flush();
    placeVirtualSites();
    cc.reorderAtoms();
    reorderedThisStep = true;
    if (cc.getAtomsWereReordered()) {
        forcesAreValid = false;
        projectionValid = false;
        for (auto& entry : groupForcesValid)
            entry.second = false;
    }
}

void CommonIntegrateSymPRKStepKernel::runOperation(ContextImpl& context, const SymPRKIntegrator& integrator,
        const SymPRKStepPlan& plan, int k, long long stepIndex, bool& forcesAreValid) {
    const SymPRKStepPlan::Operation& op = plan.getOperations()[k];
    const double dt = integrator.getStepSize();
    const double tol = integrator.getConstraintTolerance();
    const bool exact = integrator.getExactMomentum();
    // the velocities are checked for a blow-up by the operation the plan names
    const int checkStep = (op.checkVelocities && blowUpStep == 0 ? (int) min(stepIndex, (long long) INT_MAX) : 0);
    int evaluated = 0;
    // a force evaluation after the step's last drift may reorder the atoms first (see reorderAtoms)
    int lastDrift = -1;
    for (int i = 0; i < (int) plan.getOperations().size(); i++)
        if (plan.getOperations()[i].kind == SymPRKStepPlan::Drift)
            lastDrift = i;
    reorderBeforeEvaluation = (fusion != SymPRKIntegrator::FuseNone && k > lastDrift && !reorderedThisStep);
    switch (op.kind) {
    case SymPRKStepPlan::ThermostatEvent:
        if (!op.runsInStep(stepIndex))
            return;
        thermostatEvent(integrator, op.decay(dt));
        break;
    case SymPRKStepPlan::Kick:
        kick(kickForces(context, op, forcesAreValid, evaluated), op.coefficient*dt, exact, checkStep);
        break;
    case SymPRKStepPlan::Drift:
        drift(op.coefficient*dt, tol, exact, checkStep);
        forcesAreValid = false;
        for (auto& entry : groupForcesValid)
            entry.second = false;
        break;
    case SymPRKStepPlan::ProjectVelocities:
        projectVelocities(tol, exact);
        break;
    }
    trace.record(stepIndex, k, evaluated);
}

ArrayInterface& CommonIntegrateSymPRKStepKernel::kickForces(ContextImpl& context, const SymPRKStepPlan::Operation& op,
        bool& forcesAreValid, int& evaluated) {
    // The forces of this kick's groups: computed unless the plan lets it reuse cached forces and they are still
    // valid (a multiple-time-step method keeps a copy per group, so that a group is evaluated only where a drift
    // came between two of its kicks).  Fused, a group's forces are copied only when another group's evaluation is
    // about to overwrite them in the force buffer, and read from the buffer until then.
    evaluated = 0;
    if (op.reuseForces && op.keepGroupCopy && groupForcesValid[op.forceGroups])
        return *groupForces[op.forceGroups];
    if (mustEvaluateForces(op, forcesAreValid, context)) {
        flush();  // what the forces overwrite, and the positions they are computed at
        placeVirtualSites();
        if (reorderBeforeEvaluation)
            reorderAtoms(forcesAreValid);
        const int held = context.getLastForceGroups();
        if (op.keepGroupCopy && fusion != SymPRKIntegrator::FuseNone && forcesAreValid && held != op.forceGroups &&
                groupForcesValid.count(held) != 0 && !groupForcesValid[held])
            copyGroupForces(held);  // the buffer's forces of another group, which a later kick may reuse
        {
            ContextDeselector deselector(cc);
            context.calcForcesAndEnergy(true, false, op.forceGroups);
        }
        forcesAreValid = true;
        projectionValid = false;
        evaluated = op.forceGroups;
    }
    if (!op.keepGroupCopy)
        return cc.getLongForceBuffer();
    if (fusion != SymPRKIntegrator::FuseNone) {
        groupForcesValid.emplace(op.forceGroups, false);  // (known: its forces are copied before they are overwritten)
        return cc.getLongForceBuffer();
    }
    copyGroupForces(op.forceGroups);
    return *groupForces[op.forceGroups];
}

void CommonIntegrateSymPRKStepKernel::copyGroupForces(int groups) {
    unique_ptr<ComputeArray>& copy = groupForces[groups];
    if (!copy) {
        copy.reset(new ComputeArray());
        copy->initialize(cc, cc.getLongForceBuffer().getSize(), cc.getLongForceBuffer().getElementSize(), "symprkGroupForces");
    }
    for (const vector<SegmentOp>* ops : {&blockPre, &pending})
        for (const SegmentOp& pendingOp : *ops)
            if (pendingOp.forces == copy.get())
                flush();  // a pending kick reads the copy's old forces
    cc.getLongForceBuffer().copyTo(*copy);
    launches++;
    groupForcesValid[groups] = true;
}

void CommonIntegrateSymPRKStepKernel::ensureProjection(ArrayInterface& forces) {
    if (fusion != SymPRKIntegrator::FuseNone && projectionValid && projectionForces == &forces)
        return;
    flush();  // a pending projected kick reads the old projection
    projectionKernel->setArg(3, forces);
    projectionKernel->execute(projectionBlockSize, projectionBlockSize);
    launches++;
    projectionValid = true;
    projectionForces = &forces;
}

void CommonIntegrateSymPRKStepKernel::kick(ArrayInterface& forces, double cdt, bool exact, int checkStep) {
    if (exact) {
        ensureProjection(forces);
        append({OpKickProjected, cdt, 0, checkStep, &forces});
    }
    else
        append({OpKick, cdt, 0, checkStep, &forces});
}

void CommonIntegrateSymPRKStepKernel::drift(double cdt, double tol, bool exact, int checkStep) {
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    if (hasConstraints) {
        append({OpDriftDelta, cdt, 0, 0, NULL});
        flush();
        integration.applyConstraints(tol);
        if (exact) {
            // Exact momentum: cancel the round-off net momentum and torque of the constraint impulses
            // (about the pre-drift positions) with a rigid-body velocity at the new positions.
            rigidSumsKernel->setArg(0, 0);
            setMixedArg(rigidSumsKernel, 1, cdt);
            rigidSumsKernel->execute(projectionBlockSize, projectionBlockSize);
            launches++;
        }
        append({OpDriftApply, cdt, exact ? 1 : 0, checkStep, NULL});
    }
    else
        append({OpDrift, cdt, 0, 0, NULL});
    virtualSitesPending = true;
    projectionValid = false;
    if (fusion == SymPRKIntegrator::FuseNone)
        placeVirtualSites();
}

void CommonIntegrateSymPRKStepKernel::projectVelocities(double tol, bool exact) {
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    if (!exact) {
        flush();
        integration.applyVelocityConstraints(tol);
        return;
    }
    // Exact momentum: remove the round-off net momentum and torque of the velocity-constraint impulses.
    append({OpSaveVelocities, 0.0, 0, 0, NULL});
    flush();
    integration.applyVelocityConstraints(tol);
    rigidSumsKernel->setArg(0, 1);
    setMixedArg(rigidSumsKernel, 1, 1.0);
    rigidSumsKernel->execute(projectionBlockSize, projectionBlockSize);
    launches++;
    append({OpRigidApply, 0.0, 0, 0, NULL});
}

void CommonIntegrateSymPRKStepKernel::thermostatEvent(const SymPRKIntegrator& integrator, double decay) {
    // The whole event on the device: the random numbers from OpenMM's generator, one block reducing the particles and
    // computing the factor and the kept field, and the apply; nothing is read back.  Up to getKernelFusionBlockAtoms()
    // atoms that block also runs the segments before and after the event; else the sums run alone and the apply
    // joins the next segment.
    if (blockPending)
        flush();  // its event must read its random numbers before the next are prepared (which may make new ones)
    const bool oneBlock = (fusion == SymPRKIntegrator::FuseAll && cc.getNumAtoms() <= SymPRKIntegrator::getKernelFusionBlockAtoms());
    if (!oneBlock)
        flush();
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    const int dof = integrator.getThermostatDof();
    eventRandomIndex = integration.prepareRandomNumbers((dof+3)/4);
    eventTarget = 0.5*dof*SymPRKThermostat::boltzmann()*integrator.getThermostatTemperature();
    eventDecay = decay;
    eventBlockKernel->setArg(EVENT_BLOCK_OWN+2, dof);
    blockPre.swap(pending);
    pending.clear();
    blockPending = true;
    if (!oneBlock)
        flush();  // the sums alone (both segments empty)
    append({OpEventApply, 0.0, 0, 0, NULL});
}

vector<double> CommonIntegrateSymPRKStepKernel::sampleThermostatNoise(ContextImpl& context, int dof, int count) {
    // Event by event, as thermostatEvent takes its numbers (one prepareRandomNumbers block each), into one array read
    // back at the end.
    vector<double> values(2*(size_t) count, 0.0);
    if (count == 0 || !thermostatNoiseKernel)
        return values;
    ContextSelector selector(cc);
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    const int accSize = (cc.getSupportsDoublePrecision() ? sizeof(double) : sizeof(float));
    ComputeArray out;
    out.initialize(cc, 2*count, accSize, "symprkThermostatNoise");
    thermostatNoiseKernel->setArg(2, dof);
    thermostatNoiseKernel->setArg(3, out);
    for (int i = 0; i < count; i++) {
        const int index = integration.prepareRandomNumbers((dof+3)/4);
        thermostatNoiseKernel->setArg(0, integration.getRandom());
        thermostatNoiseKernel->setArg(1, index);
        thermostatNoiseKernel->setArg(4, i);
        thermostatNoiseKernel->execute(projectionBlockSize, projectionBlockSize);
    }
    if (accSize == sizeof(double))
        out.download(values);
    else {
        vector<float> single;
        out.download(single);
        values.assign(single.begin(), single.end());
    }
    hostTransfers++;
    return values;
}

void CommonIntegrateSymPRKStepKernel::initializeThermostat(int seed) {
    // The platform's generator is set up with or without a thermostat, so that the Context's checkpoints have the
    // same layout (its random state comes before the integrator's block) and an NVE checkpoint loaded into an NVT
    // Context, or the reverse, meets this integrator's own check.  Where something else in the Context (an
    // AndersenThermostat) seeded it first with another seed, the thermostat draws from that stream.
    ContextSelector selector(cc);
    try {
        cc.getIntegrationUtilities().initRandomNumberGenerator((unsigned int) seed);
        hostTransfers++;
    }
    catch (OpenMMException&) {
        // already seeded (with another seed): shared
    }
    setThermostatRunState(SymPRKThermostat::RunState());
}

// The run state on the device: {heat-bath energy, kinetic energy after the last event, skipped events, last skipped,
// peculiar kinetic energy after the last event}.
SymPRKThermostat::RunState CommonIntegrateSymPRKStepKernel::getThermostatRunState() {
    SymPRKThermostat::RunState run;
    if (!thermostatState.isInitialized())
        return run;
    ContextSelector selector(cc);
    vector<double> values(5, 0.0);
    if (thermostatState.getElementSize() == sizeof(double))
        thermostatState.download(values);
    else {
        vector<float> single;
        thermostatState.download(single);
        values.assign(single.begin(), single.end());
    }
    hostTransfers++;
    run.heatBathEnergy = values[0];
    run.kineticEnergy = values[1];
    run.skippedEvents = (long long) values[2];
    run.lastSkipped = (values[3] != 0);
    run.peculiarKineticEnergy = values[4];
    return run;
}

void CommonIntegrateSymPRKStepKernel::setThermostatRunState(const SymPRKThermostat::RunState& run) {
    if (!thermostatState.isInitialized())
        return;
    ContextSelector selector(cc);
    const vector<double> values = {run.heatBathEnergy, run.kineticEnergy, (double) run.skippedEvents, run.lastSkipped ? 1.0 : 0.0,
                                   run.peculiarKineticEnergy};
    if (thermostatState.getElementSize() == sizeof(double))
        thermostatState.upload(values);
    else
        thermostatState.upload(vector<float>(values.begin(), values.end()));
    hostTransfers++;
}

string CommonIntegrateSymPRKStepKernel::getRandomState() {
    // the generator's state is the platform's (IntegrationUtilities), in the Context's own checkpoint
    return "device";
}

void CommonIntegrateSymPRKStepKernel::setRandomState(const string& state) {
    if (state != "device")
        throw OpenMMException("SymPRKIntegrator: the checkpoint's thermostat random state was written on the Reference or CPU "
                              "platform; a checkpoint loads on the platform that wrote it");
}

double CommonIntegrateSymPRKStepKernel::computeKineticEnergy(ContextImpl& context, const SymPRKIntegrator& integrator) {
    hostTransfers++;
    return cc.getIntegrationUtilities().computeKineticEnergy(0.0);
}

long long CommonIntegrateSymPRKStepKernel::getBlowUpStep(ContextImpl& context) {
    if (blowUpStep == 0 && badStep.isInitialized()) {
        ContextSelector selector(cc);
        int value;
        badStep.download(&value);
        hostTransfers++;
        blowUpStep = value;
    }
    return blowUpStep;
}

void CommonIntegrateSymPRKStepKernel::setBlowUpStep(ContextImpl& context, long long step) {
    blowUpStep = step;
    if (badStep.isInitialized()) {
        ContextSelector selector(cc);
        int value = (int) min(step, (long long) INT_MAX);
        badStep.upload(&value);
        hostTransfers++;
    }
}
