/* openmm_symprk native plugin: the SymPRKIntegrator API class. */

#include "openmm/SymPRKIntegrator.h"
#include "openmm/SymPRKKernels.h"
#include "openmm/Context.h"
#include "openmm/OpenMMException.h"
#include "openmm/KernelFactory.h"
#include "openmm/internal/ContextImpl.h"
#include "openmm/serialization/SerializationNode.h"
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <set>
#include <sstream>
#include <string>

using namespace SymPRKPlugin;
using namespace OpenMM;
using namespace std;

// Checkpoint format: "SymPRK" + version.  Version 5: the thermostat block (after the method name) holds the heat-bath
// energy, the generator's state, then the total and peculiar kinetic energies after the last event, the skipped
// events and whether the last one was skipped.  Version 4 (the same block without the last four) still loads, with
// those at 0; the older
// versions 1-3 are refused (3: sub-steps with flags, no thermostat block; 1-2: signatures computed without the flags).
static const int64_t CHECKPOINT_MAGIC_BASE = 0x53796d50524b0000LL;
static const int64_t CHECKPOINT_MAGIC = CHECKPOINT_MAGIC_BASE + 5;
static const int64_t CHECKPOINT_MAGIC_V4 = CHECKPOINT_MAGIC_BASE + 4;

SymPRKIntegrator::SymPRKIntegrator(double stepSize) : exactMomentum(false), forcesAreValid(false),
        methodName("verlet"), stepsTaken(0), blowUpStep(0), maxSpeed(0.0), expectedParticles(-1),
        expectedConstraints(false),
        thermostat(false), keepRotation(false), thermostatTemperature(0.0), collisionTime(0.0), thermostatInterval(1),
        thermostatDof(0), randomSeed(0), traceEnabled(false), kernelFusion(FuseAll) {
    setStepSize(stepSize);
    setConstraintTolerance(1e-5);
    setSubsteps({Kick, Drift, Kick}, {0.5, 1.0, 0.5}, {-1, -1, -1}, {ForcesCached, 0, 0});
}

SymPRKIntegrator::SymPRKIntegrator(double stepSize, const vector<int>& kinds, const vector<double>& coefficients,
        const vector<int>& groups, const vector<int>& flags) :
        exactMomentum(false), forcesAreValid(false), methodName(""), stepsTaken(0), blowUpStep(0), maxSpeed(0.0),
        expectedParticles(-1), expectedConstraints(false),
        thermostat(false), keepRotation(false), thermostatTemperature(0.0), collisionTime(0.0), thermostatInterval(1),
        thermostatDof(0), randomSeed(0), traceEnabled(false), kernelFusion(FuseAll) {
    setStepSize(stepSize);
    setConstraintTolerance(1e-5);
    setSubsteps(kinds, coefficients, groups, flags);
}

