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
using namespace SymPRKPlugin;
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
        // with the ends placement's thermostat events around it
        vector<int> nvtKinds = kinds, nvtGroups = groups, nvtFlags = flags;
        vector<double> nvtCoefficients = coefficients;
        nvtKinds.insert(nvtKinds.begin(), SymPRKIntegrator::Thermostat);
        nvtKinds.push_back(SymPRKIntegrator::Thermostat);
        nvtCoefficients.insert(nvtCoefficients.begin(), 0.5);
        nvtCoefficients.push_back(0.5);
        nvtGroups.insert(nvtGroups.begin(), -1);
        nvtGroups.push_back(-1);
        nvtFlags.insert(nvtFlags.begin(), SymPRKIntegrator::FirstOfInterval);
        nvtFlags.push_back(SymPRKIntegrator::LastOfInterval);
        SymPRKIntegrator original(0.0015, nvtKinds, nvtCoefficients, nvtGroups, nvtFlags);
        original.setConstraintTolerance(3e-7);
        original.setIntegrationForceGroups(5);
        original.setExactMomentum(true);
        original.setMethodName("omelyan-2 with a twist");
        original.setMaxSpeed(250.0);
        original.setExpectedSystem(42, true);
        original.setThermostat(310.5, 0.25, 3, 120, true);
        original.setRandomNumberSeed(1234);

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
        CHECK_EQUAL(7, restored->getNumSubsteps());
        CHECK_EQUAL(2, restored->getSubstepForceGroups(3));
        CHECK_EQUAL((int) SymPRKIntegrator::LastOfInterval, restored->getSubstepFlags(6));
        CHECK_EQUAL(true, restored->hasThermostat());
        CHECK_EQUAL(original.getThermostatTemperature(), restored->getThermostatTemperature());
        CHECK_EQUAL(original.getCollisionTime(), restored->getCollisionTime());
        CHECK_EQUAL(3, restored->getThermostatInterval());
        CHECK_EQUAL(120, restored->getThermostatDof());
        CHECK_EQUAL(true, restored->getThermostatKeepsRotation());
        CHECK_EQUAL(1234, restored->getRandomNumberSeed());

        // The program signature covers the thermostat's settings but not its temperature; without a thermostat
        // it is what it was before the thermostat existed.
        SymPRKIntegrator plain(0.0015, kinds, coefficients, groups, flags), warmer(0.0015, kinds, coefficients, groups, flags);
        plain.setExactMomentum(true);
        warmer.setExactMomentum(true);
        warmer.setThermostat(400.0, 0.25, 3, 120, true);
        if (plain.getProgramSignature() == original.getProgramSignature()) {
            cerr << "the program signature ignores the thermostat" << endl;
            failures++;
        }
        CHECK_EQUAL(original.getProgramSignature(), warmer.getProgramSignature());
        warmer.setThermostatTemperature(250.0);
        CHECK_EQUAL(250.0, warmer.getThermostatTemperature());

        // XML written before the thermostat's events were sub-steps (a thermostat, no events: the ends placement was
        // implied) comes back with the ends placement's events, and the same program signature (checkpoints load)
        stringstream olderXml;
        XmlSerializer::serialize<Integrator>(&warmer, "Integrator", olderXml);
        unique_ptr<Integrator> older(XmlSerializer::deserialize<Integrator>(olderXml));
        SymPRKIntegrator* olderRestored = dynamic_cast<SymPRKIntegrator*>(older.get());
        CHECK_EQUAL(7, olderRestored->getNumSubsteps());
        for (int i = 0; i < 7; i++) {
            CHECK_EQUAL(nvtKinds[i], olderRestored->getSubstepKind(i));
            CHECK_EQUAL(nvtCoefficients[i], olderRestored->getSubstepCoefficient(i));
            CHECK_EQUAL(nvtGroups[i], olderRestored->getSubstepForceGroups(i));
            CHECK_EQUAL(nvtFlags[i], olderRestored->getSubstepFlags(i));
        }
        CHECK_EQUAL(warmer.getProgramSignature(), olderRestored->getProgramSignature());

        // XML of serialization version 2 (before the thermostat: no seed, no Thermostat node) still loads.
        stringstream plainXml;
        XmlSerializer::serialize<Integrator>(&plain, "Integrator", plainXml);
        string text = plainXml.str();
        size_t at = text.find("version=\"3\"");
        size_t seed = text.find(" randomSeed=\"0\"");
        if (at == string::npos || seed == string::npos || text.find("Thermostat") != string::npos) {
            cerr << "unexpected XML of an integrator without a thermostat:\n" << text << endl;
            return 1;
        }
        text.erase(seed, string(" randomSeed=\"0\"").size());
        text.replace(text.find("version=\"3\""), 11, "version=\"2\"");
        stringstream version2(text);
        unique_ptr<Integrator> old(XmlSerializer::deserialize<Integrator>(version2));
        SymPRKIntegrator* oldRestored = dynamic_cast<SymPRKIntegrator*>(old.get());
        if (oldRestored == NULL) {
            cerr << "version-2 XML did not come back as a SymPRKIntegrator" << endl;
            return 1;
        }
        CHECK_EQUAL(false, oldRestored->hasThermostat());
        CHECK_EQUAL(0, oldRestored->getRandomNumberSeed());
        CHECK_EQUAL(plain.getProgramSignature(), oldRestored->getProgramSignature());
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
