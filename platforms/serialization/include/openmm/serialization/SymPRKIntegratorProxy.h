#ifndef OPENMM_SYMPRK_INTEGRATOR_PROXY_H_
#define OPENMM_SYMPRK_INTEGRATOR_PROXY_H_

#include "openmm/serialization/SerializationProxy.h"

namespace SymPRKPlugin {

/** XmlSerializer support for SymPRKIntegrator (registered when libOpenMMSymPRK is loaded), under the type name
 *  "SymPRKIntegrator". */
class SymPRKIntegratorProxy : public OpenMM::SerializationProxy {
public:
    SymPRKIntegratorProxy();
    void serialize(const void* object, OpenMM::SerializationNode& node) const;
    void* deserialize(const OpenMM::SerializationNode& node) const;
};

} // namespace SymPRKPlugin

#endif /*OPENMM_SYMPRK_INTEGRATOR_PROXY_H_*/
