/* openmm_symprk native plugin: registers the Common SymPRKIntegrator kernel with the OpenCL platform. */

// The system's OpenCL C headers may be older than the wheel's opencl.hpp (Debian 12 ships the 2023.02
// headers): hide the provisional command-buffer extensions, which the plugin does not use, before
// opencl.hpp sees them.
#include <CL/opencl.h>
#undef cl_khr_command_buffer
#undef cl_khr_command_buffer_mutable_dispatch

#include "CommonSymPRKKernelFactory.h"
#include "openmm/opencl/OpenCLContext.h"
#include "openmm/opencl/OpenCLPlatform.h"

extern "C" void registerPlatforms() {
}

extern "C" void registerKernelFactories() {
    SymPRKPlugin::CommonSymPRKKernelFactory<OpenMM::OpenCLPlatform::PlatformData>::registerWith("OpenCL");
}
