/* openmm_symprk native plugin: XML serialization of SymPRKIntegrator. */

#include "openmm/serialization/SymPRKIntegratorProxy.h"
#include "openmm/serialization/SerializationNode.h"
#include "openmm/SymPRKIntegrator.h"
#include "openmm/OpenMMException.h"
#include <string>
#include <typeinfo>
#include <vector>

using namespace SymPRKPlugin;
using namespace OpenMM;
using namespace std;

SymPRKIntegratorProxy::SymPRKIntegratorProxy() : SerializationProxy("SymPRKIntegrator") {
}

void SymPRKIntegratorProxy::serialize(const void* object, SerializationNode& node) const {
    const SymPRKIntegrator& integrator = *reinterpret_cast<const SymPRKIntegrator*>(object);
    // 2: every sub-step carries its flags; 3: the thermostat (and the seed), and its events among the sub-steps
    // (read back from an older version 3 that has a thermostat and no events: the ends placement's are added)
    node.setIntProperty("version", 3);
    node.setDoubleProperty("stepSize", integrator.getStepSize());
    node.setDoubleProperty("constraintTolerance", integrator.getConstraintTolerance());
    node.setIntProperty("integrationForceGroups", integrator.getIntegrationForceGroups());
    node.setBoolProperty("exactMomentum", integrator.getExactMomentum());
    node.setStringProperty("method", integrator.getMethodName());
    node.setDoubleProperty("maxSpeed", integrator.getMaxSpeed());
    node.setIntProperty("expectedParticles", integrator.getExpectedNumParticles());
    node.setBoolProperty("expectedConstraints", integrator.getExpectedConstraints());
    node.setIntProperty("randomSeed", integrator.getRandomNumberSeed());
    if (integrator.hasThermostat()) {
        SerializationNode& bath = node.createChildNode("Thermostat");
        bath.setDoubleProperty("temperature", integrator.getThermostatTemperature());
        bath.setDoubleProperty("collisionTime", integrator.getCollisionTime());
        bath.setIntProperty("interval", integrator.getThermostatInterval());
        bath.setIntProperty("dof", integrator.getThermostatDof());
        bath.setBoolProperty("keepRotation", integrator.getThermostatKeepsRotation());
    }
    SerializationNode& substeps = node.createChildNode("Substeps");
    for (int i = 0; i < integrator.getNumSubsteps(); i++) {
        SerializationNode& s = substeps.createChildNode("Substep");
        const int kind = integrator.getSubstepKind(i);
        s.setStringProperty("kind", kind == SymPRKIntegrator::Kick ? "kick" : kind == SymPRKIntegrator::Drift ? "drift" : "thermostat");
        s.setDoubleProperty("c", integrator.getSubstepCoefficient(i));
        if (integrator.getSubstepForceGroups(i) != -1)
            s.setIntProperty("groups", integrator.getSubstepForceGroups(i));
        s.setIntProperty("flags", integrator.getSubstepFlags(i));
    }
}

void* SymPRKIntegratorProxy::deserialize(const SerializationNode& node) const {
    const int version = node.getIntProperty("version");
    if (version == 1)
        throw OpenMMException("SymPRKIntegrator: this XML was written by an older openmm_symprk (serialization version 1, "
                "sub-steps without their projection and cached-force flags) and cannot be read: create the integrator "
                "again (openmm_symprk.SymplecticIntegrator with the same method and options) and serialize it anew");
    if (version != 2 && version != 3)
        throw OpenMMException("SymPRKIntegrator: unsupported serialization version "+to_string(version)+" (this build reads 2 and 3)");
    vector<int> kinds, groups, flags;
    vector<double> coefficients;
    for (const SerializationNode& s : node.getChildNode("Substeps").getChildren()) {
        string kind = s.getStringProperty("kind");
        if (kind == "kick")
            kinds.push_back(SymPRKIntegrator::Kick);
        else if (kind == "drift")
            kinds.push_back(SymPRKIntegrator::Drift);
        else if (kind == "thermostat")
            kinds.push_back(SymPRKIntegrator::Thermostat);
        else
            throw OpenMMException("SymPRKIntegrator: unknown sub-step kind '"+kind+"' in XML");
        coefficients.push_back(s.getDoubleProperty("c"));
        groups.push_back(s.getIntProperty("groups", -1));
        flags.push_back(s.getIntProperty("flags"));
    }
    // An integrator with a thermostat written before the thermostat's events were sub-steps holds none (its events
    // were the ends placement's, implied): give it those, a half event before the sequence and one after it.
    bool thermostat = false, events = false;
    for (const SerializationNode& child : node.getChildren())
        thermostat = thermostat || (child.getName() == "Thermostat");
    for (int kind : kinds)
        events = events || (kind == SymPRKIntegrator::Thermostat);
    if (thermostat && !events) {
        kinds.insert(kinds.begin(), SymPRKIntegrator::Thermostat);
        coefficients.insert(coefficients.begin(), 0.5);
        groups.insert(groups.begin(), -1);
        flags.insert(flags.begin(), SymPRKIntegrator::FirstOfInterval);
        kinds.push_back(SymPRKIntegrator::Thermostat);
        coefficients.push_back(0.5);
        groups.push_back(-1);
        flags.push_back(SymPRKIntegrator::LastOfInterval);
    }
    SymPRKIntegrator* integrator = new SymPRKIntegrator(node.getDoubleProperty("stepSize"), kinds, coefficients, groups, flags);
    integrator->setConstraintTolerance(node.getDoubleProperty("constraintTolerance"));
    integrator->setIntegrationForceGroups(node.getIntProperty("integrationForceGroups", 0xFFFFFFFF));
    integrator->setExactMomentum(node.getBoolProperty("exactMomentum", false));
    integrator->setMethodName(node.getStringProperty("method", ""));
    integrator->setMaxSpeed(node.getDoubleProperty("maxSpeed", 0.0));
    integrator->setExpectedSystem(node.getIntProperty("expectedParticles", -1), node.getBoolProperty("expectedConstraints", false));
    // version 3: the random seed, and the thermostat when there is one (version 2 has neither)
    integrator->setRandomNumberSeed(node.getIntProperty("randomSeed", 0));
    for (const SerializationNode& child : node.getChildren())
        if (child.getName() == "Thermostat")
            integrator->setThermostat(child.getDoubleProperty("temperature"), child.getDoubleProperty("collisionTime"),
                                      child.getIntProperty("interval"), child.getIntProperty("dof"),
                                      child.getBoolProperty("keepRotation"));
    return integrator;
}

#if defined(WIN32)
    extern "C" __declspec(dllexport) void registerSymPRKSerializationProxies();
#else
    extern "C" void __attribute__((constructor)) registerSymPRKSerializationProxies();
#endif

extern "C" void registerSymPRKSerializationProxies() {
    SerializationProxy::registerProxy(typeid(SymPRKIntegrator), new SymPRKIntegratorProxy());
}