void SymPRKIntegrator::setSubsteps(const vector<int>& newKinds, const vector<double>& newCoefficients, const vector<int>& newGroups,
        const vector<int>& newFlags) {
    if (owner != NULL)
        throw OpenMMException("SymPRKIntegrator: the sub-steps cannot be changed once the integrator is bound to a Context");
    const size_t n = newKinds.size();
    if (newCoefficients.size() != n || newGroups.size() != n || newFlags.size() != n)
        throw OpenMMException("SymPRKIntegrator: kinds, coefficients, force groups and flags must have the same length");
    if (n == 0)
        throw OpenMMException("SymPRKIntegrator: a step needs at least one sub-step");
    for (size_t i = 0; i < n; i++) {
        stringstream msg;
        msg << "SymPRKIntegrator: sub-step " << i;
        if (newKinds[i] != Kick && newKinds[i] != Drift && newKinds[i] != Thermostat)
            msg << " has kind " << newKinds[i] << "; expected " << Kick << " (kick), " << Drift << " (drift) or "
                << Thermostat << " (thermostat event)";
        else if (newKinds[i] == Thermostat && !(newCoefficients[i] > 0 && std::isfinite(newCoefficients[i])))
            msg << " is a thermostat event with the coefficient " << newCoefficients[i] << "; expected a finite fraction > 0 "
                   "of the thermostat's interval (1: one whole event)";
        else if (newKinds[i] == Thermostat && (newGroups[i] != -1 || (newFlags[i] & ~(ProjectVelocitiesBefore | FirstOfInterval | LastOfInterval)) != 0
                 || (newFlags[i] & (FirstOfInterval | LastOfInterval)) == (FirstOfInterval | LastOfInterval)))
            msg << " is a thermostat event with force-group mask " << newGroups[i] << " and flags " << newFlags[i]
                << "; a thermostat event takes -1 and flags of " << ProjectVelocitiesBefore << " (project velocities first) and "
                << "one of " << FirstOfInterval << " (first step of the interval) or " << LastOfInterval << " (last step; "
                << "neither: the centre step)";
        else if (newKinds[i] != Thermostat && (newFlags[i] & (FirstOfInterval | LastOfInterval)) != 0)
            msg << " is a " << (newKinds[i] == Kick ? "kick" : "drift") << " flagged " << newFlags[i] << "; FirstOfInterval and "
                   "LastOfInterval name the step of a thermostat event";
        else if (!std::isfinite(newCoefficients[i]) || newCoefficients[i] == 0.0)
            msg << " has the coefficient " << newCoefficients[i] << "; expected a finite non-zero number (leave a zero sub-step out)";
        else if (newKinds[i] == Kick && (newGroups[i] == 0 || newGroups[i] < -1))
            msg << " has force-group mask " << newGroups[i] << "; expected a non-zero bit mask or -1";
        else if (newKinds[i] == Drift && newGroups[i] != -1)
            msg << " is a drift with force-group mask " << newGroups[i] << "; a drift takes -1";
        else if ((newFlags[i] & ~(ProjectVelocitiesBefore | ForcesCached | FirstOfInterval | LastOfInterval)) != 0)
            msg << " has flags " << newFlags[i] << "; expected a combination of " << ProjectVelocitiesBefore
                << " (project velocities before a drift or a thermostat event) and " << ForcesCached << " (a kick on cached forces)";
        else if (newKinds[i] == Kick && (newFlags[i] & ProjectVelocitiesBefore) != 0)
            msg << " is a kick flagged ProjectVelocitiesBefore, which only a drift or a thermostat event takes";
        else if (newKinds[i] == Drift && (newFlags[i] & ForcesCached) != 0)
            msg << " is a drift flagged ForcesCached, which only a kick takes";
        else
            continue;
        throw OpenMMException(msg.str());
    }
    kinds = newKinds;
    coefficients = newCoefficients;
    groups = newGroups;
    flags = newFlags;
}

int SymPRKIntegrator::substep(int index) const {
    if (index < 0 || index >= (int) kinds.size()) {
        stringstream msg;
        msg << "SymPRKIntegrator: sub-step index " << index << " is out of range (the sequence has " << kinds.size()
            << " sub-steps: 0 to " << kinds.size()-1 << ")";
        throw OpenMMException(msg.str());
    }
    return index;
}

int SymPRKIntegrator::getSubstepForceGroups(int index) const {
    return groups[substep(index)];
}

int SymPRKIntegrator::getSubstepKind(int index) const {
    return kinds[substep(index)];
}

double SymPRKIntegrator::getSubstepCoefficient(int index) const {
    return coefficients[substep(index)];
}

int SymPRKIntegrator::getSubstepFlags(int index) const {
    return flags[substep(index)];
}

int SymPRKIntegrator::getForceEvaluationsPerStep() const {
    int count = 0;
    for (size_t i = 0; i < kinds.size(); i++)
        if (kinds[i] == Kick && (flags[i] & ForcesCached) == 0)
            count++;
    return count;
}

