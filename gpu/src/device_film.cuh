#pragma once
// The film and ray counters on the device: the integer sums the kernels add samples to
// (the same fixed point as Film, so the host film takes them back unchanged), the
// per-frame counters, the warp-aggregated film add every strategy ends a sample with,
// and the host-side buffers that hold them.
#include <cuda_runtime.h>

#include <cstdint>

#include "cuda_util.h"
#include "kernel_sync.h"
#include "pathbench/common/film.h"
#include "pathbench/common/math.h"

namespace pb::gpu {

// The film as the kernels see it: the one device view of a Film (its sums, counts and
// variance sums on the device, its scale and sample limit).
struct FilmDev {
  unsigned long long* sum;  // 3 per pixel, two's complement of Film's int64 sums
  uint32_t* count;
  double* sum_sq;           // null unless variance is kept
  double scale;
  double limit;             // a channel must stay strictly below this (Film::sample_limit)
};

struct Stats {
  unsigned long long camera, bounce, shadow, paths, discarded;
};


// The sum of v over the warp's 32 lanes, mod 2^64, on every lane (all lanes call it):
// three 32-bit reductions (__reduce_add_sync) of 22, 22 and 20-bit pieces, whose sums of
// 32 stay below 2^27.
__device__ __forceinline__ unsigned long long warp_sum_u64(unsigned long long v) {
  const unsigned lo = unsigned(v) & 0x3FFFFFu, mid = unsigned(v >> 22) & 0x3FFFFFu, hi = unsigned(v >> 44);
  return static_cast<unsigned long long>(__reduce_add_sync(kFullMask, lo)) +
         (static_cast<unsigned long long>(__reduce_add_sync(kFullMask, mid)) << 22) +
         (static_cast<unsigned long long>(__reduce_add_sync(kFullMask, hi)) << 44);
}

// A lane that adds nothing takes this key: no pixel has it (pixels < 2^31,
// RenderSettings::validate), so its run never reaches the film.
constexpr uint32_t kNoPixel = 0xFFFFFFFFu;

// Film add for a whole warp (all 32 lanes call it, convergent): samples of the same
// pixel in consecutive lanes are summed first (exact integer sums), then one atomic per
// pixel and channel. Strategies that hand out consecutive samples of a pixel to
// neighbouring lanes thus need ~1/32 of the atomics, and no lane of a warp waits on
// 32 same-address atomics.
template <bool kVariance>
__device__ __forceinline__ void film_add_warp(const FilmDev& film, bool add, uint32_t pixel, const Vec3f& L,
                                              unsigned long long* discarded) {
  // No lane adds (the wavefront's shade kernel, whose paths mostly end through a shadow
  // record that trace adds): nothing to sum. The segmented sum below cost its ~140
  // instructions on every warp of shade before (ncu, paper-cornell: a tenth of shade's).
  if (__ballot_sync(kFullMask, add) == 0u) return;
  const uint32_t lane = threadIdx.x & 31;
  const bool ok = add && sample_acceptable(L, film.limit);
  if (add && !ok) atomicAdd(discarded, 1ull);
  const uint32_t key = ok ? pixel : kNoPixel;
  long long q0 = ok ? quantize_radiance(L.x, film.scale) : 0;
  long long q1 = ok ? quantize_radiance(L.y, film.scale) : 0;
  long long q2 = ok ? quantize_radiance(L.z, film.scale) : 0;
  uint32_t cnt = ok ? 1u : 0u;
  double s0 = 0, s1 = 0, s2 = 0;
  if (kVariance && ok) {
    s0 = double(L.x) * double(L.x);
    s1 = double(L.y) * double(L.y);
    s2 = double(L.z) * double(L.z);
  }
  const uint32_t key_prev = __shfl_up_sync(kFullMask, key, 1);
  const uint32_t heads = __ballot_sync(kFullMask, lane == 0 || key_prev != key);
  if (!kVariance && heads == 1u && key != kNoPixel) {
    // The whole warp is one run of one pixel, every sample accepted (the pixel strategy
    // whenever spp is a multiple of 32, as the paper's 800): the warp's reduction unit sums
    // each channel. It adds 32-bit words, so each 64-bit value goes in as three pieces of
    // 22, 22 and 20 bits, whose sums over 32 lanes cannot carry out of 32 bits; put back
    // together mod 2^64 they are the two's complement sum, bit for bit what the segmented
    // sum below gives. 10 reductions instead of 40 shuffles and their adds (ncu: the film
    // add was 5 % of the paper-cornell megakernel's instructions).
    const unsigned long long s0 = warp_sum_u64(static_cast<unsigned long long>(q0));
    const unsigned long long s1 = warp_sum_u64(static_cast<unsigned long long>(q1));
    const unsigned long long s2 = warp_sum_u64(static_cast<unsigned long long>(q2));
    if (lane == 0) {
      unsigned long long* sum = film.sum + size_t(key) * 3;
      atomicAdd(sum + 0, s0);
      atomicAdd(sum + 1, s1);
      atomicAdd(sum + 2, s2);
      atomicAdd(film.count + key, 32u);
    }
    return;
  }
  // Segmented sum over runs of equal keys in consecutive lanes (Hillis-Steele: after
  // the step with offset `off`, a lane holds the sum of [lane, lane + 2 off) within
  // its run). Runs are told apart by the lane that starts them, not by the key: one
  // pixel may have several runs in a warp.
  const uint32_t run = 31u - uint32_t(__clz(heads & (0xFFFFFFFFu >> (31u - lane))));  // latest head <= lane
#pragma unroll
  for (int off = 1; off < 32; off <<= 1) {
    const uint32_t r2 = __shfl_down_sync(kFullMask, run, off);
    const long long a0 = __shfl_down_sync(kFullMask, q0, off), a1 = __shfl_down_sync(kFullMask, q1, off),
                    a2 = __shfl_down_sync(kFullMask, q2, off);
    const uint32_t c2 = __shfl_down_sync(kFullMask, cnt, off);
    double b0 = 0, b1 = 0, b2 = 0;
    if (kVariance) {
      b0 = __shfl_down_sync(kFullMask, s0, off);
      b1 = __shfl_down_sync(kFullMask, s1, off);
      b2 = __shfl_down_sync(kFullMask, s2, off);
    }
    if (lane + off < 32 && r2 == run) {
      q0 += a0; q1 += a1; q2 += a2;
      cnt += c2;
      if (kVariance) { s0 += b0; s1 += b1; s2 += b2; }
    }
  }
  if (key != kNoPixel && run == lane) {
    unsigned long long* sum = film.sum + size_t(key) * 3;
    atomicAdd(sum + 0, static_cast<unsigned long long>(q0));
    atomicAdd(sum + 1, static_cast<unsigned long long>(q1));
    atomicAdd(sum + 2, static_cast<unsigned long long>(q2));
    atomicAdd(film.count + key, cnt);
    if (kVariance) {
      double* sq = film.sum_sq + size_t(key) * 3;
      atomicAdd(sq + 0, s0);
      atomicAdd(sq + 1, s1);
      atomicAdd(sq + 2, s2);
    }
  }
}


struct FilmBuffers {
  DeviceBuffer<unsigned long long> sum;
  DeviceBuffer<uint32_t> count;
  DeviceBuffer<double> sum_sq;
  FilmDev view{};
  void allocate(const Film& film, uint64_t pixels) {
    const char* lower = "--width/--height";
    sum.allocate(pixels * 3, "the film", lower);
    count.allocate(pixels, "the film", lower);
    if (film.has_variance()) sum_sq.allocate(pixels * 3, "the film's variance (--variance-out)", lower);
    view = {sum.get(), count.get(), sum_sq.get(), film.scale(), film.sample_limit()};
  }
  void clear(cudaStream_t s) {
    PB_CUDA_CHECK(cudaMemsetAsync(sum.get(), 0, sum.bytes(), s));
    PB_CUDA_CHECK(cudaMemsetAsync(count.get(), 0, count.bytes(), s));
    if (sum_sq.get()) PB_CUDA_CHECK(cudaMemsetAsync(sum_sq.get(), 0, sum_sq.bytes(), s));
  }
  uint64_t bytes() const { return sum.bytes() + count.bytes() + sum_sq.bytes(); }
};


}  // namespace pb::gpu
