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

SymPRKThermostat::SymPRKThermostat() : heatBathEnergy(0.0) {
}

void SymPRKThermostat::initialize(int seed) {
    if (seed == 0) {
        random_device device;
        rng.seed(((uint64_t) device() << 32) ^ (uint64_t) device());
    }
    else
        rng.seed((uint64_t) (uint32_t) seed);
    heatBathEnergy = 0.0;
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

SymPRKThermostat::Event SymPRKThermostat::event(const double* sums, double temperature, int dof, bool keepRotation, double c) {
    Event e;
    e.apply = false;
    e.alpha = 1.0;
    e.kinetic = e.newKinetic = 0.0;
    // The noise is drawn first, whatever follows, so that the random stream advances by one event per event.
    normal_distribution<double> normal(0.0, 1.0);
    const double r1 = normal(rng);
    double chi2 = 0.0;
    if (dof > 1) {
        gamma_distribution<double> gamma(0.5*(dof-1), 1.0);
        chi2 = 2.0*gamma(rng);
    }
    const double M = sums[SumMass];
    if (!(M > 0))
        return e;
    const Vec3 P(sums[SumMomentum], sums[SumMomentum+1], sums[SumMomentum+2]);
    e.velocity = P/M;
    double kinetic = 0.5*sums[SumTwiceKinetic] - 0.5*P.dot(P)/M;
    if (keepRotation) {
        const Vec3 R = Vec3(sums[SumMomentX], sums[SumMomentX+1], sums[SumMomentX+2])/M;
        const double* S = sums+SumSecond;
        // second moments and angular momentum about the centre of mass
        const Vec3 d(S[0]-M*R[0]*R[0], S[3]-M*R[1]*R[1], S[5]-M*R[2]*R[2]);
        const Vec3 o(S[1]-M*R[0]*R[1], S[2]-M*R[0]*R[2], S[4]-M*R[1]*R[2]);
        const Vec3 L = Vec3(sums[SumAngular], sums[SumAngular+1], sums[SumAngular+2]) - R.cross(P);
        e.centre = R;
        e.omega = solveInertia(d, o, L, false);
        kinetic -= 0.5*L.dot(e.omega);
    }
    const double target = 0.5*dof*BOLTZ*temperature;
    double newKinetic;
    const double alpha = rescalingFactor(kinetic, target, dof, c, r1, chi2, newKinetic);
    if (!(kinetic > 0) || !std::isfinite(kinetic) || !std::isfinite(alpha) || !std::isfinite(newKinetic))
        return e;  // nothing to rescale (or a blown-up state, which the blow-up check reports)
    e.apply = true;
    e.alpha = alpha;
    e.kinetic = kinetic;
    e.newKinetic = newKinetic;
    heatBathEnergy -= newKinetic-kinetic;
    return e;
}
