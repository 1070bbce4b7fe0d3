/* openmm_symprk native plugin: the Reference (and CPU) SymPRKIntegrator kernel.
 *
 * Arithmetic follows the CustomIntegrator program of openmm_symprk/program.py operation by operation, so
 * that on Reference both give the same trajectory to round-off:
 *   kick   v = v + (c*dt)*f/m
 *   drift  x_ref = x;  x = x + (c*dt)*v;  [constraints] x_u = x;  constrain x against x_ref;
 *          v = v + (x - x_u)/(c*dt)
 *   end    [constraints] velocity projection against the final positions
 */

#include "ReferenceSymPRKKernels.h"
#include "ReferenceConstraints.h"
#include "ReferenceVirtualSites.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"
#include "openmm/internal/ThreadPool.h"
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>

using namespace OpenMM;
using namespace std;

// Below this many particles the per-atom loops run on the calling thread: a loop over a few thousand atoms
// takes microseconds, about what a hand-off to the pool costs.  SYMPRK_THREAD_MIN_ATOMS overrides it.
static int threadThreshold() {
    const char* env = getenv("SYMPRK_THREAD_MIN_ATOMS");
    if (env != NULL)
        return atoi(env);
    return 8192;
}

void ReferenceIntegrateSymPRKStepKernel::initialize(const System& sys, const SymPRKIntegrator& integrator) {
    system = &sys;
    numParticles = sys.getNumParticles();
    masses.resize(numParticles);
    inverseMasses.resize(numParticles);
    hasVirtualSites = false;
    for (int i = 0; i < numParticles; i++) {
        masses[i] = sys.getParticleMass(i);
        inverseMasses[i] = (masses[i] == 0.0 ? 0.0 : 1.0/masses[i]);
        if (sys.isVirtualSite(i))
            hasVirtualSites = true;
    }
    hasConstraints = (sys.getNumConstraints() > 0);
    set<int> kickGroups;
    for (int s = 0; s < integrator.getNumSubsteps(); s++)
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick)
            kickGroups.insert(integrator.getSubstepForceGroups(s));
    multipleGroups = (kickGroups.size() > 1);
    groupForces.clear();
    xRef.resize(numParticles);
    xUnconstrained.resize(numParticles);
    int numThreads = data.threads.getNumThreads();
    useThreads = (numThreads > 1 && numParticles >= threadThreshold());
    int chunks = (useThreads ? numThreads : 1);
    threadStart.resize(chunks+1);
    for (int t = 0; t <= chunks; t++)
        threadStart[t] = (int) (((long long) numParticles*t)/chunks);
}

void ReferenceIntegrateSymPRKStepKernel::parallelFor(const function<void(int, int, int)>& task) {
    if (!useThreads) {
        task(0, 0, numParticles);
        return;
    }
    int chunks = threadStart.size()-1;
    data.threads.execute([&] (ThreadPool& pool, int thread) {
        if (thread < chunks)
            task(thread, threadStart[thread], threadStart[thread+1]);
    });
    data.threads.waitForThreads();
}

