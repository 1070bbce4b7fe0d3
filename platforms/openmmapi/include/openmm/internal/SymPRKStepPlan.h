#ifndef OPENMM_SYMPRK_STEP_PLAN_H_
#define OPENMM_SYMPRK_STEP_PLAN_H_

/* openmm_symprk native plugin: the operations of one step, decided once for every platform.
 *
 * SymPRKIntegrator builds the plan when it is bound to a Context, from its sub-steps and their flags, its
 * integration force groups, its thermostat settings and whether the System has constraints.  Each kernel
 * (Reference/CPU, Common) runs the operations in order and decides nothing about the step itself: which
 * force groups a kick uses, whether it may reuse cached forces and keep a copy of them, where velocities are
 * projected, where thermostat events go and in which steps of an interval they run, and after which
 * operation the velocities are checked for a blow-up are all stated here.  What stays with a kernel is the
 * run-time state (whether the cached forces still belong to the current positions) and how it does an
 * operation (Reference shares one pass over the atoms between a kick and the drift after it).
 *
 * The flags come from the sequence (openmm_symprk.methods.resolved states the rules); the plan does not
 * derive them again, it turns them into operations.
 */

#include "openmm/internal/windowsExportSymPRK.h"
#include <string>
#include <vector>

namespace SymPRKPlugin {

class SymPRKIntegrator;

class OPENMM_EXPORT_SYMPRK SymPRKStepPlan {
public:
    enum OperationKind {
        /** Stochastic velocity rescaling with decay c = exp(-coefficient * interval * dt / tau). */
        ThermostatEvent = 0,
        /** v += coefficient*dt*F/m with the forces of forceGroups (projected with exact momentum). */
        Kick = 1,
        /** x += coefficient*dt*v (RATTLE where the System has constraints); forces become invalid. */
        Drift = 2,
        /** Project the velocities onto the constraints (only planned where the System has constraints). */
        ProjectVelocities = 3
    };
    struct Operation {
        OperationKind kind;
        /** The sub-step it comes from; -1 for RATTLE's velocity projection after the last kick or drift. */
        int substep;
        /** Kick, Drift: the fraction of the step size.  ThermostatEvent: the fraction f of interval*dt/tau. */
        double coefficient;
        /** Kick: the force groups' bit mask, with a sub-step's -1 resolved to the integration force groups (all 32
         *  groups, 0xffffffff, read as an int is -1 too); else 0. */
        int forceGroups;
        /** Kick: the forces are reused while they still belong to the positions and to these groups. */
        bool reuseForces;
        /** Kick: the kicks use more than one group mask (multiple time stepping), so this one keeps a copy of
         *  its groups' forces, valid until the next drift. */
        bool keepGroupCopy;
        /** Kick: the next operation is a drift, which may share this kick's pass over the atoms. */
        bool driftFollows;
        /** The velocities are checked for a blow-up right after this operation: the last operation of every step
         *  that changes them (a kick, or a drift with constraints); end projections and events excepted. */
        bool checkVelocities;
        /** ThermostatEvent: it runs in the steps whose 0-based position within the thermostat's interval (of
         *  interval steps, collision time tau in ps) is phase. */
        int phase, interval;
        double collisionTime;
        /** ThermostatEvent: whether it runs in step stepIndex (1-based, counted like getStepsTaken()). */
        bool runsInStep(long long stepIndex) const {
            return (stepIndex-1) % interval == phase;
        }
        /** ThermostatEvent: its decay c = exp(-coefficient * interval * stepSize / tau). */
        double decay(double stepSize) const;
    };
    SymPRKStepPlan();
    /** The plan of integrator's step for a System with or without constraints. */
    SymPRKStepPlan(const SymPRKIntegrator& integrator, bool hasConstraints);
    const std::vector<Operation>& getOperations() const {
        return operations;
    }
    /** The integration force groups the plan resolved -1 to (SymPRKIntegrator re-plans when they change). */
    int getIntegrationForceGroups() const {
        return integrationForceGroups;
    }
    bool hasConstraints() const {
        return constraints;
    }
    /** Whether some operation is a thermostat event. */
    bool hasThermostatEvents() const;
    /** The distinct force-group masks the kicks use (ascending). */
    std::vector<int> getKickGroups() const;
    /**
     * One line for operation index: its kind and its facts as key=value tokens, e.g.
     * "kick substep=1 c=0.5 groups=0xffffffff reuse", "drift substep=2 c=1", "project" (RATTLE's, after the last kick
     * or drift), "thermostat substep=0 c=0.5 phase=0/3" (an ends event) or "thermostat substep=2 c=1 phase=1/3"; a trailing
     * " check" marks the blow-up check.  (Tests and messages.)
     */
    std::string describe(int index) const;
private:
    std::vector<Operation> operations;
    int integrationForceGroups;
    bool constraints;
};

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_STEP_PLAN_H_*/
