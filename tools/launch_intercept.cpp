// Counts what a process asks of an OpenCL or CUDA device: kernel launches, device-side copies and fills, and host
// transfers (reads, writes, maps).  Built and preloaded by tools/count_launches.py:
//
//   g++ -O2 -shared -fPIC -o launch_intercept.so tools/launch_intercept.cpp -ldl
//   LD_PRELOAD=$PWD/launch_intercept.so python ...
//
// Each wrapped API function counts, then calls the real one (dlsym(RTLD_NEXT)).  No OpenCL or CUDA header is needed:
// the handles are pointers and the wrappers pass every argument through unchanged.  The process reads the counts
// through the C functions at the end (ctypes.CDLL(None) finds them once the library is preloaded).
#include <dlfcn.h>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <string>

namespace {

enum Counter { LAUNCH = 0, DEVICE_COPY = 1, FILL = 2, READ = 3, WRITE = 4, MAP = 5, NUM_COUNTERS = 6 };
long long counts[NUM_COUNTERS];
std::map<std::string, long long> perKernel;
std::map<const void*, std::string> kernelNames;
std::mutex lock;

void* real(const char* name) {
    // the library after this one in the global scope, or the OpenCL/CUDA library itself (OpenMM loads its platform
    // plugins, and with them these libraries, with RTLD_LOCAL: outside the scope RTLD_NEXT searches)
    void* f = dlsym(RTLD_NEXT, name);
    const char* libraries[] = {name[0] == 'c' && name[1] == 'l' ? "libOpenCL.so.1" : "libcuda.so.1", nullptr};
    for (int i = 0; f == nullptr && libraries[i] != nullptr; i++) {
        void* handle = dlopen(libraries[i], RTLD_NOW | RTLD_LOCAL);
        if (handle != nullptr)
            f = dlsym(handle, name);
    }
    if (f == nullptr) {
        fprintf(stderr, "launch_intercept: %s not found after the interposer\n", name);
        abort();
    }
    return f;
}

void add(Counter which) {
    std::lock_guard<std::mutex> guard(lock);
    counts[which]++;
}

typedef int32_t (*GetKernelInfo)(void*, uint32_t, size_t, void*, size_t*);

std::string openclKernelName(void* kernel) {
    auto found = kernelNames.find(kernel);
    if (found != kernelNames.end())
        return found->second;
    static GetKernelInfo info = (GetKernelInfo) real("clGetKernelInfo");
    char name[256] = "?";
    size_t size = 0;
    if (info(kernel, 0x1190 /* CL_KERNEL_FUNCTION_NAME */, sizeof(name)-1, name, &size) != 0)
        strcpy(name, "?");
    kernelNames[kernel] = name;
    return name;
}

}

