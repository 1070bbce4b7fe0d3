/* openmm_symprk native plugin: the Common compute framework SymPRKIntegrator kernel. */

#include "CommonSymPRKKernels.h"
#include "openmm/common/ContextSelector.h"
#include "openmm/common/IntegrationUtilities.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"
#include <algorithm>
#include <climits>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <vector>

using namespace OpenMM;
using namespace std;

void CommonIntegrateSymPRKStepKernel::initialize(const System& system, const SymPRKIntegrator& integrator) {
    cc.initializeContexts();
    ContextSelector selector(cc);
    hasConstraints = (system.getNumConstraints() > 0);
    projectionBlockSize = 1;
    while (projectionBlockSize*2 <= min(128, cc.getMaxThreadBlockSize()))
        projectionBlockSize *= 2;
    // The thermostat's reduction leaves its 17 sums in the first 17 threads' slots (kernels/symprk.cc).
    if (integrator.hasThermostat() && projectionBlockSize < 32)
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
    bool useDouble = (cc.getUseDoublePrecision() || cc.getUseMixedPrecision());
    projection.initialize(cc, 9, useDouble ? sizeof(double) : sizeof(float), "symprkProjection");
    rigid.initialize(cc, 9, useDouble ? sizeof(double) : sizeof(float), "symprkRigid");
    vBefore.initialize(cc, cc.getPaddedNumAtoms(), useDouble ? 4*sizeof(double) : 4*sizeof(float), "symprkVelocitiesBefore");
    badStep.initialize<int>(cc, 1, "symprkBadStep");
    if (integrator.hasThermostat()) {
        thermostatSumsKernel = program->createKernel("symprkThermostatSums");
        thermostatApplyKernel = program->createKernel("symprkThermostatApply");
        // the sums' type: double where the device has it (symprk_acc in the device source)
        thermostatSums.initialize(cc, SymPRKThermostat::NumSums, cc.getSupportsDoublePrecision() ? sizeof(double) : sizeof(float),
                                  "symprkThermostatSums");
    }
    set<int> kickGroups;
    for (int s = 0; s < integrator.getNumSubsteps(); s++)
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick)
            kickGroups.insert(integrator.getSubstepForceGroups(s) == -1 ? integrator.getIntegrationForceGroups()
                                                                        : integrator.getSubstepForceGroups(s));
    multipleGroups = (kickGroups.size() > 1);
    if (multipleGroups)
        for (int mask : kickGroups) {
            groupForces[mask].reset(new ComputeArray());
            groupForces[mask]->initialize(cc, cc.getLongForceBuffer().getSize(), cc.getLongForceBuffer().getElementSize(),
                                          "symprkGroupForces");
            groupForcesValid[mask] = false;
        }
    int zero = 0;
    badStep.upload(&zero);
    if (blowUpStep != 0)
        setBlowUpStep(*cc.getContextImpl(), blowUpStep);
}

void CommonIntegrateSymPRKStepKernel::setMixedArg(ComputeKernel& kernel, int index, double value) {
    if (cc.getUseDoublePrecision() || cc.getUseMixedPrecision())
        kernel->setArg(index, value);
    else
        kernel->setArg(index, (float) value);
}

