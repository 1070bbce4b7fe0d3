#ifndef COMMON_SYMPRK_KERNEL_FACTORY_H_
#define COMMON_SYMPRK_KERNEL_FACTORY_H_

/* openmm_symprk native plugin: the kernel factory of a Common compute platform (OpenCL, CUDA), written once.
 * PlatformData is the platform's PlatformData class, whose contexts[0] is its ComputeContext. */

#include "CommonSymPRKKernels.h"
#include "openmm/KernelFactory.h"
#include "openmm/OpenMMException.h"
#include "openmm/internal/ContextImpl.h"
#include <string>

namespace SymPRKPlugin {

template <class PlatformData>
class CommonSymPRKKernelFactory : public OpenMM::KernelFactory {
public:
    OpenMM::KernelImpl* createKernelImpl(std::string name, const OpenMM::Platform& platform, OpenMM::ContextImpl& context) const {
        OpenMM::ComputeContext& cc = *static_cast<PlatformData*>(context.getPlatformData())->contexts[0];
        if (name == IntegrateSymPRKStepKernel::Name())
            return new CommonIntegrateSymPRKStepKernel(name, platform, cc);
        throw OpenMM::OpenMMException("SymPRK "+platform.getName()+" plugin: unknown kernel '"+name+"'");
    }
    /** Register a factory with the platform of that name, if this process has it. */
    static void registerWith(const std::string& platformName) {
        try {
            OpenMM::Platform& platform = OpenMM::Platform::getPlatformByName(platformName);
            platform.registerKernelFactory(IntegrateSymPRKStepKernel::Name(), new CommonSymPRKKernelFactory<PlatformData>());
        }
        catch (...) {
            // No such platform in this process: nothing to register.
        }
    }
};

} // namespace SymPRKPlugin

#endif /*COMMON_SYMPRK_KERNEL_FACTORY_H_*/
