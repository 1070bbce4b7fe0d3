#ifndef OPENMM_SYMPRK_INTEGRATOR_PROXY_H_
#define OPENMM_SYMPRK_INTEGRATOR_PROXY_H_

#include "openmm/serialization/SerializationProxy.h"

namespace OpenMM {

/** XmlSerializer support for SymPRKIntegrator (registered when libOpenMMSymPRK is loaded). */
class SymPRKIntegratorProxy : public SerializationProxy {
public:
    SymPRKIntegratorProxy();
    void serialize(const void* object, SerializationNode& node) const;
    void* deserialize(const SerializationNode& node) const;
};

} // namespace OpenMM

#endif /*OPENMM_SYMPRK_INTEGRATOR_PROXY_H_*/
