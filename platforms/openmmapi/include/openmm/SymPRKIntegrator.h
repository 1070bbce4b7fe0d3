#ifndef OPENMM_SYMPRK_INTEGRATOR_H_
#define OPENMM_SYMPRK_INTEGRATOR_H_

/* openmm_symprk native plugin: an Integrator that runs any explicit kick/drift splitting.
 *
 * One step is a sequence of sub-steps, each a kind, a coefficient c, a force-group mask and flags:
 *   kick  (Kick):   v += c*dt*F/m               (F/m projected when exact momentum is on)
 *   drift (Drift):  x += c*dt*v                  (RATTLE when the System has constraints:
 *                   positions constrained with the pre-drift positions as reference, then
 *                   v += (x - x_unconstrained)/(c*dt))
 * and, with constraints, one velocity projection at the end of the step.  Massless particles are
 * never moved; virtual sites are placed before every force evaluation and at the end of the step.
 *
 * The flags are decided by whoever builds the sequence (openmm_symprk.methods.resolved, the one place
 * that states the rules), not here: ProjectVelocitiesBefore on a drift or a thermostat event projects the
 * velocities onto the constraints first (where the System has constraints); ForcesCached on a kick says that no drift came
 * since the previous kick of its force groups (cyclically, so a closing kick's forces serve the next
 * step's opening kick), so its forces are reused whenever they are still valid.  A step then costs
 * getForceEvaluationsPerStep() force evaluations in steady state.
 *
 * This is the same program openmm_symprk/integrators/program.py compiles into a CustomIntegrator,
 * without the per-degree-of-freedom interpreter.
 *
 * An optional thermostat (setThermostat) samples the canonical ensemble by stochastic velocity rescaling of
 * the peculiar velocities (Bussi, Donadio and Parrinello 2007).  Its events are sub-steps of the sequence like the
 * kicks and drifts (openmm_symprk.methods.resolved decides where they sit): a Thermostat sub-step of coefficient f is
 * an event with c = exp(-f*interval*dt/tau), run in one step of every `interval` steps, the one its flags name:
 * FirstOfInterval (0-based index i with i mod interval == 0), LastOfInterval (== interval-1) or neither (the centre
 * step, == (interval-1)/2).  The ends placement is a half event (f = 1/2, FirstOfInterval) before the kicks and drifts
 * and one (LastOfInterval) after them; the middle placement one whole event at the sequence's centre.  With
 * constraints, RATTLE's velocity projection follows the last kick or drift (before a closing event).
 * The centre-of-mass velocity is kept (and the rigid rotation about the centre of mass when keepRotation), so
 * total momentum (and angular momentum) is unchanged; one scalar factor leaves the velocity constraints
 * satisfied.  Where the peculiar kinetic energy is at most 1e-10 of the total (a System at rest or moving as a
 * rigid whole) an event changes nothing and is counted (getSkippedThermostatEvents).  Without a thermostat a step
 * is exactly the NVE one.
 *
 * Random numbers: Reference/CPU draw them on the host (std::mt19937_64, kept in this integrator's checkpoints);
 * the Common platforms (OpenCL, CUDA, HIP) draw them on the device from OpenMM's IntegrationUtilities generator
 * (kept in the Context's checkpoint), and run the whole event there: a step makes no host transfer
 * (getHostTransfers counts the integrator's own).
 */

#include "openmm/Integrator.h"
#include "openmm/Kernel.h"
#include "openmm/internal/SymPRKStepPlan.h"
#include "openmm/internal/SymPRKThermostat.h"
#include "openmm/internal/windowsExportSymPRK.h"
#include <string>
#include <vector>