void SymPRKIntegrator::setExactMomentum(bool exact) {
    if (owner != NULL)
        throw OpenMMException("SymPRKIntegrator: exact momentum cannot be changed once the integrator is bound to a Context");
    exactMomentum = exact;
}

long long SymPRKIntegrator::getBlowUpStep() const {
    if (blowUpStep == 0 && context != NULL)
        blowUpStep = const_cast<Kernel&>(kernel).getAs<IntegrateSymPRKStepKernel>().getBlowUpStep(*context);
    return blowUpStep;
}

void SymPRKIntegrator::clearBlowUp() {
    blowUpStep = 0;
    if (context != NULL)
        kernel.getAs<IntegrateSymPRKStepKernel>().setBlowUpStep(*context, 0);
}

void SymPRKIntegrator::setMaxSpeed(double speed) {
    if (owner != NULL)
        throw OpenMMException("SymPRKIntegrator: the blow-up speed cannot be changed once the integrator is bound to a Context");
    if (!(speed >= 0.0) || !std::isfinite(speed))
        throw OpenMMException("SymPRKIntegrator: the blow-up speed must be a finite number >= 0 (0: only NaN and infinity)");
    maxSpeed = speed;
}

void SymPRKIntegrator::setExpectedSystem(int numParticles, bool constraints) {
    if (owner != NULL)
        throw OpenMMException("SymPRKIntegrator: the expected System cannot be changed once the integrator is bound to a Context");
    expectedParticles = numParticles;
    expectedConstraints = constraints;
}

void SymPRKIntegrator::setThermostat(double temperature, double tau, long long interval, int dof, bool keep) {
    if (owner != NULL)
        throw OpenMMException("SymPRKIntegrator: the thermostat cannot be changed once the integrator is bound to a Context");
    stringstream msg;
    msg << "SymPRKIntegrator: ";
    if (!(temperature > 0) || !std::isfinite(temperature))
        msg << "the thermostat temperature is " << temperature << " K; expected a finite temperature > 0 K";
    else if (!(tau > 0) || !std::isfinite(tau))
        msg << "the collision time is " << tau << " ps; expected a finite time > 0 ps";
    else if (interval < 1 || interval > INT32_MAX)
        msg << "the thermostat interval (thermostat_interval) is " << interval << " steps; expected a whole number from 1 to "
            << INT32_MAX << " (2^31-1)";
    else if (dof < 1)
        msg << "the thermostat has " << dof << " degrees of freedom; a System without degrees of freedom to "
               "thermostat cannot be thermostatted (expected >= 1)";
    else {
        thermostat = true;
        thermostatTemperature = temperature;
        collisionTime = tau;
        thermostatInterval = (int) interval;
        thermostatDof = dof;
        keepRotation = keep;
        return;
    }
    throw OpenMMException(msg.str());
}

void SymPRKIntegrator::setThermostatTemperature(double temperature) {
    if (!thermostat)
        throw OpenMMException("SymPRKIntegrator: there is no thermostat whose temperature could be set (setThermostat adds one)");
    if (!(temperature > 0) || !std::isfinite(temperature)) {
        stringstream msg;
        msg << "SymPRKIntegrator: the thermostat temperature is " << temperature << " K; expected a finite temperature > 0 K";
        throw OpenMMException(msg.str());
    }
    thermostatTemperature = temperature;
}

SymPRKThermostat::RunState SymPRKIntegrator::thermostatRunState() const {
    if (!thermostat || context == NULL)
        return SymPRKThermostat::RunState();
    return const_cast<Kernel&>(kernel).getAs<IntegrateSymPRKStepKernel>().getThermostatRunState();
}

double SymPRKIntegrator::getHeatBathEnergy() const {
    return thermostatRunState().heatBathEnergy;
}

double SymPRKIntegrator::getThermostatKineticEnergy() const {
    return thermostatRunState().kineticEnergy;
}

double SymPRKIntegrator::getThermostatPeculiarKineticEnergy() const {
    return thermostatRunState().peculiarKineticEnergy;
}

