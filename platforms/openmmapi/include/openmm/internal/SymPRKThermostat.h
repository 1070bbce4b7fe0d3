#ifndef OPENMM_SYMPRK_THERMOSTAT_H_
#define OPENMM_SYMPRK_THERMOSTAT_H_

/* openmm_symprk native plugin: the host side of a thermostat event, shared by every kernel.
 *
 * Stochastic velocity rescaling (Bussi, Donadio and Parrinello, J. Chem. Phys. 126, 014101, 2007) of the
 * peculiar velocities.  A kernel reduces the particles' velocities (and, when the rotation is kept, their
 * positions) to the NumSums sums below, over particles with mass; event() turns them into the kept velocity
 * field u_i = V + w x (x_i - R) and the factor alpha, and the kernel then sets v_i <- u_i + alpha (v_i - u_i)
 * for every particle with mass.  Random numbers are drawn here, on the host, from a std::mt19937_64 whose
 * state is the whole random state (the distributions are created afresh for every event), so a checkpoint
 * holding it continues bit for bit.  The expression for alpha is
 * openmm_symprk.physics.velocity_rescaling.rescaling_factor, operation for operation.
 */

#include "openmm/Vec3.h"
#include "openmm/internal/windowsExportSymPRK.h"
#include <random>
#include <string>

namespace SymPRKPlugin {

class OPENMM_EXPORT_SYMPRK SymPRKThermostat {
public:
    /** Layout of the sums a kernel provides (all over particles with mass m > 0; positions x, velocities v). */
    enum SumIndex {
        SumMass = 0,         // M = sum m
        SumMomentX = 1,      // sum m x (3: x, y, z)
        SumMomentum = 4,     // P = sum m v (3)
        SumTwiceKinetic = 7, // sum m v.v
        SumSecond = 8,       // sum m x x^T about the origin (6: xx, xy, xz, yy, yz, zz)
        SumAngular = 14,     // L = sum m x cross v about the origin (3)
        NumSums = 17
    };
    /** What a kernel applies: v <- u + alpha (v - u), u = velocity + omega x (x - centre), particles with mass only. */
    struct Event {
        bool apply;            // false: nothing to do (no mass, no peculiar motion, or a non-finite sum)
        double alpha;
        OpenMM::Vec3 velocity, centre, omega;  // omega = 0 unless the rotation is kept
        double kinetic, newKinetic;    // peculiar kinetic energy before and after (kJ/mol)
    };
    SymPRKThermostat();
    /** Seed the generator (0: a seed from std::random_device) and zero the heat-bath energy. */
    void initialize(int seed);
    /**
     * One event with relaxation factor c = exp(-t/tau) for a target temperature (K), the degrees of freedom and
     * whether the rotation is kept: draws r1 ~ N(0,1) and chi2 ~ chi^2(dof-1), and subtracts K' - K_pec from the
     * heat-bath energy.  A (nearly) singular inertia tensor is regularised by 1e-12 of its trace (solveInertia).
     */
    Event event(const double* sums, double temperature, int dof, bool keepRotation, double c);
    double getHeatBathEnergy() const {
        return heatBathEnergy;
    }
    void setHeatBathEnergy(double energy) {
        heatBathEnergy = energy;
    }
    /** The generator's state as text (std::mt19937_64's operator<<), and back. */
    std::string getRandomState() const;
    void setRandomState(const std::string& state);
    /**
     * (alpha, K') for the peculiar kinetic energy `kinetic`, the target N_f kT/2, c, a standard normal r1 and a
     * chi-squared variable chi2 of dof-1 degrees of freedom; K' is written to newKinetic.
     */
    static double rescalingFactor(double kinetic, double target, int dof, double c, double r1, double chi2, double& newKinetic);
    /** Boltzmann's constant in kJ/mol/K, OpenMM's value. */
    static double boltzmann();
private:
    std::mt19937_64 rng;
    double heatBathEnergy;
};

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_THERMOSTAT_H_*/