/** The openmm_symprk plugin's C++ classes (Python: openmm_symprk.plugin.symprk_swig). */
namespace SymPRKPlugin {

class OPENMM_EXPORT_SYMPRK SymPRKIntegrator : public OpenMM::Integrator {
public:
    /** What a sub-step does (openmm_symprk.methods.resolved.SubstepKind has the same numbers). */
    enum SubstepKind {
        Kick = 0,
        Drift = 1,
        /** A thermostat event over the fraction `coefficient` of interval*dt (needs setThermostat; flags: which step). */
        Thermostat = 2
    };
    /** Bits of a sub-step's flags (openmm_symprk.methods.resolved.SubstepFlag has the same numbers). */
    enum SubstepFlag {
        /**
         * A drift or a thermostat event: project the velocities onto the constraints first (only where the System
         * has constraints).  An event that follows a kick needs it: the kick leaves the constraint forces' share in
         * the velocities, a kinetic energy along the constraints that the event would otherwise rescale.
         */
        ProjectVelocitiesBefore = 1,
        /** A kick: no drift since the previous kick of its force groups; its forces are reused when still valid. */
        ForcesCached = 2,
        /** A thermostat event: it runs in the first step of every thermostat interval. */
        FirstOfInterval = 4,
        /** A thermostat event: it runs in the last step of every thermostat interval (neither bit: the centre step). */
        LastOfInterval = 8
    };
    /**
     * Create an integrator running velocity Verlet (kick 1/2, drift 1, kick 1/2; the first kick on cached forces).
     *
     * @param stepSize  the step size (ps)
     */
    explicit SymPRKIntegrator(double stepSize);
    /**
     * Create an integrator running a given sub-step sequence (see setSubsteps()).
     */
    SymPRKIntegrator(double stepSize, const std::vector<int>& kinds, const std::vector<double>& coefficients,
                     const std::vector<int>& groups, const std::vector<int>& flags);
    /**
     * Set the sub-step sequence, run as given: kinds[i] is a SubstepKind, coefficients[i] the fraction of the
     * step size (finite, non-zero; a Thermostat sub-step's fraction of interval*dt/tau, > 0), groups[i] a kick's
     * force groups as a bit mask (as in Context::getState), or -1 for the integrator's integration force groups
     * (drifts and thermostat events: -1), flags[i] a combination of SubstepFlag bits (ProjectVelocitiesBefore on
     * drifts and thermostat events only, ForcesCached on kicks only).  Kicks of different groups make a
     * multiple-time-step method; the forces of every group are kept until the positions change.  Cannot be
     * called once the integrator is bound to a Context.
     */
    void setSubsteps(const std::vector<int>& kinds, const std::vector<double>& coefficients, const std::vector<int>& groups,
                     const std::vector<int>& flags);
    /** The force-group mask of sub-step index (-1: the integration force groups; drifts: -1). */
    int getSubstepForceGroups(int index) const;
    int getNumSubsteps() const {
        return kinds.size();
    }
    int getSubstepKind(int index) const;
    double getSubstepCoefficient(int index) const;
    /** The SubstepFlag bits of sub-step index. */
    int getSubstepFlags(int index) const;
    /** Force evaluations per step in a long run, all groups counted: the kicks without ForcesCached. */
    int getForceEvaluationsPerStep() const;
    /**
     * Project the forces of every kick onto zero net force and zero net torque about the centre of mass
     * (mass weighted, massless particles excluded), so that linear and angular momentum are conserved to
     * round-off even where forces are summed in single precision.  Only meaningful for isolated systems.
     */
    bool getExactMomentum() const {
        return exactMomentum;
    }
    void setExactMomentum(bool exact);
    /** A free-form name (the catalogue method), kept in XML. */
    const std::string& getMethodName() const {
        return methodName;
    }
    void setMethodName(const std::string& name) {
        methodName = name;
    }
    /** Steps taken since the integrator was bound to its Context (kept in checkpoints). */
    long long getStepsTaken() const {
        return stepsTaken;
    }
    /**
     * The first step (1-based, counted like getStepsTaken()) at whose end some velocity was NaN, infinite
     * or faster than getMaxSpeed(); 0 if none (or since clearBlowUp()).  Checked (on the device on OpenCL/CUDA)
     * right after the last operation of every step that changes the velocities, a kick or a drift with constraints
     * (SymPRKStepPlan says which).
     */
    long long getBlowUpStep() const;
    /** Forget a recorded blow-up (the Python layer does this when it reports one). */
    void clearBlowUp();
    /** Speed (nm/ps) above which a velocity counts as a blow-up; 0 (the default): only NaN and infinity. */
    double getMaxSpeed() const {
        return maxSpeed;
    }
    /** Set the blow-up speed (nm/ps, >= 0).  Cannot be called once the integrator is bound to a Context. */
    void setMaxSpeed(double speed);
    /**
     * Declare the System this integrator was set up for: initialize() then refuses a Context whose System
     * has another number of particles, or constraints where none were expected (or the reverse), with a
     * message saying so.  numParticles < 0 (the default) disables the check.
     */
    void setExpectedSystem(int numParticles, bool constraints);
    int getExpectedNumParticles() const {
        return expectedParticles;
    }
    bool getExpectedConstraints() const {
        return expectedConstraints;
    }
    /**
     * Add the stochastic velocity-rescaling thermostat: target temperature (K, > 0), collision time tau (ps,
     * > 0), an event every `interval` steps (1 to 2^31-1; half events around each block of interval steps, or the
     * Thermostat sub-steps in its middle step), the
     * degrees of freedom it samples (>= 1: 3 per particle with mass, less constraints, less 3 for the kept
     * centre-of-mass velocity, less 3 more when the rotation is kept) and whether the rigid rotation about the
     * centre of mass is kept (only right for an isolated System).  Cannot be called once the integrator is
     * bound to a Context.
     */
    void setThermostat(double temperature, double collisionTime, long long interval, int dof, bool keepRotation);
    bool hasThermostat() const {
        return thermostat;
    }
    /** The target temperature (K); 0 without a thermostat. */
    double getThermostatTemperature() const {
        return thermostatTemperature;
    }
    /** Change the target temperature (K, > 0) of the thermostat, also while bound to a Context (the next event uses it). */
    void setThermostatTemperature(double temperature);
    /** The collision time tau (ps); 0 without a thermostat. */
    double getCollisionTime() const {
        return collisionTime;
    }
    int getThermostatInterval() const {
        return thermostatInterval;
    }
    int getThermostatDof() const {
        return thermostatDof;
    }
    bool getThermostatKeepsRotation() const {
        return keepRotation;
    }
    /**
     * The seed of the thermostat's random numbers (std::mt19937_64 on the host), used when a Context is created:
     * 0 (the default) takes a new seed from std::random_device each time, as OpenMM's integrators do.
     */
    int getRandomNumberSeed() const {
        return randomSeed;
    }
    void setRandomNumberSeed(int seed) {
        randomSeed = seed;
    }
    /**
     * The heat-bath energy (kJ/mol): minus the kinetic energy the thermostat has added since the integrator was
     * bound (kept in checkpoints), so that total energy plus heat-bath energy is the conserved effective
     * energy.  0 when not bound or without a thermostat.
     */
    double getHeatBathEnergy() const;
    /**
     * The total kinetic energy (kJ/mol) just after the last thermostat event (the event's peculiar kinetic energy
     * K' plus the kept centre-of-mass and rotation part): the temperature the thermostat samples.  With the middle
     * placement the on-step velocities of a State are not Maxwell-Boltzmann, these are.  0 before the first event
     * (and when not bound or without a thermostat).
     */
    double getThermostatKineticEnergy() const;
    /**
     * The peculiar kinetic energy (kJ/mol) just after the last thermostat event: K' of the event (the motion it may
     * rescale, without the kept centre-of-mass motion and rotation), whose 2 K' / (dof k_B) is the thermostat's
     * temperature.  0 before the first event.
     */
    double getThermostatPeculiarKineticEnergy() const;
    /**
     * Thermostat events that changed nothing because the peculiar kinetic energy was at most 1e-10 of the total
     * (a System at rest, or moving only as a rigid whole: velocity rescaling has nothing to scale), since bound.
     */
    long long getSkippedThermostatEvents() const;
    /** Whether the last thermostat event changed nothing for want of peculiar kinetic energy (false before the first). */
    bool getLastThermostatEventSkipped() const;
    /**
     * Host-device transfers (downloads and uploads) this integrator's kernel has made since bound: 0 on
     * Reference/CPU; on the Common platforms a step makes none (reading the blow-up record, the heat-bath energy
     * or the kinetic energy above, checkpoints and States make one each).  OpenMM's own force computation is not
     * counted.
     */
    long long getHostTransfers() const;
    /**
     * Device launches (kernels and device-side copies) this integrator's kernel has enqueued itself since bound: 0 on
     * Reference/CPU.  OpenMM's constraint, virtual-site, random-number and force kernels are not counted (an intercept
     * of the OpenCL or CUDA API, tools/count_launches.py, counts everything a step launches).
     */
    long long getKernelLaunches() const;
    /**
     * How the Common platforms' kernel (OpenCL, CUDA, HIP) groups the step plan's operations into device launches;
     * the trajectory is the same (bit for bit without constraints; with them within the constraint tolerance, as a
     * velocity projection whose velocities the next constrained drift projects again may be left out), the launches
     * fewer.  Reference/CPU always run the plan one operation at a time.
     */
    enum KernelFusion {
        /** One or a few launches per operation, every step ending at the step point: the plain reading of the plan. */
        FuseNone = 0,
        /** Consecutive per-atom operations in one launch; within one step() call, the last kick of a step and the first
         *  of the next as one launch where nothing reads the state between; a thermostat event as a reduction launch
         *  whose apply joins the next launch. */
        FuseSegments = 1,
        /** As FuseSegments, and a thermostat event with the per-atom operations around it in one launch of one block
         *  of threads, up to getKernelFusionBlockAtoms() atoms (the default). */
        FuseAll = 2
    };
    /** For tests and measurements: set the KernelFusion (FuseAll by default; kept across Contexts, not saved in XML). */
    void setKernelFusion(int mode);
    int getKernelFusion() const {
        return kernelFusion;
    }
    /** The largest System (atoms) whose thermostat events FuseAll runs in one block of threads. */
    static int getKernelFusionBlockAtoms();
    /**
     * For tests of the thermostat's random numbers: the noise of `count` events (r1 ~ N(0,1), chi2 ~ chi^2(dof-1)
     * with this integrator's degrees of freedom; 2*count values, r1 and chi2 of each event in turn), drawn by the bound
     * Context's kernel exactly as its events draw it and from the same stream, which it advances (Reference/CPU: the
     * host generator of the checkpoints; OpenCL/CUDA: the platform's device generator, one block of numbers per event).
     * Throws without a thermostat or when not bound.
     */
    std::vector<double> sampleThermostatNoise(int count);
    /**
     * (alpha, K'): the rescaling factor and the new peculiar kinetic energy for a peculiar kinetic energy
     * `kinetic` (kJ/mol), a target dof*kT/2, c = exp(-t/tau), a standard normal r1 and a chi-squared variable
     * chi2 of dof-1 degrees of freedom: the expression every kernel uses (for tests against other backends).
     */
    static std::vector<double> computeRescalingFactor(double kinetic, double target, int dof, double c, double r1, double chi2);
    /**
     * A hash of the sub-step program, the exact-momentum option and the thermostat's settings (not its
     * temperature, which may change during a run; nothing of it without a thermostat).  Checkpoints carry it, and
     * loadCheckpoint() refuses a checkpoint written by a SymPRKIntegrator running another program.
     */
    long long getProgramSignature() const;
    /**
     * For every registered platform without a SymPRKIntegrator kernel, register a stand-in whose kernel
     * creation throws an OpenMMException naming the platform, the platforms that have a kernel, and what to
     * do instead (called by the Python loader after it has loaded the kernel libraries).
     */
    static void registerMissingKernelFactories();
    void step(int steps);
    /**
     * For tests: the step plan of the bound Context (SymPRKStepPlan, decided once for every platform), one line
     * per operation in the order a step runs them (SymPRKStepPlan::describe gives the grammar).  Throws when the
     * integrator is not bound to a Context.
     */
    std::vector<std::string> getStepPlan() const;
    /**
     * For tests: start (true; what was recorded is cleared) or stop (false) recording what the kernel executes.
     * Kept across Contexts; off by default (recording costs a little per operation).
     */
    void setExecutionTraceEnabled(bool record);
    /**
     * For tests: what the kernel executed while recording, three numbers per operation run: the step (1-based, as
     * getStepsTaken() counts it), the operation's index in getStepPlan(), and the force-group mask whose forces it
     * evaluated (0 when it evaluated none: a kick reusing cached forces, or any other operation).  Empty when not
     * bound.
     */
    std::vector<int> getExecutionTrace() const;

protected:
    void initialize(OpenMM::ContextImpl& context);
    void cleanup();
    std::vector<std::string> getKernelNames();
    void stateChanged(OpenMM::State::DataType changed);
    double computeKineticEnergy();
    bool kineticEnergyRequiresForce() const {
        return false;
    }
    void createCheckpoint(std::ostream& stream) const;
    void loadCheckpoint(std::istream& stream);
    /** A State's integrator parameters: the heat-bath energy (with a thermostat). */
    void serializeParameters(OpenMM::SerializationNode& node) const;
    void deserializeParameters(const OpenMM::SerializationNode& node);

private:
    /** The program signature (getProgramSignature) with the exact-momentum option given. */
    long long programSignature(bool exact) const;
    /** Why loadCheckpoint refuses a SymPRKIntegrator checkpoint of another program: what differs (read on from
     * `stream`, just after the method name), and what to do. */
    std::string checkpointMismatch(std::istream& stream, long long saved, const std::string& savedMethod) const;
    /** The thermostat's run-time state in the bound Context's kernel (all zero when not bound or without a thermostat). */
    SymPRKThermostat::RunState thermostatRunState() const;
    /** index, after checking that it names a sub-step. */
    int substep(int index) const;
    /** The plan for the bound Context, made again if the integration force groups have changed. */
    const SymPRKStepPlan& currentPlan();
    std::vector<int> kinds, groups, flags;
    std::vector<double> coefficients;
    bool exactMomentum, forcesAreValid;
    std::string methodName;
    long long stepsTaken;
    mutable long long blowUpStep;
    double maxSpeed;
    int expectedParticles;
    bool expectedConstraints;
    bool thermostat, keepRotation;
    double thermostatTemperature, collisionTime;
    int thermostatInterval, thermostatDof, randomSeed;
    bool traceEnabled;
    int kernelFusion;
    SymPRKStepPlan plan;
    OpenMM::Kernel kernel;
};

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_INTEGRATOR_H_*/
