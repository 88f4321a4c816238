// The pixel strategy: one megakernel, one thread per pixel sample (a warp takes chunks of 32
// consecutive samples from a counter, or, for large flat BVHs, units of up to 256 samples of
// one pixel traced 32 at a time grouped by their first bounce's random numbers:
// sample_order.cuh), the whole path in registers. Samples of
// one pixel are summed in the warp (exact integer sums) before one atomic per pixel.
#include <cuda_runtime.h>
#include <fmt/core.h>

#include <cstdlib>
#include <string>
#include <type_traits>

#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "kernel_sync.h"
#include "path_step.cuh"
#include "sample_order.cuh"
#include "pathbench/bvh/traversal.h"
#include "pathbench/common/errors.h"
#include "strategies.cuh"
#include "work_chunks.cuh"
#include "bvh_names.h"

namespace pb::gpu {

namespace {

// The block's ray and path counts, one atomic per counter per block. (Discarded samples
// are counted where they are rejected, in film_add_warp.)
__device__ void block_stats_add(Stats* stats, uint32_t bounce, uint32_t shadow, uint32_t paths) {
  __shared__ unsigned long long acc[3];
  if (threadIdx.x < 3) acc[threadIdx.x] = 0;
  __syncthreads();
  bounce = __reduce_add_sync(kFullMask, bounce);
  shadow = __reduce_add_sync(kFullMask, shadow);
  paths = __reduce_add_sync(kFullMask, paths);
  if ((threadIdx.x & 31) == 0) {
    atomicAdd(&acc[0], bounce);
    atomicAdd(&acc[1], shadow);
    atomicAdd(&acc[2], paths);
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    atomicAdd(&stats->bounce, acc[0]);
    atomicAdd(&stats->shadow, acc[1]);
    atomicAdd(&stats->paths, acc[2]);
    atomicAdd(&stats->camera, acc[2]);
  }
}

// kMinBlocks: blocks of 256 an SM must fit, registers capped to match (1: the compiler's
// choice, 91 registers and 2 blocks for the float watertight kernel). Measured on an H100
// (docs/notes/gpu-log.md, "Occupancy of the megakernel"): 3 blocks suit scenes whose BVH sits in
// L1 (issue bound), kPixelLatencyBlocks (8: 32 registers, spills) scenes that miss to L2
// (latency bound).
// kParked: each thread's path state and shadow query live in the block's shared memory
// (25 words a thread, an odd stride: no bank conflicts) instead of registers, so that the
// traversals, where the register peak is, run with ~25 registers fewer live.
template <class T> struct ParkedPath {
  PathState<T> st;
  ShadowQuery<T> q;
};
static_assert(sizeof(ParkedPath<float>) == 100, "25 words: an odd stride in words");

// The most threads a block of k_pixel has (its launch bounds; the launcher picks 64 to 256):
// the parked state's shared arrays are sized for it.
constexpr int kPixelMaxBlock = 256;

// Whether k_pixel orders a unit's samples by their first bounce (sample_order.cuh): only the
// binary and wide BVHs' latency-bound kernels (more than 3 blocks). Measured interleaved on an
// H200 against chunks of 32 in sample order (docs/notes/gpu-log.md, "Lanes ordered by the first
// bounce"): bunny-armadillo 0.974, paper-cornell-ico:8 0.965, large-mesh 0.990, glass-dragon 0.999,
// bunny-armadillo in wide8 0.933; slower where a kernel is issue bound or the BVH is not one
// flat tree: cornell-materials and the Mitsuba box (binary, 3 blocks) 1.027 and 1.026,
// paper-cornell (rects) 1.19-1.25, instanced (two-level) 1.243.
constexpr bool lanes_ordered(int kind, int blocks) {
  return (kind == int(TraversalKind::Binary) || kind == int(TraversalKind::Wide)) && blocks > 3;
}

template <bool kVariance, uint32_t Kinds, class T, bool kWatertight, int kKind, int kMinBlocks, bool kParked = false>
__global__ void __launch_bounds__(kPixelMaxBlock, kMinBlocks) k_pixel(SceneView s, BvhView bvh, PathConfig c, uint64_t total,
                                               FilmDev film, PixelCounters* ctr) {
  kernel_prologue();
  const uint32_t lane = threadIdx.x & 31;
  uint32_t n_bounce = 0, n_shadow = 0, n_paths = 0;
  // Sample g of the launch on this lane (or none: !valid), then the warp's sums into the film.
  auto trace = [&](bool valid, uint64_t g) {
    const uint32_t pixel = valid ? c.first_pixel + uint32_t(g / c.spp) : kNoPixel;
    Vec3f L{0.0f, 0.0f, 0.0f};
    if (valid) {
      if constexpr (kParked) {
        __shared__ ParkedPath<T> parked[kPixelMaxBlock];
        ParkedPath<T>& p = parked[threadIdx.x];
        L = trace_path_bvh_in<Kinds, T, kWatertight, kKind>(s, bvh, c, pixel, c.first_sample + uint32_t(g % c.spp),
                                                            n_bounce, n_shadow, p.st, p.q);
      } else {
        L = trace_path_bvh<Kinds, T, kWatertight, kKind>(s, bvh, c, pixel, c.first_sample + uint32_t(g % c.spp), n_bounce, n_shadow);
      }
      ++n_paths;
    }
    film_add_warp<kVariance>(film, valid, pixel, L, &ctr->stats.discarded);
  };
  // Every unit of work from the counter (work_chunks.cuh). Parked: the loop's state in shared
  // memory too (for_each_chunk_parked), not in four registers live through every traversal.
  auto each = [&](unsigned long long n, auto&& work) {
    if constexpr (kParked) for_each_chunk_parked<kPixelMaxBlock / 32, unsigned long long>(n, 0ull, &ctr->chunks, work);
    else for_each_chunk<unsigned long long>(n, 0ull, &ctr->chunks, work);
  };
  if constexpr (lanes_ordered(kKind, kMinBlocks)) {
    // Units of up to kOrderGroup samples of one pixel, traced 32 at a time in the order of
    // their first bounce's numbers (sample_order.cuh), or 32 in sample order where spp is small.
    // The unit (warp-uniform) waits in shared memory, not in registers live through the traversals
    // (ptxas, sm_90, binary at 8 blocks: 704 -> 788 bytes of spill stores with it in registers).
    __shared__ uint16_t order[kPixelMaxBlock / 32][kOrderGroup];
    __shared__ uint32_t counts[kPixelMaxBlock / 32][kOrderBins];
    __shared__ SampleUnit units_now[kPixelMaxBlock / 32];
    each(sample_units(total, c.spp), [&](unsigned long long k) {
      {
        // Every lane's last read of the unit before (the loop's end test) before its slot is
        // overwritten (racecheck found the hazard).
        __syncwarp();
        const SampleUnit u = sample_unit(total, c.spp, k);
        if (lane == 0) units_now[threadIdx.x >> 5] = u;
        if (order_samples(c.spp)) order_unit(c, u, order[threadIdx.x >> 5], counts[threadIdx.x >> 5]);
        __syncwarp();
      }
      // Read through volatile at each use, so that the compiler reloads them instead of keeping
      // them in registers.
      const volatile SampleUnit* now = &units_now[threadIdx.x >> 5];
      for (uint32_t base = 0; base < now->count; base += 32) {
        const uint32_t e = base + lane;
        const bool valid = e < now->count;
        trace(valid, now->g0 + (order_samples(c.spp) && valid ? order[threadIdx.x >> 5][e] : e));
      }
    });
  } else {
    // Chunks of 32 consecutive samples.
    each((total + 31) / 32, [&](unsigned long long k) { trace(k * 32 + lane < total, k * 32 + lane); });
  }
  block_stats_add(&ctr->stats, n_bounce, n_shadow, n_paths);
}

// The counts k_pixel is compiled for (float, watertight): 3 and kPixelLatencyBlocks for every
// layout, 5 too for the wide, leaves, rects and binary layouts (kWideLatencyBlocks,
// kLeavesParkedBlocks, kLongPathBlocks), 6 for the binary layout (kPixelBigBvhBlocks);
// the parked path state for the leaves layout at every count but kPixelLatencyBlocks and the
// binary BVH's at 5, 6 and 8. run_pixel
// dispatches on these, pixel_blocks and pixel_occupancy choose within them.
constexpr bool compiled_for_five_blocks(int kind) {
  return kind == int(TraversalKind::Wide) || kind == int(TraversalKind::Leaves) || kind == int(TraversalKind::Binary) ||
         kind == int(TraversalKind::Rects);
}
constexpr bool compiled_for_six_blocks(int kind) { return kind == int(TraversalKind::Binary); }
constexpr bool parked_compiled(int kind, int blocks) {
  return ((kind == int(TraversalKind::Leaves) || kind == int(TraversalKind::Rects)) && blocks != kPixelLatencyBlocks) ||
         (kind == int(TraversalKind::Binary) && blocks >= 5);
}
static_assert(kWideLatencyBlocks == 5 && kLeavesParkedBlocks == 5 && kLongPathBlocks == 5 && kPixelLatencyBlocks == 8 &&
                  kPixelBigBvhBlocks == 6,
              "the counts compiled: 3, 5 and 8, and 6 for the binary BVH");

// The traversal kind of the kernel run_pixel runs for the scene (with_traversal_kind: a binary
// BVH with exact ties has kernels of its own), which the counts compiled are checked against.
int kernel_kind(const GpuScene::Impl& g) {
  return with_traversal_kind(g.bvh, [](auto k) { return int(decltype(k)::value); });
}

// The scene's BVH exceeds the device's L2 of l2_bytes (the binary layout's nodes and
// triangles; `kind`: kernel_kind): auto runs its megakernel at kPixelBigBvhBlocks with the
// path state parked (strategies.cuh).
bool big_binary_bvh(const GpuScene::Impl& g, int kind, uint64_t l2_bytes) {
  return kind == int(TraversalKind::Binary) && g.bvh_bytes > l2_bytes;
}

// The block count PATHBENCH_GPU_PIXEL_BLOCKS or the scene's size and paths give (pixel_occupancy;
// `kind`: kernel_kind; `big`: big_binary_bvh; `bounces`: the frame's, -1 unbounded).
PixelOccupancy pixel_blocks(const GpuScene::Impl& g, int kind, bool big, int32_t bounces) {
  const bool wide = kind == int(TraversalKind::Wide), binary = kind == int(TraversalKind::Binary);
  const int latency = wide ? kWideLatencyBlocks : kPixelLatencyBlocks;
  const char* env = std::getenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  const std::string v = env ? env : "auto";
  if (v != "auto") {
    const bool ok = v == "3" || v == std::to_string(kPixelLatencyBlocks) ||
                    (compiled_for_five_blocks(kind) && v == "5") ||
                    (compiled_for_six_blocks(kind) && v == std::to_string(kPixelBigBvhBlocks));
    if (!ok)
      throw InputError(fmt::format("PATHBENCH_GPU_PIXEL_BLOCKS={}: expected auto, 3 or {} (the wide BVH layouts: "
                                   "auto, 3, 5 or 8; the leaves and rects layouts: also 5; the binary layout: also 5 "
                                   "and {}, but not for a scene with instances traced flat)",
                                   v, kPixelLatencyBlocks, kPixelBigBvhBlocks));
    return {std::stoi(v), "PATHBENCH_GPU_PIXEL_BLOCKS=" + v};
  }
  if (big)
    return {kPixelBigBvhBlocks,
            fmt::format("auto: the binary BVH's {:.1f} MB exceed the L2: {} blocks", double(g.bvh_bytes) / 1e6,
                        kPixelBigBvhBlocks)};
  // Long paths (strategies.cuh, kLongPathBlocks): measured on the binary BVH only.
  const auto long_paths = [&](int32_t from) { return binary && (bounces < 0 || bounces >= from); };
  const std::string paths = bounces < 0 ? "unbounded paths" : fmt::format("paths of {} bounces", bounces);
  if (g.bvh_tris >= kPixelLatencyBoundTris) {
    if (long_paths(kLongPathLatencyBounces))
      return {kLongPathBlocks, fmt::format("auto: {} triangles >= {}, {} (>= {}): {} blocks", g.bvh_tris,
                                           kPixelLatencyBoundTris, paths, kLongPathLatencyBounces, kLongPathBlocks)};
    return {latency, fmt::format("auto: {} triangles >= {} (latency bound: more warps{})", g.bvh_tris,
                                 kPixelLatencyBoundTris, wide ? "; the wide BVH's count" : "")};
  }
  if (long_paths(kLongPathBounces))
    return {kLongPathBlocks, fmt::format("auto: {} triangles < {}, {} (>= {}): {} blocks", g.bvh_tris,
                                         kPixelLatencyBoundTris, paths, kLongPathBounces, kLongPathBlocks)};
  if (binary && g.bvh_tris >= kPixelTinyTris)  // strategies.cuh: short paths over all but the tiniest BVHs
    return {kPixelLatencyBlocks, fmt::format("auto: {} triangles >= {}, {} (< {}): {} blocks", g.bvh_tris,
                                             kPixelTinyTris, paths, kLongPathBounces, kPixelLatencyBlocks)};
  return {3, fmt::format("auto: {} triangles < {} (issue bound)", g.bvh_tris,
                         binary ? kPixelTinyTris : kPixelLatencyBoundTris)};
}
}  // namespace

PixelOccupancy pixel_occupancy(const GpuScene::Impl& g, uint64_t l2_bytes, uint32_t spp, int32_t bounces) {
  const int kind = kernel_kind(g);
  const bool big = big_binary_bvh(g, kind, l2_bytes);
  PixelOccupancy o = pixel_blocks(g, kind, big, bounces);
  const bool leaves = g.bvh.kind == TraversalKind::Leaves || g.bvh.kind == TraversalKind::Rects;  // rects: as leaves
  const char* env = std::getenv("PATHBENCH_GPU_PIXEL_PARKED");
  const std::string v = env ? env : "auto";
  if (v == "auto") o.parked = leaves || (o.min_blocks == kPixelBigBvhBlocks && big);
  else if (v == "0" || v == "1") o.parked = v == "1";
  else throw InputError(fmt::format("PATHBENCH_GPU_PIXEL_PARKED={}: expected auto, 0 or 1", v));
  if (o.parked && !parked_compiled(kind, o.min_blocks)) o.parked = false;
  const char* blocks = std::getenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  if (o.parked && leaves && (!blocks || std::string(blocks) == "auto")) {
    o.min_blocks = kLeavesParkedBlocks;
    o.why = fmt::format("auto: the leaves layout, its path state parked: {} blocks", kLeavesParkedBlocks);
  } else if (o.parked) {
    o.why += "; path state parked in shared memory";
  }
  o.lanes_ordered = order_samples(spp) && lanes_ordered(kind, o.min_blocks);
  return o;
}

FrameResult run_pixel(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c,
                      uint64_t total, FilmDev film, bool variance, Precision precision, bool watertight,
                      DeviceBuffer<PixelCounters>& counters, int min_blocks, bool parked) {
  PB_CUDA_CHECK(cudaMemsetAsync(counters.get(), 0, sizeof(PixelCounters), stream));
  // The megakernel compiled for the scene's material kinds (features.h).
  // In float with the watertight test, compiled for the scene's BVH layout and the
  // occupancy that suits its size; or (the accuracy study's variants) in double or with
  // Moeller-Trumbore, switching on it at the compiler's occupancy.
  with_features(g.view.material_kinds, [&](auto kinds) {
    constexpr uint32_t K = decltype(kinds)::value;
    // A warp a unit of samples at most (a chunk of 32, or sample_order.cuh's): a small frame
    // leaves no warp without one.
    auto go = [&](auto kernel, bool ordered = false) {
      const uint64_t threads = (ordered ? sample_units(total, c.spp) : (total + 31) / 32) * 32;
      launch.launch_persistent("pixel", kernel, threads, g.view, g.bvh, c, total, film, counters.get());
    };
    constexpr int kAny = kAnyKind;
    if (precision == Precision::Double) variance ? go(k_pixel<true, K, double, true, kAny, 1>) : go(k_pixel<false, K, double, true, kAny, 1>);
    else if (!watertight) variance ? go(k_pixel<true, K, float, false, kAny, 1>) : go(k_pixel<false, K, float, false, kAny, 1>);
    else
      with_traversal_kind(g.bvh, [&](auto kind) {
        constexpr int B = decltype(kind)::value;
        auto at = [&](auto blocks) {
          constexpr int N = decltype(blocks)::value;
          constexpr bool O = lanes_ordered(B, N);
          if constexpr (parked_compiled(B, N)) {  // pixel_occupancy says where it runs
            if (parked) return variance ? go(k_pixel<true, K, float, true, B, N, true>, O) : go(k_pixel<false, K, float, true, B, N, true>, O);
          }
          variance ? go(k_pixel<true, K, float, true, B, N>, O) : go(k_pixel<false, K, float, true, B, N>, O);
        };
        if constexpr (compiled_for_five_blocks(B)) {
          if (min_blocks == 5) return at(std::integral_constant<int, 5>{});
        }
        if constexpr (compiled_for_six_blocks(B)) {
          if (min_blocks == kPixelBigBvhBlocks) return at(std::integral_constant<int, kPixelBigBvhBlocks>{});
        }
        if (min_blocks == kPixelLatencyBlocks) at(std::integral_constant<int, kPixelLatencyBlocks>{});
        else at(std::integral_constant<int, 3>{});
      });
  });
  FrameResult r;
  PB_CUDA_CHECK(cudaMemcpyAsync(&r.stats, &counters.get()->stats, sizeof(Stats), cudaMemcpyDeviceToHost, stream));
  PB_CUDA_CHECK(cudaStreamSynchronize(stream));
  r.state_bytes_per_path = 0;  // in registers
  return r;
}

}  // namespace pb::gpu
