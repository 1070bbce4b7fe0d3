/* openmm_symprk native plugin: registers the Common SymPRKIntegrator kernel with the CUDA platform.
 *
 * Compiled wherever CMake finds the CUDA headers (cuda/CMakeLists.txt); never run on a machine of this project
 * yet (no GPU).  The kernel code is the same Common source as OpenCL's. */

#include "CommonSymPRKKernels.h"
#include "openmm/cuda/CudaContext.h"
#include "openmm/cuda/CudaPlatform.h"
#include "openmm/KernelFactory.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"

using namespace OpenMM;

namespace {

class CudaSymPRKKernelFactory : public KernelFactory {
public:
    KernelImpl* createKernelImpl(std::string name, const Platform& platform, ContextImpl& context) const {
        CudaContext& cu = *static_cast<CudaPlatform::PlatformData*>(context.getPlatformData())->contexts[0];
        if (name == IntegrateSymPRKStepKernel::Name())
            return new CommonIntegrateSymPRKStepKernel(name, platform, cu);
        throw OpenMMException("SymPRK CUDA plugin: unknown kernel '"+name+"'");
    }
};

}

extern "C" void registerPlatforms() {
}

extern "C" void registerKernelFactories() {
    try {
        Platform& platform = Platform::getPlatformByName("CUDA");
        platform.registerKernelFactory(IntegrateSymPRKStepKernel::Name(), new CudaSymPRKKernelFactory());
    }
    catch (...) {
    }
}
