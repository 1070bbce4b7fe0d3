/* openmm_symprk native plugin: the step plan (see SymPRKStepPlan.h). */

#include "openmm/internal/SymPRKStepPlan.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/OpenMMException.h"
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>

using namespace SymPRKPlugin;
using namespace std;

namespace {

SymPRKStepPlan::Operation operation(SymPRKStepPlan::OperationKind kind, int substep, double coefficient, int interval = 1,
        double collisionTime = 0.0) {
    SymPRKStepPlan::Operation op;
    op.kind = kind;
    op.substep = substep;
    op.coefficient = coefficient;
    op.forceGroups = 0;
    op.reuseForces = op.keepGroupCopy = op.driftFollows = op.checkVelocities = false;
    op.phase = 0;
    op.interval = interval;
    op.collisionTime = collisionTime;
    return op;
}

}

SymPRKStepPlan::SymPRKStepPlan() : integrationForceGroups(-1), constraints(false) {
}

SymPRKStepPlan::SymPRKStepPlan(const SymPRKIntegrator& integrator, bool hasConstraints) :
        integrationForceGroups(integrator.getIntegrationForceGroups()),
        constraints(hasConstraints) {
    const int n = integrator.getNumSubsteps();
    // A kick's groups: -1 stands for the integration force groups.  More than one mask among the kicks makes a
    // multiple-time-step method, whose kicks keep a copy of their groups' forces.
    set<int> masks;
    for (int s = 0; s < n; s++)
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick)
            masks.insert(integrator.getSubstepForceGroups(s) == -1 ? integrationForceGroups : integrator.getSubstepForceGroups(s));
    const bool multipleGroups = (masks.size() > 1);
    // The thermostat's events are sub-steps (where they sit is the sequence's): each runs in the step of every interval
    // its flags name.  With constraints, RATTLE's velocity projection follows the last kick or drift.
    const int interval = integrator.getThermostatInterval();
    const double tau = integrator.getCollisionTime();
    int lastKickOrDrift = -1, events = 0;
    for (int s = 0; s < n; s++) {
        if (integrator.getSubstepKind(s) != SymPRKIntegrator::Thermostat)
            lastKickOrDrift = s;
        else
            events++;
    }
    if (events > 0 && !integrator.hasThermostat())
        throw OpenMM::OpenMMException("SymPRKIntegrator: the sequence has thermostat events, but the integrator has no "
                                      "thermostat (setThermostat gives it one)");
    if (events == 0 && integrator.hasThermostat())
        throw OpenMM::OpenMMException("SymPRKIntegrator: the integrator has a thermostat, but its sequence has no thermostat "
                                      "event: add Thermostat sub-steps where the events go (ends: a half event flagged "
                                      "FirstOfInterval before the kicks and drifts and one flagged LastOfInterval after them)");
    for (int s = 0; s < n; s++) {
        const double c = integrator.getSubstepCoefficient(s);
        const int flags = integrator.getSubstepFlags(s);
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Thermostat) {
            if (constraints && (flags & SymPRKIntegrator::ProjectVelocitiesBefore) != 0)
                operations.push_back(operation(ProjectVelocities, s, 0.0));
            operations.push_back(operation(ThermostatEvent, s, c, interval, tau));
            operations.back().phase = ((flags & SymPRKIntegrator::FirstOfInterval) != 0 ? 0 :
                                       (flags & SymPRKIntegrator::LastOfInterval) != 0 ? interval-1 : (interval-1)/2);
        }
        else if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick) {
            Operation op = operation(Kick, s, c);
            op.forceGroups = (integrator.getSubstepForceGroups(s) == -1 ? integrationForceGroups : integrator.getSubstepForceGroups(s));
            op.reuseForces = (flags & SymPRKIntegrator::ForcesCached) != 0;
            op.keepGroupCopy = multipleGroups;
            operations.push_back(op);
        }
        else {
            if (constraints && (flags & SymPRKIntegrator::ProjectVelocitiesBefore) != 0)
                operations.push_back(operation(ProjectVelocities, s, 0.0));
            operations.push_back(operation(Drift, s, c));
        }
        if (s == lastKickOrDrift && constraints)
            operations.push_back(operation(ProjectVelocities, -1, 0.0));
    }
    // The blow-up check follows the last operation that changes the velocities in every step.
    int last = -1;
    for (size_t i = 0; i < operations.size(); i++) {
        const Operation& op = operations[i];
        if (op.kind == Kick || (op.kind == Drift && constraints))
            last = i;
        if (op.kind == Kick && i+1 < operations.size() && operations[i+1].kind == Drift)
            operations[i].driftFollows = true;
    }
    if (last >= 0)
        operations[last].checkVelocities = true;
}

bool SymPRKStepPlan::hasThermostatEvents() const {
    for (const Operation& op : operations)
        if (op.kind == ThermostatEvent)
            return true;
    return false;
}

double SymPRKStepPlan::Operation::decay(double stepSize) const {
    return std::exp(-coefficient*interval*stepSize/collisionTime);
}

vector<int> SymPRKStepPlan::getKickGroups() const {
    set<int> masks;
    for (const Operation& op : operations)
        if (op.kind == Kick)
            masks.insert(op.forceGroups);
    return vector<int>(masks.begin(), masks.end());
}

string SymPRKStepPlan::describe(int index) const {
    const Operation& op = operations.at(index);
    stringstream out;
    static const char* names[] = {"thermostat", "kick", "drift", "project"};
    out << names[op.kind];
    if (op.substep >= 0)
        out << " substep=" << op.substep;
    if (op.kind != ProjectVelocities)
        out << " c=" << op.coefficient;
    if (op.kind == Kick) {
        char mask[16];
        snprintf(mask, sizeof(mask), "0x%x", (unsigned int) op.forceGroups);
        out << " groups=" << mask << (op.reuseForces ? " reuse" : "") << (op.keepGroupCopy ? " copy" : "");
    }
    if (op.kind == ThermostatEvent)
        out << " phase=" << op.phase << "/" << op.interval;
    if (op.checkVelocities)
        out << " check";
    return out.str();
}
