/* openmm_symprk native plugin: the thermostat events of the Reference kernel against a hand computation.
 *
 * Four particles with mass and one massless particle, no forces, velocity Verlet with the thermostat every
 * 2 steps keeping the rotation (an isolated cluster), seed 4321.  Step 1 is a half event before the step (the
 * kicks do nothing without forces), step 2 a half event after it.  Each event is computed here from its
 * definition, with the same random stream (std::mt19937_64 seeded 4321, a fresh standard normal and a fresh
 * gamma distribution per event): kept field u = V + w x (x - R) with I w = L about the centre of mass,
 * K_pec = K - |P|^2/2M - L.w/2, the rescaling factor of Bussi, Donadio and Parrinello, v <- u + alpha (v - u),
 * heat-bath energy -= K' - K_pec.  The kernel must agree to round-off and keep P and L. */

#include "openmm/Context.h"
#include "openmm/OpenMMException.h"
#include "openmm/Platform.h"
#include "openmm/State.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/System.h"
#include "openmm/Vec3.h"
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

extern "C" void registerKernelFactories();  // the Reference kernel library's plugin entry point

using namespace OpenMM;
using namespace SymPRKPlugin;
using namespace std;

static const double MASS[5] = {12.0, 1.0, 16.0, 0.0, 2.5};  // Da; particle 3 is massless
static const double DT = 0.002, TEMPERATURE = 300.0, TAU = 0.1, KB = 0.00831446261815324;  // ps, K, ps, kJ/mol/K
static const int INTERVAL = 2, DOF = 3*4-6, SEED = 4321;

// Solve the 3x3 system A y = b by Gaussian elimination with partial pivoting.
static Vec3 solve(double A[3][3], Vec3 b) {
    double a[3][4];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            a[i][j] = A[i][j];
        a[i][3] = b[i];
    }
    for (int c = 0; c < 3; c++) {
        int p = c;
        for (int r = c+1; r < 3; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        for (int j = 0; j < 4; j++)
            swap(a[c][j], a[p][j]);
        for (int r = c+1; r < 3; r++) {
            double f = a[r][c]/a[c][c];
            for (int j = c; j < 4; j++)
                a[r][j] -= f*a[c][j];
        }
    }
    Vec3 y;
    for (int i = 2; i >= 0; i--) {
        double s = a[i][3];
        for (int j = i+1; j < 3; j++)
            s -= a[i][j]*y[j];
        y[i] = s/a[i][i];
    }
    return y;
}

// One event by hand: returns the new velocities and adds -(K' - K_pec) to bath.
static vector<Vec3> handEvent(const vector<Vec3>& x, const vector<Vec3>& v, mt19937_64& rng, double& bath) {
    normal_distribution<double> normal(0.0, 1.0);
    double r1 = normal(rng);
    gamma_distribution<double> gamma(0.5*(DOF-1), 1.0);
    double chi2 = 2.0*gamma(rng);
    double M = 0;
    Vec3 R, P;
    for (int i = 0; i < 5; i++) {
        M += MASS[i];
        R += x[i]*MASS[i];
        P += v[i]*MASS[i];
    }
    R = R/M;
    Vec3 V = P/M;
    double I[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    Vec3 L;
    double K = 0;
    for (int i = 0; i < 5; i++) {
        Vec3 r = x[i]-R;
        L += r.cross(v[i])*MASS[i];
        K += 0.5*MASS[i]*v[i].dot(v[i]);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                I[a][b] += MASS[i]*((a == b ? r.dot(r) : 0.0) - r[a]*r[b]);
    }
    Vec3 w = solve(I, L);
    double kpec = K - 0.5*P.dot(P)/M - 0.5*L.dot(w);
    double c = exp(-0.5*INTERVAL*DT/TAU), target = 0.5*DOF*KB*TEMPERATURE, s = target/DOF;
    double knew = c*kpec + (1-c)*s*(r1*r1+chi2) + 2*r1*sqrt(c*(1-c)*kpec*s);
    double alpha = sqrt(knew/kpec) * (r1+sqrt(c*kpec/((1-c)*s)) < 0 ? -1.0 : 1.0);
    bath -= knew-kpec;
    vector<Vec3> out = v;
    for (int i = 0; i < 5; i++)
        if (MASS[i] != 0) {
            Vec3 u = V + w.cross(x[i]-R);
            out[i] = u + (v[i]-u)*alpha;
        }
    return out;
}

static double maxDifference(const vector<Vec3>& a, const vector<Vec3>& b) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); i++)
        for (int k = 0; k < 3; k++)
            worst = max(worst, fabs(a[i][k]-b[i][k]));
    return worst;
}

static void momenta(const vector<Vec3>& x, const vector<Vec3>& v, Vec3& P, Vec3& L) {
    P = L = Vec3();
    for (int i = 0; i < 5; i++) {
        P += v[i]*MASS[i];
        L += x[i].cross(v[i])*MASS[i];
    }
}

