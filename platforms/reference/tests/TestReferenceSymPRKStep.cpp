/* openmm_symprk native plugin: one step of the Reference kernel against the same step computed by hand.
 *
 * Two particles joined by a harmonic bond, in three dimensions.  Velocity Verlet (the integrator's default
 * sequence: kick 1/2, drift 1, kick 1/2) and position Verlet (drift 1/2, kick 1, drift 1/2, set with
 * setSubsteps) are written out below from the bond's force law; the kernel must reproduce both to round-off. */

#include "openmm/Context.h"
#include "openmm/HarmonicBondForce.h"
#include "openmm/OpenMMException.h"
#include "openmm/Platform.h"
#include "openmm/State.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/System.h"
#include "openmm/Vec3.h"
#include <cmath>
#include <iostream>
#include <utility>
#include <vector>

extern "C" void registerKernelFactories();  // the Reference kernel library's plugin entry point

using namespace OpenMM;
using namespace SymPRKPlugin;
using namespace std;

static const double MASS[2] = {2.0, 5.0};            // Da
static const double K = 800.0, R0 = 0.1;             // kJ/mol/nm^2, nm
static const double DT = 0.002;                      // ps

// The bond's force on each particle: F2 = -K (r - R0) (x2 - x1)/r, F1 = -F2.
static void bondForces(const vector<Vec3>& x, vector<Vec3>& f) {
    Vec3 d = x[1] - x[0];
    double r = sqrt(d.dot(d));
    Vec3 f2 = d * (-K * (r - R0) / r);
    f = {-f2, f2};
}

static void kick(const vector<Vec3>& x, vector<Vec3>& v, double c) {
    vector<Vec3> f;
    bondForces(x, f);
    for (int i = 0; i < 2; i++)
        v[i] += f[i] * (c * DT / MASS[i]);
}

static void drift(vector<Vec3>& x, const vector<Vec3>& v, double c) {
    for (int i = 0; i < 2; i++)
        x[i] += v[i] * (c * DT);
}

static double maxDifference(const vector<Vec3>& a, const vector<Vec3>& b) {
    double worst = 0;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 3; k++)
            worst = max(worst, fabs(a[i][k] - b[i][k]));
    return worst;
}

// One step of `integrator` from (x, v) against the sequence `hand` ('k' kick, 'd' drift, with its coefficient).
static int checkStep(const char* name, SymPRKIntegrator& integrator, const vector<pair<char, double>>& hand,
                     const vector<Vec3>& x, const vector<Vec3>& v) {
    System system;
    for (double m : MASS)
        system.addParticle(m);
    HarmonicBondForce* bond = new HarmonicBondForce();
    bond->addBond(0, 1, R0, K);
    system.addForce(bond);
    Context context(system, integrator, Platform::getPlatformByName("Reference"));
    context.setPositions(x);
    context.setVelocities(v);
    integrator.step(1);
    State state = context.getState(State::Positions | State::Velocities);

    vector<Vec3> hx = x, hv = v;
    for (const auto& substep : hand) {
        if (substep.first == 'k')
            kick(hx, hv, substep.second);
        else
            drift(hx, hv, substep.second);
    }
    double dx = maxDifference(state.getPositions(), hx), dv = maxDifference(state.getVelocities(), hv);
    double moved = maxDifference(hx, x);
    int failed = 0;
    if (!(dx < 1e-14 && dv < 1e-12)) {
        cerr << name << ": max |x - x_hand| = " << dx << " nm, max |v - v_hand| = " << dv << " nm/ps" << endl;
        failed = 1;
    }
    if (!(moved > 1e-4)) {
        cerr << name << ": the particles did not move (" << moved << " nm)" << endl;
        failed = 1;
    }
    if (fabs(state.getTime() - DT) > 1e-15) {
        cerr << name << ": time " << state.getTime() << " ps after one step of " << DT << " ps" << endl;
        failed = 1;
    }
    return failed;
}

int main() {
    try {
        registerKernelFactories();
        vector<Vec3> x = {Vec3(0.0, 0.0, 0.0), Vec3(0.11, 0.02, -0.01)};
        vector<Vec3> v = {Vec3(0.3, -0.1, 0.2), Vec3(-0.2, 0.4, 0.1)};
        int failed = 0;

        SymPRKIntegrator verlet(DT);  // no sequence given: velocity Verlet
        failed |= checkStep("velocity Verlet", verlet, {{'k', 0.5}, {'d', 1.0}, {'k', 0.5}}, x, v);

        SymPRKIntegrator positionVerlet(DT, {SymPRKIntegrator::Drift, SymPRKIntegrator::Kick, SymPRKIntegrator::Drift},
                                        {0.5, 1.0, 0.5}, {-1, -1, -1}, {0, 0, 0});
        failed |= checkStep("position Verlet", positionVerlet, {{'d', 0.5}, {'k', 1.0}, {'d', 0.5}}, x, v);
        if (failed)
            return 1;
    }
    catch (const exception& e) {
        cerr << "exception: " << e.what() << endl;
        return 1;
    }
    cout << "Done" << endl;
    return 0;
}
