/* openmm_symprk native plugin: the step plan (SymPRKStepPlan) of an r-RESPA sequence with constraints and the
 * thermostat every third step, and the Reference kernel executing exactly it.
 *
 * Three particles: 0-1 joined by a distance constraint, 1-2 by a harmonic bond in force group 1 (slow), and a
 * harmonic well on every particle in group 0 (fast).  The sequence (verlet outside, verlet inside, two inner
 * steps; the middle inner drift flagged ProjectVelocitiesBefore to have one such projection):
 *   kick g1 1/2 (cached), kick g0 1/4 (cached), drift 1/2, kick g0 1/2, [project] drift 1/2, kick g0 1/4, kick g1 1/2
 * The plan must state: a half event at phase 0, the seven sub-steps with a projection before the second drift,
 * the end-of-step projection, a half event at phase 2 (the last of the interval), the blow-up check after the
 * last kick, group copies (two masks).  The kernel must run exactly those operations, the events in their steps
 * only, and evaluate g1 once and g0 twice per step once the first step has filled the caches.  A second
 * integrator checks that a kick of -1 is planned with the integration force groups. */

#include "openmm/Context.h"
#include "openmm/CustomExternalForce.h"
#include "openmm/HarmonicBondForce.h"
#include "openmm/OpenMMException.h"
#include "openmm/Platform.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/System.h"
#include "openmm/Vec3.h"
#include <iostream>
#include <string>
#include <vector>

extern "C" void registerKernelFactories();  // the Reference kernel library's plugin entry point

using namespace OpenMM;
using namespace SymPRKPlugin;
using namespace std;

static int failures = 0;

static void expect(bool ok, const string& what) {
    if (!ok) {
        cerr << "FAILED: " << what << endl;
        failures++;
    }
}