long long SymPRKIntegrator::getSkippedThermostatEvents() const {
    return thermostatRunState().skippedEvents;
}

bool SymPRKIntegrator::getLastThermostatEventSkipped() const {
    return thermostatRunState().lastSkipped;
}

long long SymPRKIntegrator::getHostTransfers() const {
    if (context == NULL)
        return 0;
    return const_cast<Kernel&>(kernel).getAs<IntegrateSymPRKStepKernel>().getHostTransfers();
}

long long SymPRKIntegrator::getKernelLaunches() const {
    if (context == NULL)
        return 0;
    return const_cast<Kernel&>(kernel).getAs<IntegrateSymPRKStepKernel>().getKernelLaunches();
}

void SymPRKIntegrator::setKernelFusion(int mode) {
    if (mode != FuseNone && mode != FuseSegments && mode != FuseAll) {
        stringstream msg;
        msg << "SymPRKIntegrator: kernel fusion " << mode << " is not one of " << FuseNone << " (none), " << FuseSegments
            << " (segments) and " << FuseAll << " (all)";
        throw OpenMMException(msg.str());
    }
    kernelFusion = mode;
    if (context != NULL)
        kernel.getAs<IntegrateSymPRKStepKernel>().setKernelFusion(mode);
}

int SymPRKIntegrator::getKernelFusionBlockAtoms() {
    return 4096;
}

vector<double> SymPRKIntegrator::sampleThermostatNoise(int count) {
    if (!thermostat)
        throw OpenMMException("SymPRKIntegrator::sampleThermostatNoise: the integrator has no thermostat (setThermostat)");
    if (context == NULL)
        throw OpenMMException("SymPRKIntegrator::sampleThermostatNoise: the noise is drawn by the bound Context's kernel; "
                              "create the Context first");
    if (count < 0)
        throw OpenMMException("SymPRKIntegrator::sampleThermostatNoise: count must be >= 0");
    return kernel.getAs<IntegrateSymPRKStepKernel>().sampleThermostatNoise(*context, thermostatDof, count);
}

vector<double> SymPRKIntegrator::computeRescalingFactor(double kinetic, double target, int dof, double c, double r1, double chi2) {
    if (dof < 1)
        throw OpenMMException("SymPRKIntegrator::computeRescalingFactor: dof must be >= 1");
    double newKinetic;
    double alpha = SymPRKThermostat::rescalingFactor(kinetic, target, dof, c, r1, chi2, newKinetic);
    return {alpha, newKinetic};
}

long long SymPRKIntegrator::getProgramSignature() const {
    return programSignature(exactMomentum);
}

long long SymPRKIntegrator::programSignature(bool exact) const {
    // FNV-1a over the sub-step kinds, coefficients' bits, force groups and flags, and the exact-momentum option.
    uint64_t hash = 1469598103934665603ULL;
    auto mix = [&] (const void* data, size_t size) {
        const unsigned char* bytes = (const unsigned char*) data;
        for (size_t i = 0; i < size; i++) {
            hash ^= bytes[i];
            hash *= 1099511628211ULL;
        }
    };
    // The ends placement's two events (a half event flagged FirstOfInterval first, one flagged LastOfInterval last) are
    // left out: with a thermostat they are what an ends placement is, and so a checkpoint written before they were
    // sub-steps (format 4, the ends placement implied) keeps its signature.  Any other event is hashed.
    const size_t last = kinds.size()-1;
    for (size_t i = 0; i < kinds.size(); i++) {
        const bool endsEvent = (kinds[i] == Thermostat && coefficients[i] == 0.5 &&
                                ((i == 0 && flags[i] == FirstOfInterval) || (i == last && flags[i] == LastOfInterval)));
        if (endsEvent)
            continue;
        int32_t kind = kinds[i], group = groups[i], flag = flags[i];
        mix(&kind, sizeof(kind));
        mix(&coefficients[i], sizeof(double));
        mix(&group, sizeof(group));
        mix(&flag, sizeof(flag));
    }
    int32_t exactFlag = exact ? 1 : 0;
    mix(&exactFlag, sizeof(exactFlag));
    if (thermostat) {
        // the thermostat's settings but its temperature (nothing without one: the NVE signature is unchanged)
        int32_t tag = 0x54686572, interval = thermostatInterval, dof = thermostatDof, keep = keepRotation ? 1 : 0;
        mix(&tag, sizeof(tag));
        mix(&collisionTime, sizeof(double));
        mix(&interval, sizeof(interval));
        mix(&dof, sizeof(dof));
        mix(&keep, sizeof(keep));
    }
    return (long long) (hash & 0x7fffffffffffffffULL);
}

