#pragma once
// Host+device annotations: everything in the shared path step is written once and
// compiled for the CPU tracer (g++) and the CUDA tracer (nvcc).
#if defined(__CUDACC__)
#define PB_HD __host__ __device__ inline
#define PB_DEVICE_CODE 1
#else
#define PB_HD inline
#define PB_DEVICE_CODE 0
#endif
