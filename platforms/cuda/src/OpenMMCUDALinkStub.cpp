/* An empty library whose only purpose is its name.  It is built as libOpenMMCUDA.so (soname libOpenMMCUDA.so) in the
 * build folder, never installed, and the CUDA kernel library links against it so that it records DT_NEEDED
 * libOpenMMCUDA.so.  At run time that entry is OpenMM's CUDA platform library (PyPI openmm-cuda-12 or -13, found
 * through the kernel library's RUNPATH), the library OpenMM has already loaded: the loader reuses it, and the Common
 * compute classes the kernel uses (ComputeArray, ...) resolve there.  Without the entry they resolve nowhere, since
 * OpenMM loads its platform plugins with dlopen(RTLD_LAZY), whose symbols stay local to them. */
