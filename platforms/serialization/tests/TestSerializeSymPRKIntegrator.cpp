/* openmm_symprk native plugin: an XML round trip of SymPRKIntegrator keeps every setting. */

#include "openmm/SymPRKIntegrator.h"
#include "openmm/OpenMMException.h"
#include "openmm/serialization/XmlSerializer.h"
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

using namespace OpenMM;
using namespace std;

static int failures = 0;

#define CHECK_EQUAL(expected, found) do { \
        if (!((expected) == (found))) { \
            cerr << __FILE__ << ":" << __LINE__ << ": expected " << (expected) << ", found " << (found) << endl; \
            failures++; \
        } \
    } while (0)

int main() {
    try {
        // A composition with an MTS kick (force groups 2 = bit 1) and every option away from its default.
        vector<int> kinds = {SymPRKIntegrator::Kick, SymPRKIntegrator::Drift, SymPRKIntegrator::Kick,
                             SymPRKIntegrator::Drift, SymPRKIntegrator::Kick};
        vector<double> coefficients = {0.1931833275037836, 0.5, 0.6136333449924328, 0.5, 0.1931833275037836};
        vector<int> groups = {-1, -1, 2, -1, -1};
        vector<int> flags = {SymPRKIntegrator::ForcesCached, 0, 0, SymPRKIntegrator::ProjectVelocitiesBefore, 0};
        SymPRKIntegrator original(0.0015, kinds, coefficients, groups, flags);
        original.setConstraintTolerance(3e-7);
        original.setIntegrationForceGroups(5);
        original.setExactMomentum(true);
        original.setMethodName("omelyan-2 with a twist");
        original.setMaxSpeed(250.0);
        original.setExpectedSystem(42, true);

        stringstream buffer;
        XmlSerializer::serialize<Integrator>(&original, "Integrator", buffer);
        unique_ptr<Integrator> copy(XmlSerializer::deserialize<Integrator>(buffer));
        SymPRKIntegrator* restored = dynamic_cast<SymPRKIntegrator*>(copy.get());
        if (restored == NULL) {
            cerr << "the XML did not come back as a SymPRKIntegrator:\n" << buffer.str() << endl;
            return 1;
        }
        CHECK_EQUAL(original.getStepSize(), restored->getStepSize());
        CHECK_EQUAL(original.getConstraintTolerance(), restored->getConstraintTolerance());
        CHECK_EQUAL(original.getIntegrationForceGroups(), restored->getIntegrationForceGroups());
        CHECK_EQUAL(original.getExactMomentum(), restored->getExactMomentum());
        CHECK_EQUAL(original.getMethodName(), restored->getMethodName());
        CHECK_EQUAL(original.getMaxSpeed(), restored->getMaxSpeed());
        CHECK_EQUAL(original.getExpectedNumParticles(), restored->getExpectedNumParticles());
        CHECK_EQUAL(original.getExpectedConstraints(), restored->getExpectedConstraints());
        CHECK_EQUAL(original.getNumSubsteps(), restored->getNumSubsteps());
        CHECK_EQUAL(original.getForceEvaluationsPerStep(), restored->getForceEvaluationsPerStep());
        CHECK_EQUAL(original.getProgramSignature(), restored->getProgramSignature());
        for (int i = 0; i < min(original.getNumSubsteps(), restored->getNumSubsteps()); i++) {
            CHECK_EQUAL(original.getSubstepKind(i), restored->getSubstepKind(i));
            CHECK_EQUAL(original.getSubstepCoefficient(i), restored->getSubstepCoefficient(i));  // bit for bit
            CHECK_EQUAL(original.getSubstepForceGroups(i), restored->getSubstepForceGroups(i));
            CHECK_EQUAL(original.getSubstepFlags(i), restored->getSubstepFlags(i));
        }
        CHECK_EQUAL(5, restored->getNumSubsteps());
        CHECK_EQUAL(2, restored->getSubstepForceGroups(2));
    }
    catch (const exception& e) {
        cerr << "exception: " << e.what() << endl;
        return 1;
    }
    if (failures > 0) {
        cerr << failures << " check(s) failed" << endl;
        return 1;
    }
    cout << "Done" << endl;
    return 0;
}