int main() {
    try {
        registerKernelFactories();
        System system;
        for (double m : MASS)
            system.addParticle(m);
        // velocity Verlet with the ends placement's events: half an event before and after the kicks and drift
        const int T = SymPRKIntegrator::Thermostat, K = SymPRKIntegrator::Kick, D = SymPRKIntegrator::Drift;
        SymPRKIntegrator integrator(DT, {T, K, D, K, T}, {0.5, 0.5, 1.0, 0.5, 0.5}, {-1, -1, -1, -1, -1},
                                    {SymPRKIntegrator::FirstOfInterval, SymPRKIntegrator::ForcesCached, 0, 0,
                                     SymPRKIntegrator::LastOfInterval});
        integrator.setThermostat(TEMPERATURE, TAU, INTERVAL, DOF, true);
        integrator.setRandomNumberSeed(SEED);
        Context context(system, integrator, Platform::getPlatformByName("Reference"));
        vector<Vec3> x = {Vec3(0.0, 0.0, 0.0), Vec3(0.11, 0.02, -0.01), Vec3(-0.05, 0.13, 0.04), Vec3(0.3, 0.3, 0.3),
                          Vec3(0.02, -0.09, 0.12)};
        vector<Vec3> v = {Vec3(0.3, -0.1, 0.2), Vec3(-0.2, 0.4, 0.1), Vec3(0.05, 0.02, -0.3), Vec3(1.0, 2.0, 3.0),
                          Vec3(-0.6, 0.1, 0.25)};
        context.setPositions(x);
        context.setVelocities(v);
        Vec3 P0, L0;
        momenta(x, v, P0, L0);
        mt19937_64 rng(SEED);
        double bath = 0;
        int failed = 0;

        // step 1: an event before the step, then free flight
        integrator.step(1);
        vector<Vec3> v1 = handEvent(x, v, rng, bath);
        State s1 = context.getState(State::Positions | State::Velocities);
        double dv = maxDifference(s1.getVelocities(), v1), dbath = fabs(integrator.getHeatBathEnergy()-bath);
        if (!(dv < 1e-13 && dbath < 1e-13*fabs(bath)+1e-15 && bath != 0)) {
            cerr << "event before step 1: max |v - v_hand| = " << dv << " nm/ps, heat bath " << integrator.getHeatBathEnergy()
                 << " kJ/mol against " << bath << endl;
            failed = 1;
        }
        if (maxDifference(v1, v) < 1e-3) {
            cerr << "the event did not change the velocities" << endl;
            failed = 1;
        }
        vector<Vec3> x1 = x;
        for (int i = 0; i < 5; i++)
            if (MASS[i] != 0)
                x1[i] = x[i] + v1[i]*DT;
        if (s1.getVelocities()[3] != v[3] || s1.getPositions()[3] != x[3]) {
            cerr << "the massless particle moved" << endl;
            failed = 1;
        }

        // step 2: free flight, then an event after the step (at the new positions)
        integrator.step(1);
        vector<Vec3> x2 = x1;
        for (int i = 0; i < 5; i++)
            if (MASS[i] != 0)
                x2[i] = x1[i] + v1[i]*DT;
        vector<Vec3> v2 = handEvent(x2, v1, rng, bath);
        State s2 = context.getState(State::Positions | State::Velocities);
        dv = maxDifference(s2.getVelocities(), v2);
        dbath = fabs(integrator.getHeatBathEnergy()-bath);
        double dx = maxDifference(s2.getPositions(), x2);
        if (!(dv < 1e-13 && dx < 1e-14 && dbath < 1e-13*fabs(bath)+1e-15)) {
            cerr << "event after step 2: max |v - v_hand| = " << dv << " nm/ps, |x - x_hand| = " << dx << " nm, heat bath "
                 << integrator.getHeatBathEnergy() << " kJ/mol against " << bath << endl;
            failed = 1;
        }
        Vec3 P2, L2;
        momenta(s2.getPositions(), s2.getVelocities(), P2, L2);
        double dP = sqrt((P2-P0).dot(P2-P0)), dL = sqrt((L2-L0).dot(L2-L0));
        if (!(dP < 1e-13 && dL < 1e-13)) {
            cerr << "momenta changed: |dP| = " << dP << ", |dL| = " << dL << endl;
            failed = 1;
        }
        // the heat-bath energy is minus the kinetic energy the thermostat added (no forces: K changes by events only)
        double K0 = 0, K2 = 0;
        for (int i = 0; i < 5; i++) {
            K0 += 0.5*MASS[i]*v[i].dot(v[i]);
            K2 += 0.5*MASS[i]*s2.getVelocities()[i].dot(s2.getVelocities()[i]);
        }
        if (!(fabs((K2-K0) + integrator.getHeatBathEnergy()) < 1e-12)) {
            cerr << "K2 - K0 = " << K2-K0 << " kJ/mol, heat bath " << integrator.getHeatBathEnergy() << endl;
            failed = 1;
        }
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
