// The pixel strategy's refill megakernel (the binary BVH): a lane whose ray is done takes
// its path's next ray, or a new path, while the rest of its warp walks on (Aila & Laine
// 2009, "replacing terminated rays"). k_pixel runs each ray to its end for all 32 lanes,
// so a warp walks as long as its longest ray and its longest path; here the warp steps
// its lanes' walks (binary_walk.h: down to a leaf and its triangles a step) until fewer
// than `min_active` lanes are still walking, then the lanes that are done shade together
// (the path step of common/path.h, the same calls as trace_path_bvh_in's) and begin their
// next rays. Every ray and every path is computed as in k_pixel, so the film is the same
// bit for bit (LaneFilmSum: integer sums in another order).
#include <cuda_runtime.h>

#include <cstdint>

#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "kernel_sync.h"
#include "parked_path.cuh"
#include "path_step.cuh"
#include "pathbench/bvh/binary_walk.h"
#include "pathbench/bvh/path_trace.h"
#include "strategies.cuh"

namespace pb::gpu {

namespace {

// A lane's place in its path: a sample to begin, its next ray to choose, a walk whose
// answer it waits for, its end (the film), or nothing left to do.
enum Phase : uint32_t { kNew, kNext, kClosest, kShadowThenNext, kShadowThenEnd, kEnd, kIdle };

// The samples a warp hands to its lanes: ranges of consecutive samples claimed from the
// counter (in chunks of 32), large while much is left and down to one chunk at the end
// (guided: a lane keeps one pixel for many samples, so few film flushes; the frame still
// ends evenly). Warp-uniform.
struct WarpSamples {
  unsigned long long next = 0, end = 0;
  bool exhausted = false;
  static constexpr unsigned long long kMaxChunks = 64;

