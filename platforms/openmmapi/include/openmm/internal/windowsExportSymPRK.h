#ifndef OPENMM_WINDOWSEXPORTSYMPRK_H_
#define OPENMM_WINDOWSEXPORTSYMPRK_H_

/*
 * The export macro of the openmm_symprk plugin's API library (libOpenMMSymPRK), on the pattern of OpenMM's own
 * openmm/internal/windowsExport.h, so that the plugin does not borrow OpenMM's OPENMM_EXPORT (which marks
 * symbols of OpenMM's library).  With Visual Studio three cases are told apart:
 *   (1) building the plugin's shared library: dllexport (CMake defines SYMPRK_BUILDING_SHARED_LIBRARY);
 *   (2) a client of the shared library (the kernel libraries, the SWIG module, the C++ tests): dllimport;
 *   (3) a static build (SYMPRK_BUILDING_STATIC_LIBRARY or SYMPRK_USE_STATIC_LIBRARIES): nothing.
 * Elsewhere (Linux, macOS) every symbol keeps the default visibility, as in OpenMM.
 */

#ifdef _MSC_VER
    // Keep MS VC++ quiet about lack of dll export of private members.
    #pragma warning(disable:4251)
    #if defined(SYMPRK_BUILDING_SHARED_LIBRARY)
        #define OPENMM_EXPORT_SYMPRK __declspec(dllexport)
    #elif defined(SYMPRK_BUILDING_STATIC_LIBRARY) || defined(SYMPRK_USE_STATIC_LIBRARIES)
        #define OPENMM_EXPORT_SYMPRK
    #else
        #define OPENMM_EXPORT_SYMPRK __declspec(dllimport)
    #endif
#else
    #define OPENMM_EXPORT_SYMPRK
#endif

#endif // OPENMM_WINDOWSEXPORTSYMPRK_H_