int main() {
    try {
        registerKernelFactories();
        System system;
        for (double m : {12.0, 1.0, 16.0})
            system.addParticle(m);
        system.addConstraint(0, 1, 0.1);
        HarmonicBondForce* bond = new HarmonicBondForce();
        bond->addBond(1, 2, 0.12, 2000.0);
        bond->setForceGroup(1);
        system.addForce(bond);
        CustomExternalForce* well = new CustomExternalForce("50*(x^2+y^2+z^2)");
        for (int i = 0; i < 3; i++)
            well->addParticle(i);
        well->setForceGroup(0);
        system.addForce(well);

        const int K = SymPRKIntegrator::Kick, D = SymPRKIntegrator::Drift, T = SymPRKIntegrator::Thermostat;
        const int cached = SymPRKIntegrator::ForcesCached, project = SymPRKIntegrator::ProjectVelocitiesBefore;
        const int first = SymPRKIntegrator::FirstOfInterval, last = SymPRKIntegrator::LastOfInterval;
        // the ends placement: a half event before the sequence (first step of every interval) and one after it (last)
        SymPRKIntegrator integrator(0.001, {T, K, K, D, K, D, K, K, T}, {0.5, 0.5, 0.25, 0.5, 0.5, 0.5, 0.25, 0.5, 0.5},
                                    {-1, 2, 1, -1, 1, -1, 1, 2, -1}, {first, cached, cached, 0, 0, project, 0, 0, last});
        integrator.setThermostat(300.0, 0.1, 3, 3*3-1-3, false);
        integrator.setRandomNumberSeed(5);
        Context context(system, integrator, Platform::getPlatformByName("Reference"));
        context.setPositions({Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.2, 0.05, 0)});
        context.setVelocities({Vec3(0.1, 0.2, -0.1), Vec3(-0.3, 0.1, 0.2), Vec3(0.05, -0.2, 0.1)});

        const vector<string> expected = {
            "thermostat substep=0 c=0.5 phase=0/3",
            "kick substep=1 c=0.5 groups=0x2 reuse copy",
            "kick substep=2 c=0.25 groups=0x1 reuse copy",
            "drift substep=3 c=0.5",
            "kick substep=4 c=0.5 groups=0x1 copy",
            "project substep=5",
            "drift substep=5 c=0.5",
            "kick substep=6 c=0.25 groups=0x1 copy",
            "kick substep=7 c=0.5 groups=0x2 copy check",
            "project",
            "thermostat substep=8 c=0.5 phase=2/3"};
        const vector<string> plan = integrator.getStepPlan();
        expect(plan == expected, "the plan of the r-RESPA sequence");
        if (plan != expected)
            for (const string& line : plan)
                cerr << "  " << line << endl;

        // the kernel runs the plan, the events in the steps of their phase only
        const int steps = 6;
        integrator.setExecutionTraceEnabled(true);
        integrator.step(steps);
        const vector<int> trace = integrator.getExecutionTrace();
        size_t at = 0;
        for (int step = 1; step <= steps; step++) {
            int slow = 0, fast = 0;
            for (int op = 0; op < (int) expected.size(); op++) {
                const bool event = (expected[op].rfind("thermostat", 0) == 0);
                if (event && (step-1) % 3 != (op == 0 ? 0 : 2))
                    continue;
                const bool ran = (at+2 < trace.size() && trace[at] == step && trace[at+1] == op);
                expect(ran, "step " + to_string(step) + " runs operation " + to_string(op) + " (" + expected[op] + ")");
                if (!ran)
                    return 1;
                slow += (trace[at+2] == 2);
                fast += (trace[at+2] == 1);
                expect(trace[at+2] == 0 || expected[op].rfind("kick", 0) == 0, "only kicks evaluate forces");
                at += 3;
            }
            if (step > 1)
                expect(slow == 1 && fast == 2, "step " + to_string(step) + ": g1 evaluated " + to_string(slow) + " times, g0 " +
                       to_string(fast) + " times (expected 1 and 2)");
        }
        expect(at == trace.size(), "nothing runs beyond the plan");
        expect(integrator.getForceEvaluationsPerStep() == 3, "three evaluations per step");

        // a kick of -1 is planned with the integration force groups
        SymPRKIntegrator verlet(0.001);
        verlet.setIntegrationForceGroups(1 << 1);
        Context context2(system, verlet, Platform::getPlatformByName("Reference"));
        const vector<string> verletPlan = verlet.getStepPlan();
        expect(verletPlan == vector<string>({"kick substep=0 c=0.5 groups=0x2 reuse", "drift substep=1 c=1",
                                             "kick substep=2 c=0.5 groups=0x2 check", "project"}),
               "velocity Verlet's plan with the integration force groups {1}");

        // the middle placement: the Thermostat sub-step between the drift's halves is the only event, in the middle
        // step of each interval of 3 (phase 1), with c = exp(-1*3*dt/tau); no ends events
        SymPRKIntegrator middle(0.001, {K, D, T, D, K}, {0.5, 0.5, 1.0, 0.5, 0.5}, {-1, -1, -1, -1, -1}, {cached, 0, 0, 0, 0});
        middle.setThermostat(300.0, 0.1, 3, 3*3-1-3, false);
        Context context3(system, middle, Platform::getPlatformByName("Reference"));
        context3.setPositions({Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.2, 0.05, 0)});
        context3.setVelocities({Vec3(0.1, 0.2, -0.1), Vec3(-0.3, 0.1, 0.2), Vec3(0.05, -0.2, 0.1)});
        const vector<string> middlePlan = {"kick substep=0 c=0.5 groups=0xffffffff reuse", "drift substep=1 c=0.5",
                                           "thermostat substep=2 c=1 phase=1/3", "drift substep=3 c=0.5",
                                           "kick substep=4 c=0.5 groups=0xffffffff check", "project"};
        expect(middle.getStepPlan() == middlePlan, "the plan of the middle placement");
        middle.setExecutionTraceEnabled(true);
        middle.step(7);
        vector<int> eventSteps;
        const vector<int> middleTrace = middle.getExecutionTrace();
        for (size_t i = 0; i < middleTrace.size(); i += 3)
            if (middleTrace[i+1] == 2)
                eventSteps.push_back(middleTrace[i]);
        expect(eventSteps == vector<int>({2, 5}), "the middle events run in steps 2 and 5 of 7");
        expect(middle.getHeatBathEnergy() != 0.0, "the middle events exchange heat");

        // a Thermostat sub-step needs a thermostat
        SymPRKIntegrator bare(0.001, {K, D, T, D, K}, {0.5, 0.5, 1.0, 0.5, 0.5}, {-1, -1, -1, -1, -1}, {cached, 0, 0, 0, 0});
        bool refused = false;
        try {
            Context context4(system, bare, Platform::getPlatformByName("Reference"));
        }
        catch (const OpenMMException& e) {
            refused = (string(e.what()).find("the sequence has thermostat events, but the integrator has no thermostat") != string::npos);
        }
        expect(refused, "a Thermostat sub-step without a thermostat is refused when the Context is created");

        // a thermostat without events in the sequence: refused, saying where the ends placement's events go
        SymPRKIntegrator eventless(0.001);
        eventless.setThermostat(300.0, 0.1, 1, 3*3-1-3, false);
        refused = false;
        try {
            Context context5(system, eventless, Platform::getPlatformByName("Reference"));
        }
        catch (const OpenMMException& e) {
            refused = (string(e.what()).find("its sequence has no thermostat event") != string::npos);
        }
        expect(refused, "a thermostat without Thermostat sub-steps is refused when the Context is created");
    }
    catch (const exception& e) {
        cerr << "exception: " << e.what() << endl;
        return 1;
    }
    if (failures > 0)
        return 1;
    cout << "Done" << endl;
    return 0;
}
