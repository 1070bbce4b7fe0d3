/* openmm_symprk native plugin: the SymPRKIntegrator API class. */

#include "openmm/SymPRKIntegrator.h"
#include "openmm/SymPRKKernels.h"
#include "openmm/Context.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"
#include <cmath>
#include <cstdint>
#include <istream>
#include <ostream>
#include <sstream>

using namespace OpenMM;
using namespace std;

static const int64_t CHECKPOINT_MAGIC = 0x53796d50524b0001LL; // "SymPRK" + format version 1

SymPRKIntegrator::SymPRKIntegrator(double stepSize) : exactMomentum(false), forcesAreValid(false),
        methodName("verlet"), stepsTaken(0), blowUpStep(0) {
    setStepSize(stepSize);
    setConstraintTolerance(1e-5);
    setSubsteps({Kick, Drift, Kick}, {0.5, 1.0, 0.5});
}

SymPRKIntegrator::SymPRKIntegrator(double stepSize, const vector<int>& kinds, const vector<double>& coefficients) :
        exactMomentum(false), forcesAreValid(false), methodName(""), stepsTaken(0), blowUpStep(0) {
    setStepSize(stepSize);
    setConstraintTolerance(1e-5);
    setSubsteps(kinds, coefficients);
}

void SymPRKIntegrator::setSubsteps(const vector<int>& newKinds, const vector<double>& newCoefficients) {
    if (owner != NULL)
        throw OpenMMException("SymPRKIntegrator: the sub-steps cannot be changed once the integrator is bound to a Context");
    if (newKinds.size() != newCoefficients.size())
        throw OpenMMException("SymPRKIntegrator: kinds and coefficients must have the same length");
    vector<int> k;
    vector<double> c;
    for (size_t i = 0; i < newKinds.size(); i++) {
        if (newKinds[i] != Kick && newKinds[i] != Drift) {
            stringstream msg;
            msg << "SymPRKIntegrator: sub-step " << i << " has kind " << newKinds[i] << "; expected 0 (kick) or 1 (drift)";
            throw OpenMMException(msg.str());
        }
        if (!std::isfinite(newCoefficients[i])) {
            stringstream msg;
            msg << "SymPRKIntegrator: sub-step " << i << " has a non-finite coefficient";
            throw OpenMMException(msg.str());
        }
        if (newCoefficients[i] == 0.0)
            continue;
        if (!k.empty() && k.back() == newKinds[i])
            c.back() += newCoefficients[i];
        else {
            k.push_back(newKinds[i]);
            c.push_back(newCoefficients[i]);
        }
        if (c.back() == 0.0) {
            k.pop_back();
            c.pop_back();
        }
    }
    if (k.empty())
        throw OpenMMException("SymPRKIntegrator: a step needs at least one sub-step with a non-zero coefficient");
    kinds = k;
    coefficients = c;
}

int SymPRKIntegrator::getSubstepKind(int index) const {
    if (index < 0 || index >= (int) kinds.size())
        throw OpenMMException("SymPRKIntegrator: sub-step index out of range");
    return kinds[index];
}

double SymPRKIntegrator::getSubstepCoefficient(int index) const {
    if (index < 0 || index >= (int) kinds.size())
        throw OpenMMException("SymPRKIntegrator: sub-step index out of range");
    return coefficients[index];
}

int SymPRKIntegrator::getForceEvaluationsPerStep() const {
    int n = 0;
    for (int k : kinds)
        if (k == Kick)
            n++;
    if (n > 0 && kinds.size() > 1 && kinds.front() == Kick && kinds.back() == Kick)
        n--;
    return n;
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

void SymPRKIntegrator::initialize(ContextImpl& contextRef) {
    if (owner != NULL && &contextRef.getOwner() != owner)
        throw OpenMMException("This Integrator is already bound to a context");
    context = &contextRef;
    owner = &contextRef.getOwner();
    kernel = context->getPlatform().createKernel(IntegrateSymPRKStepKernel::Name(), contextRef);
    kernel.getAs<IntegrateSymPRKStepKernel>().initialize(contextRef.getSystem(), *this);
    kernel.getAs<IntegrateSymPRKStepKernel>().setBlowUpStep(contextRef, blowUpStep);
    forcesAreValid = false;
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
    for (int i = 0; i < steps; ++i) {
        stepsTaken++;
        k.execute(*context, *this, forcesAreValid, stepsTaken);
    }
}

void SymPRKIntegrator::createCheckpoint(ostream& stream) const {
    int64_t values[3] = {CHECKPOINT_MAGIC, (int64_t) stepsTaken, (int64_t) getBlowUpStep()};
    stream.write((const char*) values, sizeof(values));
}

void SymPRKIntegrator::loadCheckpoint(istream& stream) {
    int64_t values[3];
    stream.read((char*) values, sizeof(values));
    if (!stream || values[0] != CHECKPOINT_MAGIC)
        throw OpenMMException("SymPRKIntegrator: the checkpoint was not written by a SymPRKIntegrator");
    stepsTaken = values[1];
    blowUpStep = values[2];
    if (context != NULL)
        kernel.getAs<IntegrateSymPRKStepKernel>().setBlowUpStep(*context, blowUpStep);
    forcesAreValid = false;
}