namespace {

/** Stands in for a platform without a SymPRKIntegrator kernel: creating the kernel explains and throws. */
class MissingSymPRKKernelFactory : public KernelFactory {
public:
    MissingSymPRKKernelFactory(const string& platform, const string& available) : platform(platform), available(available) {
    }
    KernelImpl* createKernelImpl(std::string name, const Platform& p, ContextImpl& context) const {
        throw OpenMMException("SymPRKIntegrator (openmm_symprk's native backend) has no kernel for the "+platform+
                " platform; this build has kernels for "+available+". Create the Context on one of those, or use "
                "openmm_symprk.SymplecticIntegrator(..., backend='custom'), whose CustomIntegrator program runs on "
                "every platform.");
    }
private:
    string platform, available;
};

}

void SymPRKIntegrator::registerMissingKernelFactories() {
    static set<string> registered;
    vector<string> names = {IntegrateSymPRKStepKernel::Name()};
    string available;
    for (int i = 0; i < Platform::getNumPlatforms(); i++) {
        Platform& platform = Platform::getPlatform(i);
        if (registered.count(platform.getName()) == 0 && platform.supportsKernels(names))
            available += (available.empty() ? "" : ", ")+platform.getName();
    }
    if (available.empty())
        available = "no platform";
    for (int i = 0; i < Platform::getNumPlatforms(); i++) {
        Platform& platform = Platform::getPlatform(i);
        if (!platform.supportsKernels(names)) {
            platform.registerKernelFactory(IntegrateSymPRKStepKernel::Name(), new MissingSymPRKKernelFactory(platform.getName(), available));
            registered.insert(platform.getName());
        }
    }
}

void SymPRKIntegrator::initialize(ContextImpl& contextRef) {
    if (owner != NULL && &contextRef.getOwner() != owner)
        throw OpenMMException("This Integrator is already bound to a context");
    const System& system = contextRef.getSystem();
    if (expectedParticles >= 0 && (system.getNumParticles() != expectedParticles ||
            (system.getNumConstraints() > 0) != expectedConstraints)) {
        stringstream msg;
        msg << "SymPRKIntegrator (" << methodName << ") was set up for a System of " << expectedParticles << " particles "
            << (expectedConstraints ? "with" : "without") << " constraints, but the Context's System has "
            << system.getNumParticles() << " particles " << (system.getNumConstraints() > 0 ? "with" : "without")
            << " constraints: create the integrator with system= the System you simulate";
        throw OpenMMException(msg.str());
    }
    plan = SymPRKStepPlan(*this, system.getNumConstraints() > 0);
    context = &contextRef;
    owner = &contextRef.getOwner();
    kernel = context->getPlatform().createKernel(IntegrateSymPRKStepKernel::Name(), contextRef);
    IntegrateSymPRKStepKernel& k = kernel.getAs<IntegrateSymPRKStepKernel>();
    k.initialize(contextRef.getSystem(), *this, plan);
    k.setBlowUpStep(contextRef, blowUpStep);
    k.initializeThermostat(randomSeed);
    k.getTrace().setEnabled(traceEnabled);
    k.setKernelFusion(kernelFusion);
    stepsTaken = 0;  // a new run (also after Context::reinitialize, as the CustomIntegrator backend counts it)
    forcesAreValid = false;
}