extern "C" {

// -- the counts ---------------------------------------------------------------------------------------------------
/** 0 launches, 1 device-side copies, 2 fills, 3 reads, 4 writes, 5 maps since the last reset. */
long long symprk_intercept_count(int which) {
    std::lock_guard<std::mutex> guard(lock);
    return (which >= 0 && which < NUM_COUNTERS ? counts[which] : -1);
}

void symprk_intercept_reset() {
    std::lock_guard<std::mutex> guard(lock);
    memset(counts, 0, sizeof(counts));
    perKernel.clear();
    kernelNames.clear();  // a released kernel's handle may come back as another kernel's
}

/** Launches per kernel name since the last reset (OpenCL), "name count" lines into buffer; the length needed. */
int symprk_intercept_kernels(char* buffer, int size) {
    std::lock_guard<std::mutex> guard(lock);
    std::string text;
    for (const auto& entry : perKernel)
        text += entry.first + " " + std::to_string(entry.second) + "\n";
    if (buffer != nullptr && size > 0) {
        strncpy(buffer, text.c_str(), size-1);
        buffer[size-1] = 0;
    }
    return (int) text.size()+1;
}

// -- OpenCL ---------------------------------------------------------------------------------------------------------
int32_t clEnqueueNDRangeKernel(void* queue, void* kernel, uint32_t dim, const size_t* offset, const size_t* global,
                               const size_t* local, uint32_t numEvents, const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, uint32_t, const size_t*, const size_t*, const size_t*, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueNDRangeKernel");
    {
        std::lock_guard<std::mutex> guard(lock);
        counts[LAUNCH]++;
        perKernel[openclKernelName(kernel)]++;
    }
    return f(queue, kernel, dim, offset, global, local, numEvents, events, event);
}

int32_t clEnqueueTask(void* queue, void* kernel, uint32_t numEvents, const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueTask");
    add(LAUNCH);
    return f(queue, kernel, numEvents, events, event);
}

int32_t clEnqueueReadBuffer(void* queue, void* buffer, uint32_t blocking, size_t offset, size_t size, void* ptr,
                            uint32_t numEvents, const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, uint32_t, size_t, size_t, void*, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueReadBuffer");
    add(READ);
    return f(queue, buffer, blocking, offset, size, ptr, numEvents, events, event);
}

int32_t clEnqueueWriteBuffer(void* queue, void* buffer, uint32_t blocking, size_t offset, size_t size, const void* ptr,
                             uint32_t numEvents, const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, uint32_t, size_t, size_t, const void*, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueWriteBuffer");
    add(WRITE);
    return f(queue, buffer, blocking, offset, size, ptr, numEvents, events, event);
}

int32_t clEnqueueReadBufferRect(void* queue, void* buffer, uint32_t blocking, const size_t* a, const size_t* b,
                                const size_t* c, size_t d, size_t e, size_t g, size_t h, void* ptr, uint32_t numEvents,
                                const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, uint32_t, const size_t*, const size_t*, const size_t*, size_t, size_t, size_t, size_t,
                         void*, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueReadBufferRect");
    add(READ);
    return f(queue, buffer, blocking, a, b, c, d, e, g, h, ptr, numEvents, events, event);
}

int32_t clEnqueueWriteBufferRect(void* queue, void* buffer, uint32_t blocking, const size_t* a, const size_t* b,
                                 const size_t* c, size_t d, size_t e, size_t g, size_t h, const void* ptr, uint32_t numEvents,
                                 const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, uint32_t, const size_t*, const size_t*, const size_t*, size_t, size_t, size_t, size_t,
                         const void*, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueWriteBufferRect");
    add(WRITE);
    return f(queue, buffer, blocking, a, b, c, d, e, g, h, ptr, numEvents, events, event);
}

void* clEnqueueMapBuffer(void* queue, void* buffer, uint32_t blocking, uint64_t flags, size_t offset, size_t size,
                         uint32_t numEvents, const void* events, void* event, int32_t* error) {
    typedef void* (*F)(void*, void*, uint32_t, uint64_t, size_t, size_t, uint32_t, const void*, void*, int32_t*);
    static F f = (F) real("clEnqueueMapBuffer");
    add(MAP);
    return f(queue, buffer, blocking, flags, offset, size, numEvents, events, event, error);
}

int32_t clEnqueueCopyBuffer(void* queue, void* src, void* dst, size_t srcOffset, size_t dstOffset, size_t size,
                            uint32_t numEvents, const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, void*, size_t, size_t, size_t, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueCopyBuffer");
    add(DEVICE_COPY);
    return f(queue, src, dst, srcOffset, dstOffset, size, numEvents, events, event);
}

int32_t clEnqueueFillBuffer(void* queue, void* buffer, const void* pattern, size_t patternSize, size_t offset, size_t size,
                            uint32_t numEvents, const void* events, void* event) {
    typedef int32_t (*F)(void*, void*, const void*, size_t, size_t, size_t, uint32_t, const void*, void*);
    static F f = (F) real("clEnqueueFillBuffer");
    add(FILL);
    return f(queue, buffer, pattern, patternSize, offset, size, numEvents, events, event);
}

// -- CUDA (driver API, as OpenMM's CUDA platform calls it) -------------------------------------------------------------
int cuLaunchKernel(void* f, unsigned gx, unsigned gy, unsigned gz, unsigned bx, unsigned by, unsigned bz, unsigned shared,
                   void* stream, void** params, void** extra) {
    typedef int (*F)(void*, unsigned, unsigned, unsigned, unsigned, unsigned, unsigned, unsigned, void*, void**, void**);
    static F g = (F) real("cuLaunchKernel");
    add(LAUNCH);
    return g(f, gx, gy, gz, bx, by, bz, shared, stream, params, extra);
}

#define SYMPRK_CUDA_COPY(name, counter, ...)                                   \
    int name(void* a, void* b, size_t c) {                                     \
        typedef int (*F)(void*, void*, size_t);                                \
        static F g = (F) real(#name);                                          \
        add(counter);                                                          \
        return g(a, b, c);                                                     \
    }
#define SYMPRK_CUDA_COPY_ASYNC(name, counter)                                  \
    int name(void* a, void* b, size_t c, void* stream) {                       \
        typedef int (*F)(void*, void*, size_t, void*);                         \
        static F g = (F) real(#name);                                          \
        add(counter);                                                          \
        return g(a, b, c, stream);                                             \
    }
// (CUdeviceptr is an integer of pointer size: passed through as a pointer-sized value)
SYMPRK_CUDA_COPY(cuMemcpyHtoD_v2, WRITE)
SYMPRK_CUDA_COPY(cuMemcpyDtoH_v2, READ)
SYMPRK_CUDA_COPY(cuMemcpyDtoD_v2, DEVICE_COPY)
SYMPRK_CUDA_COPY_ASYNC(cuMemcpyHtoDAsync_v2, WRITE)
SYMPRK_CUDA_COPY_ASYNC(cuMemcpyDtoHAsync_v2, READ)
SYMPRK_CUDA_COPY_ASYNC(cuMemcpyDtoDAsync_v2, DEVICE_COPY)

}
