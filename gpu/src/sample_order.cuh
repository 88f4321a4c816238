#pragma once
// The pixel megakernel's lanes take a pixel's samples grouped by the first bounce's random
// numbers, so that a warp's rays leave the first hit in similar directions and walk the BVH
// through similar nodes. Only which samples share a warp changes: every sample is traced
// as before and the film adds exact integer sums, so the film is the same bit for bit.
// A host model of the walks on SIMT lanes (results/amd-epyc/archive/warp-models-36776c4) gave
// bunny-armadillo 0.861 and paper-cornell-ico:8 0.815 of the warps' walk steps for groups of
// 256 samples in 16 bins; an H200 gave about a fifth of that, 0.973 and 0.958 of the time
// (results/nvidia-h200/archive/record-e024919), and was slower with 512 samples a group
// (tests-10fdac3) and where the kernel is issue bound: pixel.cu's lanes_ordered says where it runs.
#include <cuda_runtime.h>

#include <cstdint>

#include "kernel_sync.h"
#include "pathbench/bvh/sample_units.h"
#include "pathbench/common/path.h"

namespace pb::gpu {

using bvh::SampleUnit;
using bvh::kOrderBins;
using bvh::kOrderGroup;
using bvh::first_bounce_bin;
using bvh::order_samples;
using bvh::sample_unit;
using bvh::sample_units;

// Writes to `order` (one warp's kOrderGroup slots) the unit's sample offsets grouped by bin:
// a counting sort in shared memory, each bin's samples in sample order (per register round,
// the leader of the lanes that share a bin takes their slots). All 32 lanes call it;
// `counts` is the warp's kOrderBins words.
__device__ __forceinline__ void order_unit(const PathConfig& c, const SampleUnit& u, uint16_t* order,
                                           uint32_t* counts) {
  const uint32_t lane = threadIdx.x & 31, below = (1u << lane) - 1u;
  if (lane < kOrderBins) counts[lane] = 0;
  __syncwarp();
  const uint32_t pixel = c.first_pixel + uint32_t(u.g0 / c.spp), first = c.first_sample + uint32_t(u.g0 % c.spp);
  uint32_t slot[kOrderGroup / 32], bin[kOrderGroup / 32];
#pragma unroll
  for (uint32_t r = 0; r < kOrderGroup / 32; ++r) {
    const uint32_t e = r * 32 + lane;
    const bool valid = e < u.count;
    bin[r] = valid ? first_bounce_bin(pixel, c.seed, first + e) : kOrderBins;
    const uint32_t same = __match_any_sync(kFullMask, bin[r]);
    const uint32_t leader = __ffs(same) - 1;
    uint32_t base = 0;
    if (valid && lane == leader) {  // the leaders of one round hold different bins: no atomic needed
      base = counts[bin[r]];
      counts[bin[r]] = base + uint32_t(__popc(same));
    }
    slot[r] = __shfl_sync(kFullMask, base, leader) + __popc(same & below);
    __syncwarp();  // this round's counts before the next round's leaders read them
  }
  __syncwarp();
  // Each bin's first slot: the counts summed over the bins before it (16 words, every lane alike).
  uint32_t start = 0, mine = 0;
  for (uint32_t b = 0; b < kOrderBins; ++b) {
    if (b == lane) mine = start;
    start += counts[b];
  }
#pragma unroll
  for (uint32_t r = 0; r < kOrderGroup / 32; ++r) {
    const uint32_t b0 = __shfl_sync(kFullMask, mine, bin[r] < kOrderBins ? bin[r] : 0);
    if (bin[r] < kOrderBins) order[b0 + slot[r]] = uint16_t(r * 32 + lane);
  }
  __syncwarp();
}

}  // namespace pb::gpu