  __device__ void claim(unsigned long long* counter, uint64_t total, uint32_t lane) {
    const unsigned long long chunks = (total + 31) / 32, warps = grid_threads() >> 5;
    unsigned long long start = 0, k = 1;
    if (lane == 0) {
      const unsigned long long done = *reinterpret_cast<volatile unsigned long long*>(counter);
      const unsigned long long left = chunks > done ? chunks - done : 0;
      k = left / (2 * warps);
      k = k < 1 ? 1 : (k > kMaxChunks ? kMaxChunks : k);
      start = atomicAdd(counter, k);
    }
    start = __shfl_sync(kFullMask, start, 0);
    k = __shfl_sync(kFullMask, k, 0);
    next = start * 32;
    end = (start + k) * 32 < total ? (start + k) * 32 : total;
    if (next >= total) exhausted = true;
  }
};

template <bool kVariance, uint32_t Kinds, int kMinBlocks, bool kParked>
__global__ void __launch_bounds__(256, kMinBlocks)
    k_pixel_refill(SceneView s, BinaryBvhView bvh, PathConfig c, uint64_t total, FilmDev film, PixelCounters* ctr,
                   uint32_t min_active) {
  kernel_prologue();
  const uint32_t lane = threadIdx.x & 31;
  __shared__ ParkedPath<float> parked[kParked ? 256 : 1];
  ParkedPath<float> in_registers;
  ParkedPath<float>& p = kParked ? parked[threadIdx.x] : in_registers;
  PathState<float>& st = p.st;
  ShadowQuery<float>& q = p.q;

  bvh::BinaryWalk w;
  uint32_t stack[bvh::kTraversalStackSize];
  bool walking = false;
  uint32_t phase = kNew, pixel = kNoPixel;
  LaneFilmSum<kVariance> acc;
  WarpSamples samples;
  uint32_t n_bounce = 0, n_shadow = 0, n_paths = 0;
  auto begin_shadow = [&](uint32_t then) {
    ++n_shadow;
    w.begin(Vec3f(q.ray.o), Vec3f(q.ray.d), 1.0f, true);
    walking = true;
    phase = then;
  };

  for (;;) {
    // 1. The answers of the walks that ended (trace_path_bvh_in's steps after each query).
    if (!walking && phase == kClosest) {
      if (w.hit == bvh::kNoHit) {
        phase = kEnd;
      } else {
        bool wants_shadow;
        const PathEvent ev = path_hit<Kinds>(s, c, st, surface_hit(s, w.hit, st.ray), q, wants_shadow);
        if (wants_shadow) begin_shadow(ev == PathEvent::Done ? kShadowThenEnd : kShadowThenNext);
        else phase = ev == PathEvent::Done ? kEnd : kNext;
      }
    } else if (!walking && (phase == kShadowThenNext || phase == kShadowThenEnd)) {
      if (w.hit == bvh::kNoHit) shadow_unoccluded(st, q);
      phase = phase == kShadowThenEnd ? kEnd : kNext;
    }
    // 2. Ended paths to the film, new samples to lanes without a path, and each path's
    // next ray; again while a path ends without one (a last vertex that sees no emitter).
    for (;;) {
      if (phase == kEnd) {
        acc.add(film, pixel, Vec3f(st.L), &ctr->stats.discarded);
        ++n_paths;
        phase = kNew;
      }
      for (uint32_t need = __ballot_sync(kFullMask, phase == kNew); need != 0 && !samples.exhausted;
           need = __ballot_sync(kFullMask, phase == kNew)) {
        if (samples.next == samples.end) {
          samples.claim(&ctr->chunks, total, lane);
          if (samples.exhausted) break;
        }
        const unsigned long long avail = samples.end - samples.next;
        const uint32_t rank = __popc(need & ((1u << lane) - 1u));
        if (phase == kNew && rank < avail) {
          const uint64_t g = samples.next + rank;
          pixel = c.first_pixel + uint32_t(g / c.spp);
          path_begin(s, c, pixel, c.first_sample + uint32_t(g % c.spp), st);
          phase = kNext;
        }
        const unsigned long long taken = __popc(need);
        samples.next += taken < avail ? taken : avail;
      }
      if (phase == kNew) phase = kIdle;  // no samples left
      if (phase == kNext) {
        if (bvh::gpu_final_vertex(s, c, st)) {  // only emitted light can still count
          if (path_final_query<Kinds>(s, c, st, q)) begin_shadow(kShadowThenEnd);
          else phase = kEnd;
        } else {
          if (st.depth > 0) ++n_bounce;  // the camera ray is counted per path
          w.begin(Vec3f(st.ray.o), Vec3f(st.ray.d), bvh::kInf, false);
          walking = true;
          phase = kClosest;
        }
      }
      if (__ballot_sync(kFullMask, phase == kEnd) == 0u) break;
    }
    // Every lane walks now or is idle.
    if (__ballot_sync(kFullMask, walking) == 0u) break;
    // 3. The walks, a leaf a step, until too few lanes walk to keep the warp busy.
    for (;;) {
      if (walking && w.step(bvh, stack)) walking = false;
      if (uint32_t(__popc(__ballot_sync(kFullMask, walking))) < min_active) break;
    }
  }
  acc.flush(film);
  block_stats_add(&ctr->stats, n_bounce, n_shadow, n_paths);
}

}  // namespace

FrameResult run_pixel_refill(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c,
                             uint64_t total, FilmDev film, bool variance, DeviceBuffer<PixelCounters>& counters,
                             int min_blocks, bool parked, uint32_t min_active) {
  PB_CUDA_CHECK(cudaMemsetAsync(counters.get(), 0, sizeof(PixelCounters), stream));
  with_features(g.view.material_kinds, [&](auto kinds) {
    constexpr uint32_t K = decltype(kinds)::value;
    const uint64_t threads = (total + 31) / 32 * 32;
    auto go = [&](auto kernel) {
      launch.launch_persistent("pixel", kernel, threads, g.view, g.bvh.binary, c, total, film, counters.get(),
                               min_active);
    };
    auto at = [&](auto blocks, auto park) {
      constexpr int N = decltype(blocks)::value;
      constexpr bool P = decltype(park)::value;
      variance ? go(k_pixel_refill<true, K, N, P>) : go(k_pixel_refill<false, K, N, P>);
    };
    using Five = std::integral_constant<int, 5>;
    using Eight = std::integral_constant<int, kPixelLatencyBlocks>;
    if (min_blocks == 5) parked ? at(Five{}, std::true_type{}) : at(Five{}, std::false_type{});
    else parked ? at(Eight{}, std::true_type{}) : at(Eight{}, std::false_type{});
  });
  FrameResult r;
  PB_CUDA_CHECK(cudaMemcpyAsync(&r.stats, &counters.get()->stats, sizeof(Stats), cudaMemcpyDeviceToHost, stream));
  PB_CUDA_CHECK(cudaStreamSynchronize(stream));
  r.state_bytes_per_path = 0;
  return r;
}

}  // namespace pb::gpu
