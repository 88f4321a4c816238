#pragma once
// The wavefront's state in device memory (pbrt-v4's wavefront/ split: state here, stages
// in wavefront_stages.cuh, the pool that owns the memory in path_pool.cu): paths and
// shadow rays as structures of arrays, the per-frame counters, and the warp-aggregated
// queue append.
#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>

#include "device_film.cuh"
#include "kernel_sync.h"
#include "pathbench/common/path.h"

namespace pb::gpu {

// wavefront and paper-queue: a pool of `capacity` paths in flight as structure of
// arrays, stage kernels linked by queues. Paths that continue are compacted into the
// other of two state buffers (warp-aggregated atomic append), new samples are appended
// after them, so every stage reads its paths contiguously. Each stage kernel loops over
// a count it reads on the device: the host never waits between stages.

struct PathSoA {
  float4* o;        // ray origin, bsdf_pdf
  float4* d;        // ray direction, pixel (bits)
  float4* beta;     // throughput, depth (bits)
  float4* L;        // radiance so far, sample (bits)
};

// Shadow rays of one iteration: a light-sampling ray, or the last vertex's emitter
// query (path_final_query), or both from the same origin (a "pair"). `target`: index
// of the continuing path in the next buffer, or kShadowDone | pixel for a path that
// ended (its radiance is in L; L.w != 0 marks a pair, whose second ray is d2/c2).
struct ShadowSoA {
  float4* o;        // origin, contribution.x
  float4* d;        // direction (unnormalised, to the light point), contribution.y
  float2* ct;       // contribution.z, target (bits)
  float4* L;        // radiance of a finished path, pair flag (written and read only for those)
  float4* d2;       // a pair's second ray: direction, contribution.x
  float2* c2;       // contribution.y, .z
};
constexpr uint32_t kShadowDone = 0x80000000u;  // pixels < 2^31 (RenderSettings::validate)

// One iteration's plan and appends. Two alternate (iteration i uses it[i & 1]): the
// trace kernel of iteration i plans it from it[(i + 1) & 1], the iteration before,
// which nobody writes any more, while it[i & 1], last used two iterations ago, is free
// to be reset. So no kernel of its own and no grid-wide barrier is needed to plan.
struct IterationCounters {
  uint32_t n_cur;     // paths traced this iteration: continuing ones, then new samples
  uint32_t gen_dst;   // index of the first new sample's path (= continuing paths)
  uint32_t n_next;    // paths continued into the next buffer (appends)
  uint32_t n_shadow;  // shadow rays queued (appends)
  unsigned long long gen_base;    // the first new sample's index in the frame
  unsigned long long next_after;  // samples handed out up to and including this iteration
};

constexpr uint32_t kNotPlanned = 0xFFFFFFFFu;  // a plan slot the GPU has not written yet (PathPool)

// Chunk counters of the stage kernels (work_chunks.cuh): trace's are reset by shade
// and shade's by trace, each by a kernel that runs wholly between the two launches that use
// it (stream order and PDL's wait in kernel_prologue), so no launch of their own is needed.
struct ChunkCounters {
  uint32_t shadow;   // trace: the shadow rays
  uint32_t closest;  // trace: the closest hits
  uint32_t shade;
};

// Each group on a 128-byte line of its own: the appends (it), the chunk claims and the stats'
// atomics come from every warp at once, and one line takes them one after another.
struct WaveCounters {
  alignas(128) IterationCounters it[2];
  alignas(128) Stats stats;  // booked by the planning thread, plus the kernels' atomics
  alignas(128) ChunkCounters chunks;
};

// n_next and n_shadow are one 8-byte word to the appends (queue_push_both).
static_assert(offsetof(IterationCounters, n_shadow) == offsetof(IterationCounters, n_next) + 4 &&
                  offsetof(IterationCounters, n_next) % 8 == 0,
              "n_next and n_shadow: one aligned 64-bit word, n_next the low half");

// Where a lane's appends go: its slot in the next buffer and in the shadow queue (each
// meaningful only where the lane appended there).
struct QueueSlots {
  uint32_t next, shadow;
};

// Warp-aggregated appends to both of an iteration's queues with one atomic: a 64-bit add of
// (shadow rays << 32 | paths) to the word n_next and n_shadow make (n_next < 2^32 cannot carry
// into n_shadow). Every shade chunk appends to both, and all warps append to this one word:
// as two 32-bit atomics their results were 48 % of k_wf_shade's stall samples (Nsight Compute,
// H100, paper-cornell; docs/notes/gpu-log.md). All 32 lanes call it.
__device__ __forceinline__ QueueSlots queue_push_both(IterationCounters& at, bool next, bool shadow) {
  const uint32_t lane = threadIdx.x & 31, below = (1u << lane) - 1u;
  const uint32_t m_next = __ballot_sync(kFullMask, next), m_shadow = __ballot_sync(kFullMask, shadow);
  unsigned long long base = 0;
  if (lane == 0 && (m_next | m_shadow) != 0u) {
    const unsigned long long add = (static_cast<unsigned long long>(__popc(m_shadow)) << 32) | uint32_t(__popc(m_next));
    base = atomicAdd(reinterpret_cast<unsigned long long*>(&at.n_next), add);
  }
  base = __shfl_sync(kFullMask, base, 0);
  return {uint32_t(base) + uint32_t(__popc(m_next & below)), uint32_t(base >> 32) + uint32_t(__popc(m_shadow & below))};
}

__device__ __forceinline__ PathState<float> load_path(const PathSoA& p, uint32_t i) {
  const float4 o = p.o[i], d = p.d[i], b = p.beta[i], L = p.L[i];
  PathState<float> st;
  st.ray.o = {o.x, o.y, o.z};
  st.bsdf_pdf = o.w;
  st.ray.d = {d.x, d.y, d.z};
  st.pixel = __float_as_uint(d.w);
  st.beta = {b.x, b.y, b.z};
  st.depth = __float_as_uint(b.w);
  st.L = {L.x, L.y, L.z};
  st.sample = __float_as_uint(L.w);
  return st;
}

__device__ __forceinline__ void store_path(const PathSoA& p, uint32_t i, const PathState<float>& st) {
  p.o[i] = make_float4(st.ray.o.x, st.ray.o.y, st.ray.o.z, st.bsdf_pdf);
  p.d[i] = make_float4(st.ray.d.x, st.ray.d.y, st.ray.d.z, __uint_as_float(st.pixel));
  p.beta[i] = make_float4(st.beta.x, st.beta.y, st.beta.z, __uint_as_float(st.depth));
  p.L[i] = make_float4(st.L.x, st.L.y, st.L.z, __uint_as_float(st.sample));
}

}  // namespace pb::gpu
