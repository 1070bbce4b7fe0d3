#ifndef OPENMM_SYMPRK_THERMOSTAT_H_
#define OPENMM_SYMPRK_THERMOSTAT_H_

/* openmm_symprk native plugin: the host side of a thermostat event (the Reference/CPU kernel's; the Common
 * kernel runs the same operations on the device, symprkThermostatEvent in common/src/kernels/symprk.cc).
 *
 * Stochastic velocity rescaling (Bussi, Donadio and Parrinello, J. Chem. Phys. 126, 014101, 2007) of the
 * peculiar velocities.  A kernel reduces the particles with mass to the Sums below in two passes -- the centre
 * of mass first, then the moments about it, so that nothing cancels far from the origin -- and event() turns
 * them into the kept velocity field u_i = V + w x (x_i - R) and the factor alpha; the kernel then sets
 * v_i <- u_i + alpha (v_i - u_i) for every particle with mass.  Random numbers are drawn here from a
 * std::mt19937_64 whose state is the whole random state (the distributions are created afresh for every
 * event), so a checkpoint holding it continues bit for bit.  The expression for alpha is
 * openmm_symprk.physics.velocity_rescaling.rescaling_factor, operation for operation.
 */

#include "openmm/Vec3.h"
#include "openmm/internal/windowsExportSymPRK.h"
#include <random>
#include <string>

namespace SymPRKPlugin {

class OPENMM_EXPORT_SYMPRK SymPRKThermostat {
public:
    /** What a kernel sums over the particles with mass m > 0 (positions x, velocities v). */
    struct Sums {
        double mass;              // M = sum m
        OpenMM::Vec3 centre;      // R, the centre of mass (first pass)
        OpenMM::Vec3 momentum;    // P = sum m v
        double twiceKinetic;      // sum m v.v
        double twicePeculiar;     // sum m |v - P/M|^2 (second pass)
        OpenMM::Vec3 d, o;        // rotation kept: (sum m rx^2, ry^2, rz^2), (sum m rx ry, rx rz, ry rz), r = x - R
        OpenMM::Vec3 angular;     // rotation kept: L = sum m r x v about R
    };
    /** What a kernel applies: v <- u + alpha (v - u), u = velocity + omega x (x - centre), particles with mass only. */
    struct Event {
        bool apply;            // false: nothing to do (no mass, no peculiar motion, or a non-finite sum)
        double alpha;
        OpenMM::Vec3 velocity, centre, omega;  // omega = 0 unless the rotation is kept
        double kinetic, newKinetic;    // peculiar kinetic energy before and after (kJ/mol)
    };
    /**
     * What an event leaves behind for the integrator to report, per Context (kept in checkpoints): the heat-bath
     * energy (kJ/mol, minus the kinetic energy the events added), the total and the peculiar kinetic energy just after
     * the last event (0 before the first; the peculiar one is what the thermostat's temperature is made of), the events
     * skipped for want of peculiar kinetic energy, and whether the last event was one.
     */
    struct RunState {
        double heatBathEnergy = 0.0, kineticEnergy = 0.0, peculiarKineticEnergy = 0.0;
        long long skippedEvents = 0;
        bool lastSkipped = false;
    };
    /** The fraction of the total kinetic energy at or below which the peculiar part counts as none (round-off). */
    static double negligiblePeculiarFraction() {
        return 1e-10;
    }
    SymPRKThermostat();
    /** Seed the generator (0: a seed from std::random_device) and zero the heat-bath energy and the counters. */
    void initialize(int seed);
    /**
     * One event with relaxation factor c = exp(-t/tau) for a target temperature (K), the degrees of freedom and
     * whether the rotation is kept: draws r1 ~ N(0,1) and chi2 ~ chi^2(dof-1), and subtracts K' - K_pec from the
     * heat-bath energy.  A (nearly) singular inertia tensor is regularised (solveInertia).  Where K_pec is at most
     * negligiblePeculiarFraction() of the total kinetic energy nothing is applied and the event is counted as
     * skipped (the noise is drawn all the same: one draw per event).
     */
    Event event(const Sums& sums, double temperature, int dof, bool keepRotation, double c);
    /**
     * The noise of one event, as event() draws it: r1 ~ N(0,1), then chi2 ~ chi^2(dof-1) (0 for dof = 1), from the
     * generator in that order (a fresh distribution per call, so the generator's state is the whole random state).
     */
    void drawNoise(int dof, double& r1, double& chi2);
    const RunState& getRunState() const {
        return run;
    }
    void setRunState(const RunState& state) {
        run = state;
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
    RunState run;
};

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_THERMOSTAT_H_*/