void CommonIntegrateSymPRKStepKernel::execute(ContextImpl& context, const SymPRKIntegrator& integrator, bool& forcesAreValid, long long stepIndex) {
    ContextSelector selector(cc);
    IntegrationUtilities& integration = cc.getIntegrationUtilities();
    const int numAtoms = cc.getNumAtoms();
    const bool mixed = cc.getUseMixedPrecision();
    if (!hasInitializedKernels) {
        hasInitializedKernels = true;
        // Arguments set per sub-step: the coefficient (index 0) and the check step.
        kickKernel->addArg();
        kickKernel->addArg(cc.getVelm());
        kickKernel->addArg(cc.getLongForceBuffer());
        kickKernel->addArg(0);
        kickKernel->addArg(badStep);
        kickProjectedKernel->addArg();
        kickProjectedKernel->addArg(cc.getVelm());
        kickProjectedKernel->addArg(cc.getLongForceBuffer());
        kickProjectedKernel->addArg(cc.getPosq());
        if (mixed)
            kickProjectedKernel->addArg(cc.getPosqCorrection());
        else
            kickProjectedKernel->addArg(nullptr);
        kickProjectedKernel->addArg(projection);
        kickProjectedKernel->addArg(0);
        kickProjectedKernel->addArg(badStep);
        driftKernel->addArg();
        driftKernel->addArg(cc.getPosq());
        if (mixed)
            driftKernel->addArg(cc.getPosqCorrection());
        else
            driftKernel->addArg(nullptr);
        driftKernel->addArg(cc.getVelm());
        driftDeltaKernel->addArg();
        driftDeltaKernel->addArg(cc.getVelm());
        driftDeltaKernel->addArg(integration.getPosDelta());
        driftApplyKernel->addArg();
        driftApplyKernel->addArg(cc.getPosq());
        if (mixed)
            driftApplyKernel->addArg(cc.getPosqCorrection());
        else
            driftApplyKernel->addArg(nullptr);
        driftApplyKernel->addArg(cc.getVelm());
        driftApplyKernel->addArg(integration.getPosDelta());
        driftApplyKernel->addArg(0);
        driftApplyKernel->addArg(badStep);
        driftApplyKernel->addArg(0);
        driftApplyKernel->addArg(rigid);
        rigidSumsKernel->addArg();
        rigidSumsKernel->addArg();
        rigidSumsKernel->addArg(cc.getPosq());
        if (mixed)
            rigidSumsKernel->addArg(cc.getPosqCorrection());
        else
            rigidSumsKernel->addArg(nullptr);
        rigidSumsKernel->addArg(cc.getVelm());
        rigidSumsKernel->addArg(integration.getPosDelta());
        rigidSumsKernel->addArg(vBefore);
        rigidSumsKernel->addArg(rigid);
        rigidApplyKernel->addArg(cc.getPosq());
        if (mixed)
            rigidApplyKernel->addArg(cc.getPosqCorrection());
        else
            rigidApplyKernel->addArg(nullptr);
        rigidApplyKernel->addArg(cc.getVelm());
        rigidApplyKernel->addArg(rigid);
        projectionKernel->addArg(cc.getPosq());
        if (mixed)
            projectionKernel->addArg(cc.getPosqCorrection());
        else
            projectionKernel->addArg(nullptr);
        projectionKernel->addArg(cc.getVelm());
        projectionKernel->addArg(cc.getLongForceBuffer());
        projectionKernel->addArg(projection);
        if (integrator.hasThermostat()) {
            const int withPositions = integrator.getThermostatKeepsRotation() ? 1 : 0;
            thermostatSumsKernel->addArg(cc.getPosq());
            if (mixed)
                thermostatSumsKernel->addArg(cc.getPosqCorrection());
            else
                thermostatSumsKernel->addArg(nullptr);
            thermostatSumsKernel->addArg(cc.getVelm());
            thermostatSumsKernel->addArg(withPositions);
            thermostatSumsKernel->addArg(thermostatSums);
            thermostatApplyKernel->addArg(cc.getPosq());
            if (mixed)
                thermostatApplyKernel->addArg(cc.getPosqCorrection());
            else
                thermostatApplyKernel->addArg(nullptr);
            thermostatApplyKernel->addArg(cc.getVelm());
            thermostatApplyKernel->addArg(withPositions);
            for (int i = 0; i < 10; i++)
                thermostatApplyKernel->addArg();  // alpha, V, R, w: set per event
        }
    }
    const double dt = integrator.getStepSize();
    const double tol = integrator.getConstraintTolerance();
    const int groups = integrator.getIntegrationForceGroups();
    const bool exact = integrator.getExactMomentum();
    const int numSubsteps = integrator.getNumSubsteps();
    integration.setNextStepSize(dt);

    // The velocities are checked for a blow-up in the last sub-step that changes them.
    int lastVelocityStep = -1;
    for (int s = 0; s < numSubsteps; s++)
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick || hasConstraints)
            lastVelocityStep = s;
    const int check = (int) min(stepIndex, (long long) INT_MAX);

    if (context.updateContextState())
        forcesAreValid = false;
    if (!forcesAreValid)
        for (auto& entry : groupForcesValid)
            entry.second = false;  // cached forces of a multiple-time-step method belong to old positions
    // Thermostat: a half event before the first step of every interval (after the Context's state updates, a
    // barostat's move included), and one after its last step (below).
    if (thermostatBefore(integrator, stepIndex))
        thermostatEvent(integrator);
    for (int s = 0; s < numSubsteps; s++) {
        const double cdt = integrator.getSubstepCoefficient(s)*dt;
        const int checkStep = (s == lastVelocityStep && blowUpStep == 0 ? check : 0);
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick) {
            // The forces of this kick's groups: computed unless cached since the last drift (a multiple-time-step
            // method keeps a copy per group, so that a group is evaluated only where a drift came between two of
            // its kicks).
            const int mask = (integrator.getSubstepForceGroups(s) == -1 ? groups : integrator.getSubstepForceGroups(s));
            const bool reuse = (integrator.getSubstepFlags(s) & SymPRKIntegrator::ForcesCached) != 0;
            ArrayInterface* kickForces = &cc.getLongForceBuffer();
            if (reuse && multipleGroups && groupForcesValid[mask])
                kickForces = groupForces[mask].get();
            else {
                if (!reuse || !forcesAreValid || context.getLastForceGroups() != mask) {
                    ContextDeselector deselector(cc);
                    context.calcForcesAndEnergy(true, false, mask);
                    forcesAreValid = true;
                }
                if (multipleGroups) {
                    cc.getLongForceBuffer().copyTo(*groupForces[mask]);
                    groupForcesValid[mask] = true;
                    kickForces = groupForces[mask].get();
                }
            }
            kickKernel->setArg(2, *kickForces);
            kickProjectedKernel->setArg(2, *kickForces);
            projectionKernel->setArg(3, *kickForces);
            if (exact) {
                projectionKernel->execute(projectionBlockSize, projectionBlockSize);
                setMixedArg(kickProjectedKernel, 0, cdt);
                kickProjectedKernel->setArg(6, checkStep);
                kickProjectedKernel->execute(numAtoms);
            }
            else {
                setMixedArg(kickKernel, 0, cdt);
                kickKernel->setArg(3, checkStep);
                kickKernel->execute(numAtoms);
            }
        }
        else {
            // a projection before a drift flagged for one (openmm_symprk.methods.resolved states the rule)
            if (hasConstraints && (integrator.getSubstepFlags(s) & SymPRKIntegrator::ProjectVelocitiesBefore) != 0)
                projectVelocities(tol, exact);
            if (hasConstraints) {
                setMixedArg(driftDeltaKernel, 0, cdt);
                driftDeltaKernel->execute(numAtoms);
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
                driftApplyKernel->execute(numAtoms);
            }
            else {
                setMixedArg(driftKernel, 0, cdt);
                driftKernel->execute(numAtoms);
            }
            integration.computeVirtualSites();
            forcesAreValid = false;
            for (auto& entry : groupForcesValid)
                entry.second = false;
        }
    }
    if (hasConstraints)
        projectVelocities(tol, exact);
    if (thermostatAfter(integrator, stepIndex))
        thermostatEvent(integrator);
    cc.setTime(cc.getTime()+dt);
    cc.setStepCount(cc.getStepCount()+1);
    cc.reorderAtoms();
    if (cc.getAtomsWereReordered())
        forcesAreValid = false;
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

