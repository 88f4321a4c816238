// Reads of a device film outside the render (DeviceFilm, render.h): the largest |sum|,
// which run/'s NCCL reduction of MPI ranks' films checks against 2^63 before it adds the
// films with plain (unchecked) int64 sums. A kernel of its own file, so that no other
// kernel's code changes.
#include <cuda_runtime.h>

#include <cstdint>

#include "cuda_util.h"

namespace pb::gpu {

namespace {
// Grid-stride maximum of |v| over n two's-complement values (as unsigned: |INT64_MIN| =
// 2^63 fits), a warp's maximum by shuffles, one atomicMax per warp.
__global__ void max_abs_kernel(const unsigned long long* v, uint64_t n, unsigned long long* out) {
  unsigned long long m = 0;
  for (uint64_t i = uint64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += uint64_t(gridDim.x) * blockDim.x) {
    const unsigned long long x = v[i];
    const unsigned long long a = (x >> 63) ? 0ull - x : x;
    m = a > m ? a : m;
  }
  for (int off = 16; off > 0; off >>= 1) {
    const unsigned long long o = __shfl_down_sync(0xFFFFFFFFu, m, off);
    m = o > m ? o : m;
  }
  if ((threadIdx.x & 31) == 0) atomicMax(out, m);
}
}  // namespace

uint64_t max_abs_sum_on_device(const unsigned long long* sums, uint64_t n) {
  if (n == 0) return 0;
  // 8 bytes kept for the process (one device per process: an MPI rank's), so that the check
  // costs a kernel and two small copies, not an allocation and a synchronising free.
  static unsigned long long* out = nullptr;
  if (!out) PB_CUDA_CHECK(cudaMalloc(&out, sizeof(unsigned long long)));
  PB_CUDA_CHECK(cudaMemset(out, 0, sizeof(unsigned long long)));
  int device = 0, sms = 1;
  PB_CUDA_CHECK(cudaGetDevice(&device));
  PB_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
  const uint64_t want = (n + 255) / 256;
  const unsigned blocks = unsigned(want < uint64_t(sms) * 8 ? want : uint64_t(sms) * 8);
  max_abs_kernel<<<blocks, 256>>>(sums, n, out);
  PB_CUDA_CHECK(cudaGetLastError());
  unsigned long long m = 0;
  PB_CUDA_CHECK(cudaMemcpy(&m, out, sizeof m, cudaMemcpyDeviceToHost));  // after the kernel (default stream)
  return m;
}

}  // namespace pb::gpu
