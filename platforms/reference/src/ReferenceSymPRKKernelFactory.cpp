/* openmm_symprk native plugin: kernel factory for the Reference platform and every platform derived from it
 * (the CPU platform). */

#include "ReferenceSymPRKKernels.h"
#include "ReferencePlatform.h"
#include "openmm/KernelFactory.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"

using namespace SymPRKPlugin;
using namespace OpenMM;

namespace {

class ReferenceSymPRKKernelFactory : public KernelFactory {
public:
    KernelImpl* createKernelImpl(std::string name, const Platform& platform, ContextImpl& context) const {
        ReferencePlatform::PlatformData& data = *static_cast<ReferencePlatform::PlatformData*>(context.getPlatformData());
        if (name == IntegrateSymPRKStepKernel::Name())
            return new ReferenceIntegrateSymPRKStepKernel(name, platform, data);
        throw OpenMMException("SymPRK Reference plugin: unknown kernel '"+name+"'");
    }
};

}

extern "C" void registerPlatforms() {
}

extern "C" void registerKernelFactories() {
    for (int i = 0; i < Platform::getNumPlatforms(); i++) {
        Platform& platform = Platform::getPlatform(i);
        if (dynamic_cast<ReferencePlatform*>(&platform) != NULL)
            platform.registerKernelFactory(IntegrateSymPRKStepKernel::Name(), new ReferenceSymPRKKernelFactory());
    }
}
