#ifndef REFERENCE_SYMPRK_KERNELS_H_
#define REFERENCE_SYMPRK_KERNELS_H_

#include "openmm/SymPRKKernels.h"
#include "ReferencePlatform.h"
#include <functional>
#include <map>
#include <vector>

namespace SymPRKPlugin {

/**
 * The SymPRKIntegrator step on the Reference platform, also serving the CPU platform (CpuPlatform derives
 * from ReferencePlatform and shares its PlatformData: positions, velocities, forces, the constraint
 * algorithms -- with the CPU's threaded SETTLE -- and the virtual sites).  Per-atom loops run on the
 * platform's thread pool when the system is large enough to pay for the hand-off.
 */
class ReferenceIntegrateSymPRKStepKernel : public IntegrateSymPRKStepKernel {
public:
    ReferenceIntegrateSymPRKStepKernel(std::string name, const OpenMM::Platform& platform, OpenMM::ReferencePlatform::PlatformData& data) :
            IntegrateSymPRKStepKernel(name, platform), data(data), blowUpStep(0) {
    }
    void initialize(const OpenMM::System& system, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan);
    void execute(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator, const SymPRKStepPlan& plan,
                 bool& forcesAreValid, long long stepIndex, bool nextStepFollows);
    double computeKineticEnergy(OpenMM::ContextImpl& context, const SymPRKIntegrator& integrator);
    bool energyEvaluationKeepsForces() const {
        return true;
    }
    long long getBlowUpStep(OpenMM::ContextImpl& context) {
        return blowUpStep;
    }
    void setBlowUpStep(OpenMM::ContextImpl& context, long long step) {
        blowUpStep = step;
    }
private:
    /** Mass-weighted sums over the particles with mass about their centre (the exact-momentum projections). */
    struct Moments {
        double mass;                // M (0: no particle with mass; nothing else is then computed)
        OpenMM::Vec3 centre;        // centre of mass
        OpenMM::Vec3 d, o;          // (sum m x^2, sum m y^2, sum m z^2), (sum m xy, sum m xz, sum m yz) about the centre
        OpenMM::Vec3 sum, moment;   // with vectors: sum vectors[i] and sum (x_i - centre) x vectors[i]
    };
    void parallelFor(const std::function<void(int, int, int)>& task);
    Moments computeMoments(const std::vector<OpenMM::Vec3>& pos, const std::vector<OpenMM::Vec3>* vectors);
    void computeProjection(const std::vector<OpenMM::Vec3>& pos, const std::vector<OpenMM::Vec3>& force);
    void removeRigidChange(const std::vector<OpenMM::Vec3>& pos, std::vector<OpenMM::Vec3>& vel, OpenMM::Vec3 dP, OpenMM::Vec3 dL);
    void projectVelocities(std::vector<OpenMM::Vec3>& pos, std::vector<OpenMM::Vec3>& vel, double tol, bool exact);
    const std::vector<OpenMM::Vec3>& kickForces(OpenMM::ContextImpl& context, const SymPRKStepPlan::Operation& kick,
                                                bool& forcesAreValid, int& evaluated);
    /** x_ref = x; x += c*dt*v for a particle with mass; x_unconstrained = x (x_ref, x_unconstrained: with constraints). */
    void driftAtom(int i, double cdt) {
        std::vector<OpenMM::Vec3>& pos = *data.positions;
        if (hasConstraints)
            xRef[i] = pos[i];
        if (masses[i] != 0.0)
            for (int j = 0; j < 3; j++)
                pos[i][j] = pos[i][j] + cdt*(*data.velocities)[i][j];
        if (hasConstraints)
            xUnconstrained[i] = pos[i];
    }
    void kick(const std::vector<OpenMM::Vec3>& f, double cdt, bool exact, const SymPRKStepPlan::Operation* drift, double dt);
    void finishDrift(double cdt, double tol, bool exact, bool& forcesAreValid);
    void thermostatEvent(const SymPRKIntegrator& integrator, double decay);
    void checkVelocities(const SymPRKIntegrator& integrator, long long stepIndex);
    OpenMM::ReferencePlatform::PlatformData& data;
    const OpenMM::System* system;
    std::vector<double> masses, inverseMasses;
    std::vector<OpenMM::Vec3> xRef, xUnconstrained, vBefore;
    std::vector<int> threadStart;
    bool hasConstraints, hasVirtualSites, useThreads;
    std::map<int, std::vector<OpenMM::Vec3> > groupForces;  // multiple time stepping: forces per group mask
    int numParticles;
    long long blowUpStep;
    // exact-momentum projection: centre of mass, acceleration of the centre of mass, angular acceleration
    OpenMM::Vec3 com, acm, alpha;
};

} // namespace SymPRKPlugin

#endif /*REFERENCE_SYMPRK_KERNELS_H_*/