void ReferenceIntegrateSymPRKStepKernel::computeProjection(const vector<Vec3>& pos, const vector<Vec3>& force) {
    // Sums in double, in a fixed order (per-chunk partial sums added in chunk order): deterministic.
    int chunks = threadStart.size()-1;
    vector<double> mass(chunks, 0.0);
    vector<Vec3> mx(chunks), fsum(chunks);
    parallelFor([&] (int t, int start, int end) {
        double m = 0;
        Vec3 a, b;
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0) {
                m += masses[i];
                a += pos[i]*masses[i];
                b += force[i];
            }
        mass[t] = m;
        mx[t] = a;
        fsum[t] = b;
    });
    double totalMass = 0;
    Vec3 moment, netForce;
    for (int t = 0; t < chunks; t++) {
        totalMass += mass[t];
        moment += mx[t];
        netForce += fsum[t];
    }
    if (totalMass == 0.0) {
        com = acm = alpha = Vec3();
        return;
    }
    com = moment/totalMass;
    acm = netForce/totalMass;
    vector<Vec3> torque(chunks), diag(chunks), offdiag(chunks);
    parallelFor([&] (int t, int start, int end) {
        Vec3 tau, d, o;
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0) {
                Vec3 r = pos[i]-com;
                tau += r.cross(force[i]);
                double m = masses[i];
                d += Vec3(m*r[0]*r[0], m*r[1]*r[1], m*r[2]*r[2]);
                o += Vec3(m*r[0]*r[1], m*r[0]*r[2], m*r[1]*r[2]);
            }
        torque[t] = tau;
        diag[t] = d;
        offdiag[t] = o;
    });
    Vec3 tau, d, o;
    for (int t = 0; t < chunks; t++) {
        tau += torque[t];
        d += diag[t];
        o += offdiag[t];
    }
    alpha = solveInertia(d, o, tau);
}

Vec3 ReferenceIntegrateSymPRKStepKernel::solveInertia(Vec3 d, Vec3 o, Vec3 tau) {
    // d = (sum m x^2, sum m y^2, sum m z^2), o = (sum m xy, sum m xz, sum m yz) about the centre of mass.
    // The inertia tensor is regularised by 1e-12 of its trace (a linear molecule or a single particle then
    // gives a finite result; the shift changes a round-off-sized torque by 1e-12 of itself).
    return SymPRKThermostat::solveInertia(d, o, tau);
}

void ReferenceIntegrateSymPRKStepKernel::thermostatEvent(const SymPRKIntegrator& integrator) {
    // The sums in double, serially in particle order (deterministic, whatever the thread count); the host
    // computes the kept field and the factor (SymPRKThermostat), then every particle with mass is rescaled.
    const vector<Vec3>& pos = *data.positions;
    vector<Vec3>& vel = *data.velocities;
    const bool rotation = integrator.getThermostatKeepsRotation();
    double sums[SymPRKThermostat::NumSums] = {0};
    double M = 0, px = 0, py = 0, pz = 0, twiceK = 0;
    for (int i = 0; i < numParticles; i++) {
        const double m = masses[i];
        if (m == 0.0)
            continue;
        const Vec3& v = vel[i];
        M += m;
        px += m*v[0];
        py += m*v[1];
        pz += m*v[2];
        twiceK += m*(v[0]*v[0]+v[1]*v[1]+v[2]*v[2]);
    }
    sums[SymPRKThermostat::SumMass] = M;
    sums[SymPRKThermostat::SumMomentum] = px;
    sums[SymPRKThermostat::SumMomentum+1] = py;
    sums[SymPRKThermostat::SumMomentum+2] = pz;
    sums[SymPRKThermostat::SumTwiceKinetic] = twiceK;
    if (rotation) {
        // the positions' moments and the angular momentum about the origin
        double mx = 0, my = 0, mz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, lx = 0, ly = 0, lz = 0;
        for (int i = 0; i < numParticles; i++) {
            const double m = masses[i];
            if (m == 0.0)
                continue;
            const Vec3& x = pos[i];
            const Vec3& v = vel[i];
            mx += m*x[0];
            my += m*x[1];
            mz += m*x[2];
            xx += m*x[0]*x[0];
            xy += m*x[0]*x[1];
            xz += m*x[0]*x[2];
            yy += m*x[1]*x[1];
            yz += m*x[1]*x[2];
            zz += m*x[2]*x[2];
            lx += m*(x[1]*v[2]-x[2]*v[1]);
            ly += m*(x[2]*v[0]-x[0]*v[2]);
            lz += m*(x[0]*v[1]-x[1]*v[0]);
        }
        const double moments[12] = {mx, my, mz, xx, xy, xz, yy, yz, zz, lx, ly, lz};
        for (int j = 0; j < 3; j++) {
            sums[SymPRKThermostat::SumMomentX+j] = moments[j];
            sums[SymPRKThermostat::SumAngular+j] = moments[9+j];
        }
        for (int j = 0; j < 6; j++)
            sums[SymPRKThermostat::SumSecond+j] = moments[3+j];
    }
    const SymPRKThermostat::Event e = thermostat.event(sums, integrator, thermostatDecay(integrator));
    if (!e.apply)
        return;
    const double alpha = e.alpha;
    const Vec3 V = e.velocity, R = e.centre, w = e.omega;
    parallelFor([&] (int t, int start, int end) {
        if (rotation) {
            for (int i = start; i < end; i++)
                if (masses[i] != 0.0) {
                    const Vec3 u = V + w.cross(pos[i]-R);
                    for (int j = 0; j < 3; j++)
                        vel[i][j] = u[j] + alpha*(vel[i][j]-u[j]);
                }
        }
        else {
            for (int i = start; i < end; i++)
                if (masses[i] != 0.0)
                    for (int j = 0; j < 3; j++)
                        vel[i][j] = V[j] + alpha*(vel[i][j]-V[j]);
        }
    });
}

