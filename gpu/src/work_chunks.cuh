#pragma once
// Work handed out to warps in chunks of 32 consecutive items (chunk k: items [32 k, 32 k +
// 32)), used by the persistent kernels (the pixel megakernel, the wavefront's stages). The
// first `fixed` chunks go by grid stride (warp w takes w, w + W, ...: no atomics); the rest
// come from a counter, one atomic a chunk, so a warp that drew short work takes more and a
// launch ends when its work does, not with the warp of the longest static share.
// Measured on an H100 (docs/notes/gpu-log.md, "Work from a counter"): the megakernel all from the
// counter, paper-cornell 12.00 -> 11.58 ms, ico:8 48.6 -> 43.0; the wavefront's stages
// with the last full round and the partial one from it, paper-cornell unchanged, ico:8 -6 %;
// with the last 4, ico:8 -14 %, paper-cornell +3.5 %; today the meshes take 4 and the rest
// only the partial round (strategies.cuh, kWavefrontCounterRounds).
#include <cuda_runtime.h>

#include <cstdint>

#include "kernel_sync.h"

namespace pb::gpu {

// body(k) for chunks k < end; `counter` (zero on entry) hands out the chunks from `fixed`
// on. All 32 lanes of a warp call it and body(k) (k is warp-uniform). Index: uint32_t or
// unsigned long long (atomicAdd's types). `fixed` >= end + warps: no claim at all. Warps
// beyond the work should not claim (claims queue on one address): static_chunks makes a
// launch with no more chunks than warps all static, and the megakernel's grid is no larger
// than its chunks (Launcher::launch_persistent).
template <class Index, class Body>
__device__ __forceinline__ void for_each_chunk(Index end, Index fixed, Index* counter, Body&& body) {
  const Index warp = grid_thread() >> 5, warps = grid_threads() >> 5;
  const bool leader = (threadIdx.x & 31) == 0;
  Index claim = warp < fixed || !leader ? Index(0) : atomicAdd(counter, Index(1));
  Index k = warp < fixed ? warp : fixed + __shfl_sync(kFullMask, claim, 0);
  while (k < end) {  // one call site of body: inlined once
    // The next chunk is the static one after k, or a claim made now, before working on k,
    // so that the atomic's latency hides behind the work.
    const bool claims = k + warps >= fixed;
    if (claims && leader) claim = atomicAdd(counter, Index(1));
    body(k);
    k = claims ? fixed + __shfl_sync(kFullMask, claim, 0) : k + warps;
  }
}

// for_each_chunk with its state between chunks (the chunk and the claim in flight) in the
// block's shared memory, one slot a warp, instead of in registers that stay live through
// body(k): the parked pixel megakernel's (pixel.cu), whose traversals run at the register
// cap (H100, interleaved, same films: ico:8 0.995, paper-cornell 0.996, large-mesh 0.994;
// docs/notes/gpu-log.md, 2026-11-27). kWarps: the most warps a block has (its
// slots). The __syncwarp calls order the leader's write of the next chunk after every
// lane's read of the last one.
template <int kWarps, class Index, class Body>
__device__ __forceinline__ void for_each_chunk_parked(Index end, Index fixed, Index* counter, Body&& body) {
  __shared__ Index next[kWarps];
  const Index warp = grid_thread() >> 5, warps = grid_threads() >> 5;
  const uint32_t w = threadIdx.x >> 5;
  const bool leader = (threadIdx.x & 31) == 0;
  if (leader) next[w] = warp < fixed ? warp : fixed + atomicAdd(counter, Index(1));
  __syncwarp();
  Index k = next[w];
  while (k < end) {
    const bool claims = k + warps >= fixed;
    __syncwarp();
    if (leader) next[w] = claims ? fixed + atomicAdd(counter, Index(1)) : k + warps;
    body(k);
    __syncwarp();
    k = next[w];
  }
}

// The wavefront's split: every full round of the grid stride static but the last
// `counter_rounds`; those and the partial round from the counter. No more chunks than
// warps: all static (no warp takes two, so there is nothing to balance).
__device__ __forceinline__ uint32_t static_chunks(uint32_t end, uint32_t counter_rounds) {
  const uint32_t warps = grid_threads() >> 5, rounds = end / warps;
  if (end <= warps) return end + warps;  // for_each_chunk: no claims
  return rounds > counter_rounds ? (rounds - counter_rounds) * warps : 0;
}

}  // namespace pb::gpu
