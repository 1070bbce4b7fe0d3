/* openmm_symprk native plugin: the Reference (and CPU) SymPRKIntegrator kernel.
 *
 * It runs the operations of the step plan (SymPRKStepPlan) in order.  Arithmetic follows the CustomIntegrator
 * program of openmm_symprk/integrators/program.py operation by operation, so that on Reference both give the
 * same trajectory to round-off:
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
#include "openmm/internal/SymPRKInertia.h"
#include "openmm/internal/ThreadPool.h"
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

using namespace SymPRKPlugin;
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

void ReferenceIntegrateSymPRKStepKernel::initialize(const System& sys, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan) {
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
    hasConstraints = plan.hasConstraints();
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

ReferenceIntegrateSymPRKStepKernel::Moments ReferenceIntegrateSymPRKStepKernel::computeMoments(const vector<Vec3>& pos,
        const vector<Vec3>* vectors) {
    // Sums in double, in a fixed order (per-chunk partial sums added in chunk order): deterministic.  Two passes:
    // the mass, centre of mass (and the vectors' sum), then the second moments (and the vectors' moment) about it.
    int chunks = threadStart.size()-1;
    vector<double> mass(chunks, 0.0);
    vector<Vec3> mx(chunks), vsum(chunks);
    parallelFor([&] (int t, int start, int end) {
        double m = 0;
        Vec3 a, b;
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0) {
                m += masses[i];
                a += pos[i]*masses[i];
                if (vectors != NULL)
                    b += (*vectors)[i];
            }
        mass[t] = m;
        mx[t] = a;
        vsum[t] = b;
    });
    Moments result;
    result.mass = 0;
    Vec3 moment;
    for (int t = 0; t < chunks; t++) {
        result.mass += mass[t];
        moment += mx[t];
        result.sum += vsum[t];
    }
    if (result.mass == 0.0)
        return result;
    const Vec3 c = result.centre = moment/result.mass;
    vector<Vec3> vmoment(chunks), diag(chunks), offdiag(chunks);
    parallelFor([&] (int t, int start, int end) {
        Vec3 tau, d, o;
        for (int i = start; i < end; i++)
            if (masses[i] != 0.0) {
                Vec3 r = pos[i]-c;
                if (vectors != NULL)
                    tau += r.cross((*vectors)[i]);
                double m = masses[i];
                d += Vec3(m*r[0]*r[0], m*r[1]*r[1], m*r[2]*r[2]);
                o += Vec3(m*r[0]*r[1], m*r[0]*r[2], m*r[1]*r[2]);
            }
        vmoment[t] = tau;
        diag[t] = d;
        offdiag[t] = o;
    });
    for (int t = 0; t < chunks; t++) {
        result.moment += vmoment[t];
        result.d += diag[t];
        result.o += offdiag[t];
    }
    return result;
}

void ReferenceIntegrateSymPRKStepKernel::computeProjection(const vector<Vec3>& pos, const vector<Vec3>& force) {
    // The exact-momentum kick: the acceleration of the centre of mass and the angular acceleration about it
    // (the inertia tensor regularised by 1e-12 of its trace).
    const Moments m = computeMoments(pos, &force);
    if (m.mass == 0.0) {
        com = acm = alpha = Vec3();
        return;
    }
    com = m.centre;
    acm = m.sum/m.mass;
    alpha = solveInertia(m.d, m.o, m.moment);
}

void ReferenceIntegrateSymPRKStepKernel::thermostatEvent(const SymPRKIntegrator& integrator, double decay) {
    // The sums in double, serially in particle order (deterministic, whatever the thread count), in two passes: the
    // centre of mass (about the first particle with mass, so that nothing cancels far from the origin) and the
    // momentum, then the moments about the centre of mass; the host computes the kept field and the factor
    // (SymPRKThermostat), then every particle with mass is rescaled.
    const vector<Vec3>& pos = *data.positions;
    vector<Vec3>& vel = *data.velocities;
    const bool rotation = integrator.getThermostatKeepsRotation();
    SymPRKThermostat::Sums sums;
    sums.mass = sums.twiceKinetic = sums.twicePeculiar = 0.0;
    Vec3 origin, moment;
    bool first = true;
    for (int i = 0; i < numParticles; i++) {
        const double m = masses[i];
        if (m == 0.0)
            continue;
        if (first) {
            origin = pos[i];
            first = false;
        }
        const Vec3& v = vel[i];
        sums.mass += m;
        moment += (pos[i]-origin)*m;
        sums.momentum += v*m;
        sums.twiceKinetic += m*v.dot(v);
    }
    if (sums.mass > 0) {
        const Vec3 R = sums.centre = origin+moment/sums.mass;
        const Vec3 V = sums.momentum/sums.mass;
        for (int i = 0; i < numParticles; i++) {
            const double m = masses[i];
            if (m == 0.0)
                continue;
            const Vec3 u = vel[i]-V;
            sums.twicePeculiar += m*u.dot(u);
            if (rotation) {
                const Vec3 r = pos[i]-R;
                sums.d += Vec3(m*r[0]*r[0], m*r[1]*r[1], m*r[2]*r[2]);
                sums.o += Vec3(m*r[0]*r[1], m*r[0]*r[2], m*r[1]*r[2]);
                sums.angular += r.cross(u)*m;
            }
        }
    }
    const SymPRKThermostat::Event e = thermostat.event(sums, integrator.getThermostatTemperature(), integrator.getThermostatDof(),
                                                       rotation, decay);
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
    const Moments m = computeMoments(pos, NULL);
    if (m.mass == 0.0)
        return;
    const Vec3 c = m.centre;
    Vec3 w = -dP/m.mass;
    Vec3 gamma = solveInertia(m.d, m.o, c.cross(dP)-dL);
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

const vector<Vec3>& ReferenceIntegrateSymPRKStepKernel::kickForces(ContextImpl& context, const SymPRKStepPlan::Operation& op,
        bool& forcesAreValid, int& evaluated) {
    // The forces of this kick's groups: computed unless the plan lets it reuse cached forces and they are still
    // valid.  A multiple-time-step method keeps a copy per group, so that a group is evaluated only where a
    // drift came between two of its kicks.
    evaluated = 0;
    if (op.reuseForces) {
        auto cached = groupForces.find(op.forceGroups);
        if (cached != groupForces.end())
            return cached->second;
    }
    if (mustEvaluateForces(op, forcesAreValid, context)) {
        context.calcForcesAndEnergy(true, false, op.forceGroups);
        forcesAreValid = true;
        evaluated = op.forceGroups;
    }
    if (op.keepGroupCopy)
        return groupForces[op.forceGroups] = *data.forces;
    return *data.forces;
}

void ReferenceIntegrateSymPRKStepKernel::kick(const vector<Vec3>& f, double cdt, bool exact, const SymPRKStepPlan::Operation* drift,
        double dt) {
    // One pass over the atoms: the kick, and the drift after it when one is given (the per-atom arithmetic is the
    // same as in two passes).
    vector<Vec3>& pos = *data.positions;
    vector<Vec3>& vel = *data.velocities;
    const bool fuse = (drift != NULL);
    const double cdtDrift = (fuse ? drift->coefficient*dt : 0.0);
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
}

void ReferenceIntegrateSymPRKStepKernel::finishDrift(double cdt, double tol, bool exact, bool& forcesAreValid) {
    // RATTLE: constrain the positions against the pre-drift ones, v += (x - x_unconstrained)/(c*dt); then the
    // virtual sites.  The forces no longer belong to the positions.
    vector<Vec3>& pos = *data.positions;
    vector<Vec3>& vel = *data.velocities;
    if (hasConstraints) {
        data.constraints->apply(xRef, pos, inverseMasses, tol);
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
        data.virtualSites->computePositions(*system, pos, data.periodicBoxVectors);
    forcesAreValid = false;
    groupForces.clear();
}

void ReferenceIntegrateSymPRKStepKernel::checkVelocities(const SymPRKIntegrator& integrator, long long stepIndex) {
    // Record the first step that leaves a velocity NaN, infinite or beyond the blow-up speed (NaN fails every <=).
    if (blowUpStep != 0)
        return;
    const vector<Vec3>& vel = *data.velocities;
    const double maxSpeed = integrator.getMaxSpeed();
    const double limit = (maxSpeed > 0 ? maxSpeed*maxSpeed : numeric_limits<double>::max());
    for (int i = 0; i < numParticles; i++)
        if (!(vel[i].dot(vel[i]) <= limit)) {
            blowUpStep = stepIndex;
            break;
        }
}

void ReferenceIntegrateSymPRKStepKernel::execute(ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
        bool& forcesAreValid, long long stepIndex, bool nextStepFollows) {
    // (nextStepFollows is ignored: this kernel is the plain reading of the plan, every step ends at the step point)
    const double dt = integrator.getStepSize();
    const double tol = integrator.getConstraintTolerance();
    const bool exact = integrator.getExactMomentum();
    if (context.updateContextState())
        forcesAreValid = false;
    if (!forcesAreValid)
        groupForces.clear();  // the cached forces of a multiple-time-step method belong to old positions
    const vector<SymPRKStepPlan::Operation>& ops = plan.getOperations();
    for (int k = 0; k < (int) ops.size(); k++) {
        const SymPRKStepPlan::Operation& op = ops[k];
        bool check = op.checkVelocities;
        switch (op.kind) {
        case SymPRKStepPlan::ThermostatEvent:
            if (!op.runsInStep(stepIndex))
                continue;
            thermostatEvent(integrator, op.decay(dt));
            trace.record(stepIndex, k, 0);
            break;
        case SymPRKStepPlan::Kick: {
            int evaluated;
            const vector<Vec3>& f = kickForces(context, op, forcesAreValid, evaluated);
            trace.record(stepIndex, k, evaluated);
            // the drift right after a kick shares its pass over the atoms
            const SymPRKStepPlan::Operation* drift = (op.driftFollows ? &ops[k+1] : NULL);
            kick(f, op.coefficient*dt, exact, drift, dt);
            if (drift != NULL) {
                k++;
                trace.record(stepIndex, k, 0);
                finishDrift(drift->coefficient*dt, tol, exact, forcesAreValid);
                check = check || drift->checkVelocities;
            }
            break;
        }
        case SymPRKStepPlan::Drift: {
            const double cdt = op.coefficient*dt;
            parallelFor([&] (int t, int start, int end) {
                for (int i = start; i < end; i++)
                    driftAtom(i, cdt);
            });
            trace.record(stepIndex, k, 0);
            finishDrift(cdt, tol, exact, forcesAreValid);
            break;
        }
        case SymPRKStepPlan::ProjectVelocities:
            projectVelocities(*data.positions, *data.velocities, tol, exact);
            trace.record(stepIndex, k, 0);
            break;
        }
        if (check)
            checkVelocities(integrator, stepIndex);
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