void ReferenceIntegrateSymPRKStepKernel::removeRigidChange(const vector<Vec3>& pos, vector<Vec3>& vel, Vec3 dP, Vec3 dL) {
    // Velocities changed by impulses whose net momentum dP and angular momentum dL (about the origin) should be
    // zero but are not, by round-off: add the rigid-body velocity w + gamma x (r - c) that cancels both
    // (c: centre of mass of pos).  A rigid-body velocity keeps every distance-constraint velocity condition.
    int chunks = threadStart.size()-1;
    vector<double> mass(chunks, 0.0);
    vector<Vec3> mx(chunks);
    parallelFor([&] (int t, int start, int end) {
        double m = 0;
        Vec3 a;
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0) {
                m += masses[i];
                a += pos[i]*masses[i];
            }
        mass[t] = m;
        mx[t] = a;
    });
    double M = 0;
    Vec3 moment;
    for (int t = 0; t < chunks; t++) {
        M += mass[t];
        moment += mx[t];
    }
    if (M == 0.0)
        return;
    Vec3 c = moment/M;
    vector<Vec3> diag(chunks), offdiag(chunks);
    parallelFor([&] (int t, int start, int end) {
        Vec3 d, o;
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0) {
                Vec3 r = pos[i]-c;
                double m = masses[i];
                d += Vec3(m*r[0]*r[0], m*r[1]*r[1], m*r[2]*r[2]);
                o += Vec3(m*r[0]*r[1], m*r[0]*r[2], m*r[1]*r[2]);
            }
        diag[t] = d;
        offdiag[t] = o;
    });
    Vec3 d, o;
    for (int t = 0; t < chunks; t++) {
        d += diag[t];
        o += offdiag[t];
    }
    Vec3 w = -dP/M;
    Vec3 gamma = solveInertia(d, o, c.cross(dP)-dL);
    parallelFor([&] (int t, int start, int end) {
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0)
                vel[i] = vel[i] + w + gamma.cross(pos[i]-c);
    });
}

void ReferenceIntegrateSymPRKStepKernel::projectVelocities(vector<Vec3>& pos, vector<Vec3>& vel, double tol, bool exact) {
    ReferenceConstraintAlgorithm& constraints = *data.constraints;
    if (!exact) {
        constraints.applyToVelocities(pos, vel, inverseMasses, tol);
        return;
    }
    // Exact momentum: remove the round-off net momentum and torque of the velocity-constraint impulses.
    vBefore = vel;
    constraints.applyToVelocities(pos, vel, inverseMasses, tol);
    Vec3 dP, dL;
    for (int i = 0; i < numParticles; i++)
        if (masses[i] != 0.0) {
            Vec3 impulse = (vel[i]-vBefore[i])*masses[i];
            dP += impulse;
            dL += pos[i].cross(impulse);
        }
    removeRigidChange(pos, vel, dP, dL);
}

