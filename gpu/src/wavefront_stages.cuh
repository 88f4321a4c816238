#pragma once
// The wavefront's two stage kernels. trace: plans the iteration from the one before (the
// refill with new samples), traces the shadow rays the iteration before queued
// (occlusion, then radiance to the film or the continuing path), then this iteration's
// closest hits (new samples' camera rays made there and again in shade, never stored).
// shade: the shared path step; continuing paths compacted into the next buffer, shadow
// rays queued. Launched by PathPool (path_pool.cu, the only includer).
#include <cuda_runtime.h>

#include "device_film.cuh"
#include "kernel_sync.h"
#include "path_step.cuh"
#include "pathbench/bvh/traversal.h"
#include "wavefront_state.cuh"
#include "work_chunks.cuh"
#include "bvh_names.h"

namespace pb::gpu {
namespace {

// This iteration's plan, from the one before (`prev`, complete: its kernels are done):
// the paths that continued, then as many new samples as fit. Every trace thread
// computes it (a few uniform loads), so no launch between iterations is needed.
struct IterationPlan {
  uint32_t n_cur, gen_dst;
  unsigned long long gen_base, next_after;
};

__device__ __forceinline__ IterationPlan plan_iteration(const IterationCounters& prev, unsigned long long total,
                                                        uint32_t capacity) {
  const uint32_t cont = prev.n_next;
  const unsigned long long remaining = total - prev.next_after;
  const uint32_t room = capacity - cont;
  const uint32_t n = uint32_t(remaining < room ? remaining : room);
  return {cont + n, cont, prev.next_after, prev.next_after + n};
}

// Thread 0 of the trace kernel: records the plan for shade and the next trace and books
// the iteration before into the stats. The record it overwrites was last used two
// iterations ago; no other thread touches these stats fields meanwhile (the shadow rays
// of the same kernel add to stats.discarded only).
__device__ __forceinline__ void record_plan(WaveCounters* ctr, uint32_t parity, const IterationPlan& plan) {
  const IterationCounters& prev = ctr->it[parity ^ 1u];
  ctr->stats.bounce += prev.n_next;
  ctr->stats.shadow += prev.n_shadow;
  ctr->stats.camera += plan.n_cur - plan.gen_dst;
  ctr->it[parity] = {plan.n_cur, plan.gen_dst, 0u, 0u, plan.gen_base, plan.next_after};
}

// Where the wavefront is: the iteration's parity and what planning needs.
struct WaveStep {
  uint32_t parity;           // iteration & 1: which IterationCounters is this iteration's
  unsigned long long total;  // samples in the frame
  uint32_t capacity;         // paths a buffer holds
  uint32_t* planned;         // mapped host memory: 1 if this iteration has paths to trace, else 0
  uint32_t counter_rounds;   // work_chunks.cuh's static_chunks (kWavefrontCounterRounds)
};

// This iteration's new samples: indices [gen_dst, n_cur) of the current buffer, after
// the continuing paths; a warp takes consecutive samples of a pixel, as the pixel
// strategy does (coherent camera rays). They are never stored: trace and shade each
// make the camera path from its sample index (path_begin: one random draw and a camera
// ray), which costs less than writing 64 bytes a new path and reading them back twice.
struct NewPaths {
  uint32_t dst;             // first index of a new path
  unsigned long long base;  // its sample index in the frame
  uint32_t spp;
};

__device__ __forceinline__ PathState<float> current_path(const SceneView& s, const PathConfig& c, const PathSoA& cur,
                                                         const NewPaths& fresh, uint32_t i) {
  if (i < fresh.dst) return load_path(cur, i);
  const unsigned long long g = fresh.base + (i - fresh.dst);
  PathState<float> st;
  path_begin(s, c, c.first_pixel + uint32_t(g / fresh.spp), c.first_sample + uint32_t(g % fresh.spp), st);
  return st;
}

// Blocks an SM for the trace kernel: 5 (48 registers) suits the binary and brute-force
// traversals; the wide one holds a node's 20 words and spills under 48 (ptxas, when
// closest hits and shadow rays were two kernels: 28 B and 100 B), so it gets 4 (64 registers).
// -DPB_WF_TRACE_BLOCKS=N and -DPB_WF_SHADE_BLOCKS=N build other counts (measurements).
#ifndef PB_WF_TRACE_BLOCKS
#define PB_WF_TRACE_BLOCKS 5
#endif
#ifndef PB_WF_SHADE_BLOCKS
#define PB_WF_SHADE_BLOCKS 3
#endif
template <int kKind>
constexpr int kTraversalBlocksPerSm = kKind == int(TraversalKind::Wide) ? 4 : PB_WF_TRACE_BLOCKS;
constexpr int kShadeBlocksPerSm = PB_WF_SHADE_BLOCKS;

// One chunk of the shadow rays the last shade queued (n of them; rays [base, base + 32)):
// occlusion, then the radiance to the film (a path that ended) or to the continuing path's
// L in `continued`, the buffer the last shade wrote and the next one reads. All 32 lanes
// call it (film_add_warp).
template <bool kVariance, int kKind>
__device__ __forceinline__ void trace_shadow_chunk(const BvhView& bvh, const ShadowSoA& sh, const PathSoA& continued,
                                                   uint32_t base, uint32_t n, const FilmDev& film,
                                                   unsigned long long* discarded) {
  const uint32_t i = base + (threadIdx.x & 31);
  bool add = false;
  uint32_t pixel = 0;
  Vec3f L{0.0f, 0.0f, 0.0f};
  if (i < n) {
    const float4 o = sh.o[i], d = sh.d[i];
    const float2 ct = sh.ct[i];
    const uint32_t target = __float_as_uint(ct.y);
    const bool done = (target & kShadowDone) != 0;
    // The radiance this ray adds to, loaded before the walk so that its latency hides behind
    // it: a finished path's in the record, a continuing one's in `continued`.
    float4 l = done ? sh.L[i] : continued.L[target];
    const Vec3f origin{o.x, o.y, o.z};
    const bool visible = !occluded<true, kKind>(bvh, origin, {d.x, d.y, d.z}, 1.0f);
    if (done) {
      L = {l.x, l.y, l.z};
      if (visible) L = L + Vec3f{o.w, d.w, ct.x};  // shadow_unoccluded: L += contribution
      if (l.w != 0.0f) {                             // a pair: the last vertex's emitter query
        const float4 d2 = sh.d2[i];
        const float2 c2 = sh.c2[i];
        if (!occluded<true, kKind>(bvh, origin, {d2.x, d2.y, d2.z}, 1.0f)) L = L + Vec3f{d2.w, c2.x, c2.y};
      }
      add = true;
      pixel = target & ~kShadowDone;
    } else if (visible) {
      l.x = l.x + o.w;
      l.y = l.y + d.w;
      l.z = l.z + ct.x;
      continued.L[target] = l;
    }
  }
  film_add_warp<kVariance>(film, add, pixel, L, discarded);
}

// Path i's closest hit: its ray from `cur` (a continuing path) or made from its sample
// index (a new one).
template <int kKind>
__device__ __forceinline__ void trace_closest(const SceneView& s, const PathConfig& c, const BvhView& bvh,
                                              const PathSoA& cur, const NewPaths& fresh, uint32_t* prim, uint32_t i) {
  Vec3f o, d;
  if (i < fresh.dst) {
    const float4 o4 = cur.o[i], d4 = cur.d[i];
    o = {o4.x, o4.y, o4.z};
    d = {d4.x, d4.y, d4.z};
  } else {
    const PathState<float> st = current_path(s, c, cur, fresh, i);
    o = st.ray.o;
    d = st.ray.d;
  }
  float t;
  prim[i] = intersect_closest<true, kKind>(bvh, o, d, kInf, t);
}

// One launch for both traversal stages: the shadow rays the iteration before queued
// (kShadows), then this iteration's closest hits. The shadows' radiance goes to paths in
// `cur` (L), the closest hits read their rays (o, d): different fields, and shade, which
// reads both, comes after. Planned here too (plan_iteration). One launch fewer an
// iteration, and a block that runs out of shadow rays goes on to closest hits.
template <bool kVariance, bool kShadows, int kKind>  // kKind: the BVH layout (traversal.h)
__global__ void __launch_bounds__(256, kTraversalBlocksPerSm<kKind>)
    k_wf_trace(SceneView s, PathConfig c, BvhView bvh, PathSoA cur, uint32_t* prim, ShadowSoA sh, WaveCounters* ctr,
               WaveStep step, FilmDev film) {
  kernel_prologue();
  const IterationCounters& prev = ctr->it[step.parity ^ 1u];
  const IterationPlan plan = plan_iteration(prev, step.total, step.capacity);
  const uint32_t n_shadow = prev.n_shadow;  // thread 0 below writes it[parity], not prev
  if (grid_thread() == 0) {
    record_plan(ctr, step.parity, plan);
    ctr->chunks.shade = 0;  // shade's counter: the last shade is done, the next starts after this trace
    *reinterpret_cast<volatile uint32_t*>(step.planned) = plan.n_cur != 0;  // for the host's loop
    __threadfence_system();
  }
  const uint32_t n = plan.n_cur;
  const NewPaths fresh{plan.gen_dst, plan.gen_base, c.spp};
  unsigned long long* discarded = &ctr->stats.discarded;
  // The shadow rays first, then the closest hits, each in chunks (for_each_chunk).
  if constexpr (kShadows) {
    const uint32_t end = (n_shadow + 31) / 32;
    for_each_chunk(end, static_chunks(end, step.counter_rounds), &ctr->chunks.shadow, [&](uint32_t k) {
      trace_shadow_chunk<kVariance, kKind>(bvh, sh, cur, k * 32, n_shadow, film, discarded);
    });
  }
  const uint32_t end = (n + 31) / 32;
  for_each_chunk(end, static_chunks(end, step.counter_rounds), &ctr->chunks.closest, [&](uint32_t k) {
    const uint32_t i = k * 32 + (threadIdx.x & 31);
    if (i < n) trace_closest<kKind>(s, c, bvh, cur, fresh, prim, i);
  });
}

__device__ __forceinline__ void push_shadow(const ShadowSoA& sh, uint32_t k, const ShadowQuery<float>& q, uint32_t target) {
  sh.o[k] = make_float4(q.ray.o.x, q.ray.o.y, q.ray.o.z, q.contribution.x);
  sh.d[k] = make_float4(q.ray.d.x, q.ray.d.y, q.ray.d.z, q.contribution.y);
  sh.ct[k] = make_float2(q.contribution.z, __uint_as_float(target));
}

// One chunk of shade: paths [base, base + 32) of `cur` (n of them). All 32 lanes call it
// (the appends, film_add_warp, the pair count). Returns the chunk's pairs (their second rays
// are shadow rays the stats count), the same on every lane.
template <bool kVariance, uint32_t Kinds>
__device__ __forceinline__ uint32_t shade_chunk(const SceneView& s, const PathConfig& c, const PathSoA& cur,
                                            const PathSoA& next, const uint32_t* prim, const ShadowSoA& sh,
                                            WaveCounters* ctr, IterationCounters& at, const NewPaths& fresh,
                                            const FilmDev& film, uint32_t base, uint32_t n) {
  const uint32_t i = base + (threadIdx.x & 31);
  bool add = false, cont = false, wants_shadow = false, final_ray = false;
  uint32_t pixel = 0;
  Vec3f L_add{0.0f, 0.0f, 0.0f};
  PathState<float> st;
  ShadowQuery<float> q, fq;
  if (i < n) {
    // The hit first: its load then waits while a new path's camera ray is made.
    const uint32_t h = prim[i];
    st = current_path(s, c, cur, fresh, i);
    pixel = st.pixel;
    if (h == kNoHit) {
      add = true;
      L_add = st.L;
    } else {
      PathEvent ev = path_hit<Kinds>(s, c, st, surface_hit(s, h, st.ray), q, wants_shadow);
      // The next vertex would be the last: answer it here (trace_path does the same
      // at the top of its loop), so the path never goes through trace + shade again.
      if (ev == PathEvent::Continue && gpu_final_vertex(s, c, st)) {
        final_ray = path_final_query<Kinds>(s, c, st, fq);
        ev = PathEvent::Done;
      }
      cont = ev == PathEvent::Continue;
      if (ev == PathEvent::Done && !wants_shadow && !final_ray) {
        add = true;
        L_add = st.L;
      }
    }
  }
  const bool shadow = wants_shadow || final_ray;
  const QueueSlots slot = queue_push_both(at, cont, shadow);
  // Work that needs no slot, while the append's atomic is in flight.
  film_add_warp<kVariance>(film, add, pixel, L_add, &ctr->stats.discarded);
  const bool pair = wants_shadow && final_ray;
  if (cont) store_path(next, slot.next, st);
  if (shadow) {
    // Light-sampling ray first (shadow_unoccluded's order in trace_path); both rays of a
    // pair leave from the same origin (the offset hit point). A path that ended has its
    // radiance in the record (kShadowDone | pixel); a continuing one, its slot in `next`.
    const uint32_t k = slot.shadow;
    push_shadow(sh, k, wants_shadow ? q : fq, cont ? slot.next : kShadowDone | st.pixel);
    if (pair) {
      sh.d2[k] = make_float4(fq.ray.d.x, fq.ray.d.y, fq.ray.d.z, fq.contribution.x);
      sh.c2[k] = make_float2(fq.contribution.y, fq.contribution.z);
    }
    if (!cont) sh.L[k] = make_float4(st.L.x, st.L.y, st.L.z, pair ? 1.0f : 0.0f);
  }
  return __reduce_add_sync(kFullMask, pair ? 1u : 0u);
}

template <bool kVariance, uint32_t Kinds>
__global__ void __launch_bounds__(256, kShadeBlocksPerSm) k_wf_shade(SceneView s, PathConfig c, PathSoA cur, PathSoA next,
                                                     const uint32_t* prim, ShadowSoA sh, WaveCounters* ctr, uint32_t parity,
                                                     FilmDev film, uint32_t counter_rounds) {
  kernel_prologue();
  IterationCounters& at = ctr->it[parity];
  const uint32_t n = at.n_cur;
  const NewPaths fresh{at.gen_dst, at.gen_base, c.spp};
  if (grid_thread() == 0) {  // the next trace's counters: this iteration's trace is done
    ctr->chunks.shadow = 0;
    ctr->chunks.closest = 0;
  }
  const uint32_t end = (n + 31) / 32;
  uint32_t pairs = 0;  // the warp's, booked once at the end: one atomic a warp, not one a chunk
  for_each_chunk(end, static_chunks(end, counter_rounds), &ctr->chunks.shade, [&](uint32_t k) {
    pairs += shade_chunk<kVariance, Kinds>(s, c, cur, next, prim, sh, ctr, at, fresh, film, k * 32, n);
  });
  if ((threadIdx.x & 31) == 0 && pairs) atomicAdd(&ctr->stats.shadow, static_cast<unsigned long long>(pairs));
}

}  // namespace
}  // namespace pb::gpu