const SymPRKStepPlan& SymPRKIntegrator::currentPlan() {
    // The only setting of the plan that may change while bound: Integrator::setIntegrationForceGroups.
    if (plan.getIntegrationForceGroups() != getIntegrationForceGroups())
        plan = SymPRKStepPlan(*this, plan.hasConstraints());
    return plan;
}

vector<string> SymPRKIntegrator::getStepPlan() const {
    if (context == NULL)
        throw OpenMMException("SymPRKIntegrator::getStepPlan: the step plan is made when the integrator is bound to a Context; "
                              "create the Context first");
    vector<string> lines;
    for (int i = 0; i < (int) plan.getOperations().size(); i++)
        lines.push_back(plan.describe(i));
    return lines;
}

void SymPRKIntegrator::setExecutionTraceEnabled(bool record) {
    traceEnabled = record;
    if (context != NULL)
        kernel.getAs<IntegrateSymPRKStepKernel>().getTrace().setEnabled(record);
}

vector<int> SymPRKIntegrator::getExecutionTrace() const {
    if (context == NULL)
        return {};
    return const_cast<Kernel&>(kernel).getAs<IntegrateSymPRKStepKernel>().getTrace().getEntries();
}

void SymPRKIntegrator::cleanup() {
    kernel = Kernel();
}

vector<string> SymPRKIntegrator::getKernelNames() {
    return {IntegrateSymPRKStepKernel::Name()};
}

void SymPRKIntegrator::stateChanged(State::DataType changed) {
    forcesAreValid = false;
}

double SymPRKIntegrator::computeKineticEnergy() {
    // Context::getState(getEnergy) evaluates the energy just before this call; on the Common platforms that
    // clears the force buffers, on Reference/CPU the forces are restored (the kernel says which).
    IntegrateSymPRKStepKernel& k = kernel.getAs<IntegrateSymPRKStepKernel>();
    if (!k.energyEvaluationKeepsForces())
        forcesAreValid = false;
    return k.computeKineticEnergy(*context, *this);
}

void SymPRKIntegrator::step(int steps) {
    if (context == NULL)
        throw OpenMMException("This Integrator is not bound to a context!");
    IntegrateSymPRKStepKernel& k = kernel.getAs<IntegrateSymPRKStepKernel>();
    const SymPRKStepPlan& stepPlan = currentPlan();
    for (int i = 0; i < steps; ++i) {
        stepsTaken++;
        k.execute(*context, *this, stepPlan, forcesAreValid, stepsTaken, i+1 < steps);
    }
}

void SymPRKIntegrator::createCheckpoint(ostream& stream) const {
    int64_t values[5] = {CHECKPOINT_MAGIC, (int64_t) stepsTaken, (int64_t) getBlowUpStep(),
                         (int64_t) getProgramSignature(), (int64_t) methodName.size()};
    stream.write((const char*) values, sizeof(values));
    stream.write(methodName.data(), methodName.size());
    // the thermostat: a flag, then the heat-bath energy and the generator's state (length and text)
    int64_t hasBath = thermostat ? 1 : 0;
    stream.write((const char*) &hasBath, sizeof(hasBath));
    if (thermostat) {
        IntegrateSymPRKStepKernel& k = const_cast<Kernel&>(kernel).getAs<IntegrateSymPRKStepKernel>();
        const SymPRKThermostat::RunState run = k.getThermostatRunState();
        string state = k.getRandomState();
        int64_t size = state.size();
        stream.write((const char*) &run.heatBathEnergy, sizeof(double));
        stream.write((const char*) &size, sizeof(size));
        stream.write(state.data(), state.size());
        int64_t skipped[2] = {(int64_t) run.skippedEvents, run.lastSkipped ? 1 : 0};
        stream.write((const char*) &run.kineticEnergy, sizeof(double));
        stream.write((const char*) &run.peculiarKineticEnergy, sizeof(double));
        stream.write((const char*) skipped, sizeof(skipped));
    }
}

