/* openmm_symprk native plugin: the host side of a thermostat event (see SymPRKThermostat.h). */

#include "openmm/internal/SymPRKThermostat.h"
#include "openmm/internal/SymPRKInertia.h"
#include "openmm/OpenMMException.h"
#include "SimTKOpenMMRealType.h"
#include <cmath>
#include <sstream>

using namespace SymPRKPlugin;
using namespace OpenMM;
using namespace std;

SymPRKThermostat::SymPRKThermostat() {
}

void SymPRKThermostat::initialize(int seed) {
    if (seed == 0) {
        random_device device;
        rng.seed(((uint64_t) device() << 32) ^ (uint64_t) device());
    }
    else
        rng.seed((uint64_t) (uint32_t) seed);
    run = RunState();
}

double SymPRKThermostat::boltzmann() {
    return BOLTZ;
}

string SymPRKThermostat::getRandomState() const {
    stringstream stream;
    stream << rng;
    return stream.str();
}

void SymPRKThermostat::setRandomState(const string& state) {
    stringstream stream(state);
    std::mt19937_64 restored;
    stream >> restored;
    if (stream.fail())
        throw OpenMMException("SymPRKIntegrator: the checkpoint's thermostat random state is damaged");
    rng = restored;
}

double SymPRKThermostat::rescalingFactor(double kinetic, double target, int dof, double c, double r1, double chi2, double& newKinetic) {
    // openmm_symprk.physics.velocity_rescaling.rescaling_factor, the same operations in the same order.
    if (!(kinetic > 0)) {
        newKinetic = kinetic;  // no peculiar motion: nothing to rescale
        return 1.0;
    }
    const double s = target/dof;
    const double knew = c*kinetic + (1.0-c)*s*(r1*r1+chi2) + 2.0*r1*sqrt(c*(1.0-c)*kinetic*s);
    double alpha = sqrt(max(knew, 0.0)/kinetic);
    if (c < 1.0 && r1+sqrt(c*kinetic/((1.0-c)*s)) < 0)
        alpha = -alpha;  // the velocity came out reversed along itself
    newKinetic = knew;
    return alpha;
}

void SymPRKThermostat::drawNoise(int dof, double& r1, double& chi2) {
    normal_distribution<double> normal(0.0, 1.0);
    r1 = normal(rng);
    chi2 = 0.0;
    if (dof > 1) {
        gamma_distribution<double> gamma(0.5*(dof-1), 1.0);
        chi2 = 2.0*gamma(rng);
    }
}

SymPRKThermostat::Event SymPRKThermostat::event(const Sums& sums, double temperature, int dof, bool keepRotation, double c) {
    Event e;
    e.apply = false;
    e.alpha = 1.0;
    e.kinetic = e.newKinetic = 0.0;
    // The noise is drawn first, whatever follows, so that the random stream advances by one event per event.
    double r1, chi2;
    drawNoise(dof, r1, chi2);
    const double M = sums.mass;
    if (!(M > 0))
        return e;
    e.velocity = sums.momentum/M;
    const double total = 0.5*sums.twiceKinetic;
    double kinetic = 0.5*sums.twicePeculiar;
    if (keepRotation) {
        e.centre = sums.centre;
        e.omega = solveInertia(sums.d, sums.o, sums.angular, false);
        kinetic -= 0.5*sums.angular.dot(e.omega);
    }
    if (!std::isfinite(kinetic) || !std::isfinite(total))
        return e;  // a blown-up state, which the blow-up check reports
    run.kineticEnergy = total;
    run.peculiarKineticEnergy = kinetic;
    run.lastSkipped = false;
    if (!(kinetic > negligiblePeculiarFraction()*total)) {
        run.skippedEvents++;  // at rest or a rigid motion: only round-off to scale
        run.lastSkipped = true;
        return e;
    }
    const double target = 0.5*dof*BOLTZ*temperature;
    double newKinetic;
    const double alpha = rescalingFactor(kinetic, target, dof, c, r1, chi2, newKinetic);
    if (!std::isfinite(alpha) || !std::isfinite(newKinetic))
        return e;
    e.apply = true;
    e.alpha = alpha;
    e.kinetic = kinetic;
    e.newKinetic = newKinetic;
    run.heatBathEnergy -= newKinetic-kinetic;
    run.kineticEnergy = total-kinetic+newKinetic;
    run.peculiarKineticEnergy = newKinetic;
    return e;
}
