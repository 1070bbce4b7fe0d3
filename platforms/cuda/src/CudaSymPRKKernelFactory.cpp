/* openmm_symprk native plugin: registers the Common SymPRKIntegrator kernel with the CUDA platform.
 *
 * Compiled wherever CMake finds the CUDA headers (cuda/CMakeLists.txt); run on an H100 and an H200 through
 * `symprk gpucheck` (docs/data/gpucheck), never in CI (no GPU).  The kernel code is the same Common source as
 * OpenCL's. */

#include "CommonSymPRKKernelFactory.h"
#include "openmm/cuda/CudaContext.h"
#include "openmm/cuda/CudaPlatform.h"

extern "C" void registerPlatforms() {
}

extern "C" void registerKernelFactories() {
    SymPRKPlugin::CommonSymPRKKernelFactory<OpenMM::CudaPlatform::PlatformData>::registerWith("CUDA");
}