void CommonIntegrateSymPRKStepKernel::thermostatEvent(const SymPRKIntegrator& integrator) {
    // One reduction on the device, one download of its sums, the factor and the kept field on the host
    // (SymPRKThermostat), one kernel applying them.
    thermostatSumsKernel->execute(projectionBlockSize, projectionBlockSize);
    vector<double> sums(SymPRKThermostat::NumSums);
    if (thermostatSums.getElementSize() == sizeof(double))
        thermostatSums.download(sums);
    else {
        vector<float> single(SymPRKThermostat::NumSums);
        thermostatSums.download(single);
        for (int i = 0; i < SymPRKThermostat::NumSums; i++)
            sums[i] = single[i];
    }
    const SymPRKThermostat::Event e = thermostat.event(sums.data(), integrator, thermostatDecay(integrator));
    if (!e.apply)
        return;
    const double values[10] = {e.alpha, e.velocity[0], e.velocity[1], e.velocity[2], e.centre[0], e.centre[1], e.centre[2],
                               e.omega[0], e.omega[1], e.omega[2]};
    for (int i = 0; i < 10; i++)
        setMixedArg(thermostatApplyKernel, 4+i, values[i]);
    thermostatApplyKernel->execute(cc.getNumAtoms());
}

double CommonIntegrateSymPRKStepKernel::computeKineticEnergy(ContextImpl& context, const SymPRKIntegrator& integrator) {
    return cc.getIntegrationUtilities().computeKineticEnergy(0.0);
}

long long CommonIntegrateSymPRKStepKernel::getBlowUpStep(ContextImpl& context) {
    if (blowUpStep == 0 && badStep.isInitialized()) {
        ContextSelector selector(cc);
        int value;
        badStep.download(&value);
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
    }
}
