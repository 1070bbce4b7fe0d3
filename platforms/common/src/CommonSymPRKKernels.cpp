/* openmm_symprk native plugin: the Common compute framework SymPRKIntegrator kernel.  It runs the operations of
 * the step plan (SymPRKStepPlan) in order, one or a few device kernels per operation. */

#include "CommonSymPRKKernels.h"
#include "openmm/common/ContextSelector.h"
#include "openmm/common/IntegrationUtilities.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"
#include <algorithm>
#include <climits>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace SymPRKPlugin;
using namespace OpenMM;
using namespace std;

void CommonIntegrateSymPRKStepKernel::initialize(const System& system, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan) {
    cc.initializeContexts();
    ContextSelector selector(cc);
    hasConstraints = plan.hasConstraints();
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
    // Squared blow-up speed: the given one, or the largest finite value of the velocity type (so that only NaN
    // and infinity count, as every comparison with NaN is false and inf <= max is false).
    const bool doubleVelocities = (cc.getUseDoublePrecision() || cc.getUseMixedPrecision());
    const double maxSpeed = integrator.getMaxSpeed();
    if (maxSpeed > 0)
        defines["MAX_SPEED2"] = cc.doubleToString(maxSpeed*maxSpeed, true);
    else
        defines["MAX_SPEED2"] = (doubleVelocities ? "1.7976931348623157e308" : "3.402823466e38f");
    ComputeProgram program = cc.compileProgram(CommonSymPRKKernelSources::symprk, defines);
    kickKernel = program->createKernel("symprkKick");
    kickProjectedKernel = program->createKernel("symprkKickProjected");
    driftKernel = program->createKernel("symprkDrift");
    driftDeltaKernel = program->createKernel("symprkDriftDelta");
    driftApplyKernel = program->createKernel("symprkDriftApply");
    projectionKernel = program->createKernel("symprkProjection");
    rigidSumsKernel = program->createKernel("symprkRigidSums");
    rigidApplyKernel = program->createKernel("symprkRigidApply");
    const int mixedSize = (doubleVelocities ? sizeof(double) : sizeof(float));
    projection.initialize(cc, 9, mixedSize, "symprkProjection");
    rigid.initialize(cc, 9, mixedSize, "symprkRigid");
    vBefore.initialize(cc, cc.getPaddedNumAtoms(), 4*mixedSize, "symprkVelocitiesBefore");
    badStep.initialize<int>(cc, 1, "symprkBadStep");
    if (plan.hasThermostatEvents()) {
        thermostatEventKernel = program->createKernel("symprkThermostatEvent");
        thermostatApplyKernel = program->createKernel("symprkThermostatApply");
        thermostatNoiseKernel = program->createKernel("symprkThermostatNoise");
        for (int i = 0; i < 5; i++)
            thermostatNoiseKernel->addArg();  // random, its index, dof, the output, the sample: set per call
        // double where the device has it (symprk_acc in the device source)
        const int accSize = (cc.getSupportsDoublePrecision() ? sizeof(double) : sizeof(float));
        thermostatEventData.initialize(cc, 11, accSize, "symprkThermostatEvent");
        thermostatState.initialize(cc, 5, accSize, "symprkThermostatState");
    }
    groupForces.clear();
    groupForcesValid.clear();
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
    // Arguments set per operation (left empty here): the coefficient c*dt (index 0), the check step, the forces.
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    ArrayInterface* velm = &cc.getVelm();
    ArrayInterface* posDelta = &integration.getPosDelta();
    kickKernel->addArg();
    addArrayArgs(kickKernel, {velm, &cc.getLongForceBuffer()});
    kickKernel->addArg(0);
    kickKernel->addArg(badStep);
    kickProjectedKernel->addArg();
    addArrayArgs(kickProjectedKernel, {velm, &cc.getLongForceBuffer()});
    addPositionArgs(kickProjectedKernel);
    kickProjectedKernel->addArg(projection);
    kickProjectedKernel->addArg(0);
    kickProjectedKernel->addArg(badStep);
    driftKernel->addArg();
    addPositionArgs(driftKernel);
    driftKernel->addArg(*velm);
    driftDeltaKernel->addArg();
    addArrayArgs(driftDeltaKernel, {velm, posDelta});
    driftApplyKernel->addArg();
    addPositionArgs(driftApplyKernel);
    addArrayArgs(driftApplyKernel, {velm, posDelta});
    driftApplyKernel->addArg(0);
    driftApplyKernel->addArg(badStep);
    driftApplyKernel->addArg(0);
    driftApplyKernel->addArg(rigid);
    rigidSumsKernel->addArg();
    rigidSumsKernel->addArg();
    addPositionArgs(rigidSumsKernel);
    addArrayArgs(rigidSumsKernel, {velm, posDelta, &vBefore, &rigid});
    addPositionArgs(rigidApplyKernel);
    addArrayArgs(rigidApplyKernel, {velm, &rigid});
    addPositionArgs(projectionKernel);
    addArrayArgs(projectionKernel, {velm, &cc.getLongForceBuffer(), &projection});
    if (plan.hasThermostatEvents()) {
        const int withPositions = integrator.getThermostatKeepsRotation() ? 1 : 0;
        addPositionArgs(thermostatEventKernel);
        thermostatEventKernel->addArg(*velm);
        thermostatEventKernel->addArg(withPositions);
        for (int i = 0; i < 5; i++)
            thermostatEventKernel->addArg();  // random, its index, dof, target, c: set per event
        thermostatEventKernel->addArg(thermostatEventData);
        thermostatEventKernel->addArg(thermostatState);
        addPositionArgs(thermostatApplyKernel);
        thermostatApplyKernel->addArg(*velm);
        thermostatApplyKernel->addArg(withPositions);
        thermostatApplyKernel->addArg(thermostatEventData);
    }
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

void CommonIntegrateSymPRKStepKernel::execute(ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
        bool& forcesAreValid, long long stepIndex) {
    ContextSelector selector(cc);
    if (!hasInitializedKernels) {
        hasInitializedKernels = true;
        setKernelArguments(integrator, plan);
    }
    const double dt = integrator.getStepSize();
    const double tol = integrator.getConstraintTolerance();
    const bool exact = integrator.getExactMomentum();
    if (dt != lastStepSize) {
        cc.getIntegrationUtilities().setNextStepSize(dt);  // an upload (OpenMM's constraint kernels read it)
        lastStepSize = dt;
        hostTransfers++;
    }
    const int check = (int) min(stepIndex, (long long) INT_MAX);

    if (context.updateContextState())
        forcesAreValid = false;
    if (!forcesAreValid)
        for (auto& entry : groupForcesValid)
            entry.second = false;  // cached forces of a multiple-time-step method belong to old positions
    const vector<SymPRKStepPlan::Operation>& ops = plan.getOperations();
    for (int k = 0; k < (int) ops.size(); k++) {
        const SymPRKStepPlan::Operation& op = ops[k];
        // the velocities are checked for a blow-up by the kernel of the operation the plan names
        const int checkStep = (op.checkVelocities && blowUpStep == 0 ? check : 0);
        int evaluated = 0;
        switch (op.kind) {
        case SymPRKStepPlan::ThermostatEvent:
            if (!op.runsInStep(stepIndex))
                continue;
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
    cc.setTime(cc.getTime()+dt);
    cc.setStepCount(cc.getStepCount()+1);
    cc.reorderAtoms();
    if (cc.getAtomsWereReordered())
        forcesAreValid = false;
}

ArrayInterface& CommonIntegrateSymPRKStepKernel::kickForces(ContextImpl& context, const SymPRKStepPlan::Operation& op,
        bool& forcesAreValid, int& evaluated) {
    // The forces of this kick's groups: computed unless the plan lets it reuse cached forces and they are still
    // valid (a multiple-time-step method keeps a copy per group, so that a group is evaluated only where a drift
    // came between two of its kicks).
    evaluated = 0;
    if (op.reuseForces && op.keepGroupCopy && groupForcesValid[op.forceGroups])
        return *groupForces[op.forceGroups];
    if (mustEvaluateForces(op, forcesAreValid, context)) {
        ContextDeselector deselector(cc);
        context.calcForcesAndEnergy(true, false, op.forceGroups);
        forcesAreValid = true;
        evaluated = op.forceGroups;
    }
    if (!op.keepGroupCopy)
        return cc.getLongForceBuffer();
    unique_ptr<ComputeArray>& copy = groupForces[op.forceGroups];
    if (!copy) {
        copy.reset(new ComputeArray());
        copy->initialize(cc, cc.getLongForceBuffer().getSize(), cc.getLongForceBuffer().getElementSize(), "symprkGroupForces");
    }
    cc.getLongForceBuffer().copyTo(*copy);
    groupForcesValid[op.forceGroups] = true;
    return *copy;
}

void CommonIntegrateSymPRKStepKernel::kick(ArrayInterface& forces, double cdt, bool exact, int checkStep) {
    kickKernel->setArg(2, forces);
    kickProjectedKernel->setArg(2, forces);
    projectionKernel->setArg(3, forces);
    if (exact) {
        projectionKernel->execute(projectionBlockSize, projectionBlockSize);
        setMixedArg(kickProjectedKernel, 0, cdt);
        kickProjectedKernel->setArg(6, checkStep);
        kickProjectedKernel->execute(cc.getNumAtoms());
    }
    else {
        setMixedArg(kickKernel, 0, cdt);
        kickKernel->setArg(3, checkStep);
        kickKernel->execute(cc.getNumAtoms());
    }
}

void CommonIntegrateSymPRKStepKernel::drift(double cdt, double tol, bool exact, int checkStep) {
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    if (hasConstraints) {
        setMixedArg(driftDeltaKernel, 0, cdt);
        driftDeltaKernel->execute(cc.getNumAtoms());
        integration.applyConstraints(tol);
        if (exact) {
            // Exact momentum: cancel the round-off net momentum and torque of the constraint impulses
            // (about the pre-drift positions) with a rigid-body velocity at the new positions.
            rigidSumsKernel->setArg(0, 0);
            setMixedArg(rigidSumsKernel, 1, cdt);
            rigidSumsKernel->execute(projectionBlockSize, projectionBlockSize);
        }
        setMixedArg(driftApplyKernel, 0, cdt);
        driftApplyKernel->setArg(5, checkStep);
        driftApplyKernel->setArg(7, exact ? 1 : 0);
        driftApplyKernel->execute(cc.getNumAtoms());
    }
    else {
        setMixedArg(driftKernel, 0, cdt);
        driftKernel->execute(cc.getNumAtoms());
    }
    integration.computeVirtualSites();
}

void CommonIntegrateSymPRKStepKernel::projectVelocities(double tol, bool exact) {
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    if (!exact) {
        integration.applyVelocityConstraints(tol);
        return;
    }
    // Exact momentum: remove the round-off net momentum and torque of the velocity-constraint impulses.
    cc.getVelm().copyTo(vBefore);
    integration.applyVelocityConstraints(tol);
    rigidSumsKernel->setArg(0, 1);
    setMixedArg(rigidSumsKernel, 1, 1.0);
    rigidSumsKernel->execute(projectionBlockSize, projectionBlockSize);
    rigidApplyKernel->execute(cc.getNumAtoms());
}

void CommonIntegrateSymPRKStepKernel::thermostatEvent(const SymPRKIntegrator& integrator, double decay) {
    // The whole event on the device: the random numbers from OpenMM's generator, one block reducing the particles and
    // computing the factor and the kept field, one kernel applying them; nothing is read back.
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    const int dof = integrator.getThermostatDof();
    const int index = integration.prepareRandomNumbers((dof+3)/4);
    thermostatEventKernel->setArg(4, integration.getRandom());
    thermostatEventKernel->setArg(5, index);
    thermostatEventKernel->setArg(6, dof);
    setAccArg(thermostatEventKernel, 7, 0.5*dof*SymPRKThermostat::boltzmann()*integrator.getThermostatTemperature());
    setAccArg(thermostatEventKernel, 8, decay);
    thermostatEventKernel->execute(projectionBlockSize, projectionBlockSize);
    thermostatApplyKernel->execute(cc.getNumAtoms());
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