void ReferenceIntegrateSymPRKStepKernel::execute(ContextImpl& context, const SymPRKIntegrator& integrator, bool& forcesAreValid, long long stepIndex) {
    vector<Vec3>& pos = *data.positions;
    vector<Vec3>& vel = *data.velocities;
    vector<Vec3>& force = *data.forces;
    const double dt = integrator.getStepSize();
    const double tol = integrator.getConstraintTolerance();
    const int groups = integrator.getIntegrationForceGroups();
    const bool exact = integrator.getExactMomentum();
    ReferenceConstraintAlgorithm& constraints = *data.constraints;
    const ReferenceVirtualSites& vsites = *data.virtualSites;

    if (context.updateContextState())
        forcesAreValid = false;
    if (!forcesAreValid)
        groupForces.clear();  // the cached forces of a multiple-time-step method belong to old positions
    // Thermostat: a half event before the first step of every interval (after the Context's state updates, a
    // barostat's move included), and one after its last step (below).
    if (thermostatBefore(integrator, stepIndex))
        thermostatEvent(integrator);

    // One pass over the atoms per kick and per drift; a kick directly followed by a drift (every kick but a
    // step's last) shares its pass with it.  The per-atom arithmetic is the same either way.
    auto driftAtom = [&] (int i, double cdt) {
        if (hasConstraints)
            xRef[i] = pos[i];
        if (masses[i] != 0.0)
            for (int j = 0; j < 3; j++)
                pos[i][j] = pos[i][j] + cdt*vel[i][j];
        if (hasConstraints)
            xUnconstrained[i] = pos[i];
    };
    auto finishDrift = [&] (double cdt) {
        if (hasConstraints) {
            constraints.apply(xRef, pos, inverseMasses, tol);
            int chunks = threadStart.size()-1;
            vector<Vec3> netP(chunks), netL(chunks);
            parallelFor([&] (int t, int start, int end) {
                Vec3 p, l;
                for (int i = start; i < end; i++)
                    if (masses[i] != 0.0) {
                        for (int j = 0; j < 3; j++)
                            vel[i][j] = vel[i][j] + (pos[i][j]-xUnconstrained[i][j])/cdt;
                        if (exact) {
                            Vec3 impulse = (pos[i]-xUnconstrained[i])*(masses[i]/cdt);
                            p += impulse;
                            l += xRef[i].cross(impulse);
                        }
                    }
                netP[t] = p;
                netL[t] = l;
            });
            if (exact) {
                // Exact momentum: the constraint impulses m (x - x_u)/h carry no net momentum and no torque about
                // the pre-drift positions in exact arithmetic; remove their round-off values.
                Vec3 dP, dL;
                for (int t = 0; t < chunks; t++) {
                    dP += netP[t];
                    dL += netL[t];
                }
                removeRigidChange(pos, vel, dP, dL);
            }
        }
        if (hasVirtualSites)
            vsites.computePositions(*system, pos, data.periodicBoxVectors);
        forcesAreValid = false;
        groupForces.clear();
    };
    // The sub-step flags come with the sequence (openmm_symprk.methods.resolved states the rules): a velocity
    // projection before a drift flagged ProjectVelocitiesBefore (where the System has constraints), and forces
    // reused by a kick flagged ForcesCached while they are still valid.
    const int numSubsteps = integrator.getNumSubsteps();
    auto projectBefore = [&] (int s) {
        return hasConstraints && (integrator.getSubstepFlags(s) & SymPRKIntegrator::ProjectVelocitiesBefore) != 0;
    };
    for (int s = 0; s < numSubsteps; ) {
        const double cdt = integrator.getSubstepCoefficient(s)*dt;
        if (integrator.getSubstepKind(s) == SymPRKIntegrator::Kick) {
            // The forces of this kick's groups: computed unless cached since the last drift.  A
            // multiple-time-step method keeps a copy per group, so that a group is evaluated only where a
            // drift came between two of its kicks.
            const int mask = (integrator.getSubstepForceGroups(s) == -1 ? groups : integrator.getSubstepForceGroups(s));
            const bool reuse = (integrator.getSubstepFlags(s) & SymPRKIntegrator::ForcesCached) != 0;
            const vector<Vec3>* kickForces = &force;
            auto cached = (reuse ? groupForces.find(mask) : groupForces.end());
            if (cached != groupForces.end())
                kickForces = &cached->second;
            else {
                if (!reuse || !forcesAreValid || context.getLastForceGroups() != mask) {
                    context.calcForcesAndEnergy(true, false, mask);
                    forcesAreValid = true;
                }
                if (multipleGroups) {
                    groupForces[mask] = force;
                    kickForces = &groupForces[mask];
                }
            }
            const vector<Vec3>& f = *kickForces;
            // a drift right after this kick shares its pass, unless it projects the velocities first (a kick of
            // another force group may follow too: multiple time stepping)
            const bool fuse = (s+1 < numSubsteps && integrator.getSubstepKind(s+1) == SymPRKIntegrator::Drift &&
                               !projectBefore(s+1));
            const double cdtDrift = (fuse ? integrator.getSubstepCoefficient(s+1)*dt : 0.0);
            if (exact) {
                computeProjection(pos, f);
                parallelFor([&] (int t, int start, int end) {
                    for (int i = start; i < end; i++) {
                        if (masses[i] != 0.0) {
                            Vec3 a = f[i]/masses[i] - acm - alpha.cross(pos[i]-com);
                            vel[i] = vel[i] + a*cdt;
                        }
                        if (fuse)
                            driftAtom(i, cdtDrift);
                    }
                });
            }
            else {
                parallelFor([&] (int t, int start, int end) {
                    for (int i = start; i < end; i++) {
                        if (masses[i] != 0.0)
                            for (int j = 0; j < 3; j++)
                                vel[i][j] = vel[i][j] + cdt*f[i][j]/masses[i];
                        if (fuse)
                            driftAtom(i, cdtDrift);
                    }
                });
            }
            if (fuse) {
                finishDrift(cdtDrift);
                s += 2;
            }
            else
                s += 1;
        }
        else {
            if (projectBefore(s))
                projectVelocities(pos, vel, tol, exact);
            parallelFor([&] (int t, int start, int end) {
                for (int i = start; i < end; i++)
                    driftAtom(i, cdt);
            });
            finishDrift(cdt);
            s += 1;
        }
    }
    if (hasConstraints)
        projectVelocities(pos, vel, tol, exact);
    if (thermostatAfter(integrator, stepIndex))
        thermostatEvent(integrator);

    // Record the first step that leaves a velocity NaN, infinite or beyond the blow-up speed (NaN fails every <=).
    if (blowUpStep == 0) {
        const double maxSpeed = integrator.getMaxSpeed();
        const double limit = (maxSpeed > 0 ? maxSpeed*maxSpeed : numeric_limits<double>::max());
        for (int i = 0; i < numParticles; i++)
            if (!(vel[i].dot(vel[i]) <= limit)) {
                blowUpStep = stepIndex;
                break;
            }
    }
    data.time += dt;
    data.stepCount++;
}

double ReferenceIntegrateSymPRKStepKernel::computeKineticEnergy(ContextImpl& context, const SymPRKIntegrator& integrator) {
    const vector<Vec3>& vel = *data.velocities;
    double energy = 0.0;
    for (int i = 0; i < numParticles; i++)
        if (masses[i] != 0.0)
            energy += masses[i]*vel[i].dot(vel[i]);
    return 0.5*energy;
}
