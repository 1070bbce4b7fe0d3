/* openmm_symprk native plugin: registers the Common SymPRKIntegrator kernel with the OpenCL platform. */

// The system's OpenCL C headers may be older than the wheel's opencl.hpp (Debian 12 ships the 2023.02
// headers): hide the provisional command-buffer extensions, which the plugin does not use, before
// opencl.hpp sees them.
#include <CL/opencl.h>
#undef cl_khr_command_buffer
#undef cl_khr_command_buffer_mutable_dispatch

#include "CommonSymPRKKernels.h"
#include "openmm/opencl/OpenCLContext.h"
#include "openmm/opencl/OpenCLPlatform.h"
#include "openmm/KernelFactory.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"

using namespace OpenMM;

namespace {

class OpenCLSymPRKKernelFactory : public KernelFactory {
public:
    KernelImpl* createKernelImpl(std::string name, const Platform& platform, ContextImpl& context) const {
        OpenCLContext& cl = *static_cast<OpenCLPlatform::PlatformData*>(context.getPlatformData())->contexts[0];
        if (name == IntegrateSymPRKStepKernel::Name())
            return new CommonIntegrateSymPRKStepKernel(name, platform, cl);
        throw OpenMMException("SymPRK OpenCL plugin: unknown kernel '"+name+"'");
    }
};

}

extern "C" void registerPlatforms() {
}

extern "C" void registerKernelFactories() {
    try {
        Platform& platform = Platform::getPlatformByName("OpenCL");
        platform.registerKernelFactory(IntegrateSymPRKStepKernel::Name(), new OpenCLSymPRKKernelFactory());
    }
    catch (...) {
        // No OpenCL platform in this process: nothing to register.
    }
}
