/* openmm_symprk native plugin: registers the Common SymPRKIntegrator kernel with the CUDA platform.
 *
 * Compiled wherever CMake finds the CUDA headers (cuda/CMakeLists.txt); never run on a machine of this project
 * yet (no GPU).  The kernel code is the same Common source as OpenCL's. */

#include "CommonSymPRKKernelFactory.h"
#include "openmm/cuda/CudaContext.h"
#include "openmm/cuda/CudaPlatform.h"

extern "C" void registerPlatforms() {
}

extern "C" void registerKernelFactories() {
    SymPRKPlugin::CommonSymPRKKernelFactory<OpenMM::CudaPlatform::PlatformData>::registerWith("CUDA");
}