void SymPRKIntegrator::loadCheckpoint(istream& stream) {
    int64_t values[3];
    stream.read((char*) values, sizeof(values));
    const bool version4 = (stream && values[0] == CHECKPOINT_MAGIC_V4);
    if (stream && values[0] > CHECKPOINT_MAGIC_BASE && values[0] < CHECKPOINT_MAGIC_V4) {
        stringstream msg;
        msg << "SymPRKIntegrator: the checkpoint was written by an older openmm_symprk (checkpoint format "
            << (values[0]-CHECKPOINT_MAGIC_BASE) << "; this one reads formats 4 and " << (CHECKPOINT_MAGIC-CHECKPOINT_MAGIC_BASE)
            << ", which carries the thermostat's heat-bath energy and random state" << (values[0]-CHECKPOINT_MAGIC_BASE < 3 ?
               " and whose program signature covers the sub-step flags" : "") << "): it cannot be loaded. Load the "
               "positions and velocities of the saved run (a State or a PDB/XML file) instead";
        throw OpenMMException(msg.str());
    }
    if (!stream || (values[0] != CHECKPOINT_MAGIC && !version4)) {
        // A program of openmm_symprk's CustomIntegrator backend writes its globals here, its signature first (an
        // integer below 2^52, as a double); OpenMM's Verlet and Langevin integrators write nothing of their own.
        double first = 0;
        memcpy(&first, &values[0], sizeof(first));
        const bool customProgram = (stream.gcount() >= (streamsize) sizeof(first) && std::isfinite(first) && first >= 1 &&
                                    first < 4503599627370496.0 && first == std::floor(first));
        if (customProgram)
            throw OpenMMException("SymPRKIntegrator: the checkpoint was not written by a SymPRKIntegrator but, by the "
                    "look of it, by openmm_symprk's CustomIntegrator backend: load it into SymplecticIntegrator(..., "
                    "backend='custom') with the same method and options as when it was saved");
        throw OpenMMException("SymPRKIntegrator: the checkpoint was not written by a SymPRKIntegrator but by another "
                "integrator (OpenMM's VerletIntegrator, LangevinMiddleIntegrator and the like). A checkpoint continues "
                "the run of the integrator that wrote it; to go on from that run with this one, save a State there "
                "(Simulation.saveState) and load it here (Simulation.loadState), or set the positions and velocities");
    }
    int64_t more[2];
    stream.read((char*) more, sizeof(more));
    string name(more[1] > 0 && more[1] < 4096 ? more[1] : 0, ' ');
    if (!name.empty())
        stream.read(&name[0], name.size());
    if (!stream)
        throw OpenMMException("SymPRKIntegrator: the checkpoint is truncated");
    if (more[0] != getProgramSignature())
        throw OpenMMException(checkpointMismatch(stream, more[0], name));
    int64_t hasBath = 0;
    stream.read((char*) &hasBath, sizeof(hasBath));
    SymPRKThermostat::RunState run;
    string state;
    if (stream && hasBath == 1) {
        int64_t size = 0;
        stream.read((char*) &run.heatBathEnergy, sizeof(double));
        stream.read((char*) &size, sizeof(size));
        if (stream && size > 0 && size < (1 << 20)) {
            state.resize(size);
            stream.read(&state[0], size);
        }
        else
            stream.setstate(ios::failbit);
        if (stream && !version4) {
            int64_t skipped[2] = {0, 0};
            stream.read((char*) &run.kineticEnergy, sizeof(double));
            stream.read((char*) &run.peculiarKineticEnergy, sizeof(double));
            stream.read((char*) skipped, sizeof(skipped));
            run.skippedEvents = skipped[0];
            run.lastSkipped = (skipped[1] != 0);
        }
    }
    if (!stream || hasBath != (thermostat ? 1 : 0))
        throw OpenMMException("SymPRKIntegrator: the checkpoint is truncated or damaged (its thermostat block)");
    if (thermostat && context != NULL) {
        IntegrateSymPRKStepKernel& k = kernel.getAs<IntegrateSymPRKStepKernel>();
        k.setRandomState(state);
        k.setThermostatRunState(run);
    }
    stepsTaken = values[1];
    blowUpStep = values[2];
    if (context != NULL)
        kernel.getAs<IntegrateSymPRKStepKernel>().setBlowUpStep(*context, blowUpStep);
    forcesAreValid = false;
}

string SymPRKIntegrator::checkpointMismatch(istream& stream, long long saved, const string& savedMethod) const {
    int64_t savedBath = -1;
    stream.read((char*) &savedBath, sizeof(savedBath));
    vector<string> differs;
    bool ensemble = false;
    if (stream && (savedBath == 0 || savedBath == 1) && (savedBath == 1) != thermostat) {
        ensemble = true;
        differs.push_back(string("the ensemble (the checkpoint's run was ")+(savedBath == 1 ? "NVT, with temperature=" :
                "NVE, without temperature=")+"; this integrator runs "+(thermostat ? "NVT" : "NVE")+")");
    }
    if (savedMethod != methodName)
        differs.push_back("the method (the checkpoint's run used '"+savedMethod+"'; this integrator runs '"+methodName+"')");
    if (differs.empty() && saved == programSignature(!exactMomentum))
        differs.push_back(string("exact_momentum (the checkpoint's run had it ")+(exactMomentum ? "off" : "on")+
                "; this integrator has it "+(exactMomentum ? "on" : "off")+")");
    if (differs.empty())
        differs.push_back(thermostat ? "the thermostat's settings other than its temperature (collision_time, "
                "thermostat_interval, thermostat_position) or the System's degrees of freedom (its constraints)" :
                "the program's sub-steps (the System's constraints, or groups= and inner_method=)");
    string what = differs[0];
    for (size_t i = 1; i < differs.size(); i++)
        what += " and "+differs[i];
    string message = "SymPRKIntegrator: the checkpoint was written by a SymPRKIntegrator running another program; what "
            "differs: "+what+". ";
    if (ensemble)
        return message+"A checkpoint continues one run in its ensemble; to change the ensemble, save a State of that "
                "run (Simulation.saveState) and load it into a Simulation with this integrator (Simulation.loadState)";
    return message+"Create the integrator with the same method and options as when the checkpoint was saved";
}

// A State's integrator parameters: the heat-bath energy, so that a State carries the effective energy's offset as the
// checkpoint does (the random state stays with checkpoints).
static const char* STATE_NODE = "SymPRKThermostat";

void SymPRKIntegrator::serializeParameters(SerializationNode& node) const {
    if (!thermostat || context == NULL)
        return;
    node.createChildNode(STATE_NODE).setDoubleProperty("heatBathEnergy", getHeatBathEnergy());
}

void SymPRKIntegrator::deserializeParameters(const SerializationNode& node) {
    for (const SerializationNode& child : node.getChildren()) {
        if (child.getName() != STATE_NODE)
            throw OpenMMException("SymPRKIntegrator: the State's integrator parameters hold '"+child.getName()+"', which a "
                                  "SymPRKIntegrator does not have (a State saved with another integrator?)");
        if (!thermostat)
            throw OpenMMException("SymPRKIntegrator: the State holds a thermostat's heat-bath energy, but this integrator "
                                  "has no thermostat (a State saved by an NVT run, loaded into an NVE one): load it with "
                                  "getIntegratorParameters=False, or into an integrator with temperature=");
        if (context != NULL) {
            IntegrateSymPRKStepKernel& k = kernel.getAs<IntegrateSymPRKStepKernel>();
            SymPRKThermostat::RunState run = k.getThermostatRunState();
            run.heatBathEnergy = child.getDoubleProperty("heatBathEnergy");
            k.setThermostatRunState(run);
        }
    }
}
