#pragma once
// What the orchestration (render.cu) asks of each GPU strategy: a frame's result, which
// shadow records the settings need, and the pixel strategy's entry (pixel.cu). The
// wavefront and paper-queue strategies are PathPool (path_pool.cuh).
#include <cuda_runtime.h>

#include <cstdint>
#include <string>

#include "cuda_util.h"
#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "pathbench/common/path.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::gpu {

struct FrameResult {
  Stats stats{};
  uint64_t state_bytes_per_path = 0, paths_in_flight = 0, pool_bytes = 0;
  uint64_t iterations = 0;
  uint32_t counter_rounds = 0;  // wavefront, paper-queue: kWavefrontCounterRounds or ...LatencyBound
};

// Which shadow records a frame needs: light-sampling rays, the last vertex's emitter
// queries (bounded paths, few emitters: path_at_final_vertex), and pairs of both.
struct ShadowUse {
  bool records = false;
  bool pairs = false;
  static ShadowUse of(const Scene& scene, const RenderSettings& settings) {
    const bool lights = !scene.emitters.empty();
    const bool nee = lights && settings.sampling == Sampling::Nee;
    const bool final_queries = lights && settings.max_bounces > 0 && scene.emitters.size() <= kMaxEmittersForFinalQuery;
    return {nee || final_queries, nee && final_queries};
  }
};

// The megakernel's occupancy: blocks of 256 threads an SM (registers capped to match),
// and why. From kPixelLatencyBoundTris triangle references on, a scene's BVH misses L1
// and the megakernel waits on memory (more warps hide it); below, it was issue bound on an H100
// at the time, but on an H200 today the binary BVH's short paths gain from more warps from
// kPixelTinyTris on, and its long paths everywhere (kLongPathBlocks, below).
// PATHBENCH_GPU_PIXEL_BLOCKS=auto|3|8 (5 too for the leaves and binary layouts, 6 for the binary)
// overrides it (a bad value: InputError); the wide BVH's megakernel is compiled for 5 too
// (pixel.cu: compiled_for_five_blocks).
struct PixelOccupancy {
  int min_blocks = 3;
  std::string why;
  // The path state parked in shared memory (pixel.cu, ParkedPath) instead of registers.
  // PATHBENCH_GPU_PIXEL_PARKED=auto|0|1; auto: the leaves layout (at kLeavesParkedBlocks
  // unless PATHBENCH_GPU_PIXEL_BLOCKS says otherwise), and a binary BVH larger than the L2 at
  // kPixelBigBvhBlocks. 1 also parks the binary BVH's at 5, 6 and 8 blocks. Not the default at 8:
  // measured on an H100 (docs/notes/gpu-log.md, "A vertex's shadow ray and the next ray in one
  // walk"), 0.984-0.995 of the time in registers on the diffuse icospheres but 1.004 on
  // large-mesh, 1.018 on bunny-armadillo and 1.045 on glass-dragon (it takes 205 KB of an
  // SM's L1).
  bool parked = false;
  // The kernel that runs orders a pixel's samples by their first bounce (pixel.cu:
  // lanes_ordered; sample_order.cuh), and the frame has bvh::kOrderMinSpp samples a pixel or more.
  bool lanes_ordered = false;
};
constexpr uint32_t kPixelLatencyBoundTris = 16384;
// The latency-bound build: 8 blocks (32 registers, ~700 bytes of spills) since the slab
// test's min/max became one instruction each; interleaved on an H200 against 5 blocks
// (48 registers): ico:5 35.81 -> 35.69 ms, ico:7 43.12 -> 42.92, ico:8 49.08 -> 47.96
// (256x256x800 nee; 4 and 6 blocks in between; results/nvidia-h200/archive/pixel-occupancy-8).
constexpr int kPixelLatencyBlocks = 8;
// A binary BVH larger than the device's L2 (its nodes and triangles: GpuScene::Impl::bvh_bytes)
// gets 6 blocks (40 registers) with the path state parked: its node loads miss L2, and at 8
// blocks the spills of the path state (32 registers) compete with them for L2. H100 (50 MB of
// L2), 256x256x800 nee, interleaved against 8 blocks in registers, the same films
// (docs/notes/gpu-log.md, "The big BVHs' megakernel at 6 blocks, parked"): ico:8 (111 MB)
// 0.968, large-mesh (1.1 GB) 0.977; below the L2 it did not pay, bunny-armadillo (11 MB) 1.008,
// glass-dragon (16 MB) 0.994, so those keep 8.
constexpr int kPixelBigBvhBlocks = 6;
// The wide BVH's megakernel holds a node's 20 words and the ray's slab constants across its
// child tests: at 8 blocks (32 registers) it spills them. It gets a count of its own for
// latency-bound scenes, kWideLatencyBlocks (at most 48 registers): on an H100,
// paper-cornell-ico:8 256x256x800 nee, interleaved, 4 blocks 92.76 ms, 5 blocks 92.15, 8
// blocks 103.80 (binary at 8: 43.03; docs/notes/gpu-log.md, "Wide BVH: own occupancy, short
// stack"). Measured with 4 and 6 compiled too; kept to 3, 5 and 8 (each count is one more
// megakernel per material set and variance flag in pixel.cu's compile).
constexpr int kWideLatencyBlocks = 5;
// The leaves layout's megakernel is compiled for 3, 5 and 8 blocks too (PATHBENCH_GPU_PIXEL_BLOCKS).
// With the path state parked in shared memory (PixelOccupancy::parked, pixel.cu's ParkedPath)
// it needs 64 registers and spills nothing (in registers: 80 and 28 / 16 bytes spilled), and
// auto gives it kLeavesParkedBlocks. H100, paper-cornell 256x256x800 nee, same films
// (docs/notes/gpu-log.md, "The path state parked in shared memory"): in registers at 3
// blocks 10.645 ms, at 4 10.749, at 5 10.454; parked at 3 (64 registers: 4 blocks run)
// 10.245, parked at 5 (48 registers, 100 / 84 bytes spilled) 10.131.
constexpr int kLeavesParkedBlocks = 5;
// Long paths: the binary BVH's megakernel at kLongPathBlocks (48 registers) from kLongPathBounces
// bounces where auto would give it 3 (issue bound, below kPixelLatencyBoundTris), and from
// kLongPathLatencyBounces where it would give kPixelLatencyBlocks; unbounded paths count as long.
// A BVH larger than the L2 keeps kPixelBigBvhBlocks. Each path's later bounces go their own ways,
// and more warps hide that better than 3 blocks' registers do. Interleaved on an H200,
// 256x256x800 nee, the same films (docs/notes/gpu-log.md, "Long paths at 5 blocks"), 5 blocks
// against auto's count before:
//   3 blocks: cornell-box at 2 bounces 1.064, 3 1.002, 4 0.963, 5 0.934, 8 0.906 (uniform 0.920);
//     cornell-materials 1.019 / 0.958 / 0.931 at 2 / 3 / 4, 0.884 at 8, 0.856 at 16; cornell-box
//     glass, mirror, ggx at 8: 0.911, 0.920, 0.890; paper-cornell-ico:3 at 4 and 8: 0.940, 0.942;
//   8 blocks: paper-cornell-ico:5 at 4 and 8: 0.967, 0.965; bunny-armadillo 1.009 at 4, 0.979 at 8;
//     glass-dragon at 8 0.986;
//   6 parked (above the L2) at 8 bounces: ico:8 1.060, large-mesh 1.082: kept.
// From 3 bounces, not 4, once short paths over meshes ran at 8 (below): at 3 bounces 5 blocks against
// 8, paper-cornell-ico:2 0.985, ico:4 0.981 (docs/notes/gpu-log.md, "Short paths over meshes at 8
// blocks").
constexpr int kLongPathBlocks = 5;
constexpr int32_t kLongPathBounces = 3, kLongPathLatencyBounces = 8;
// Short paths (fewer than kLongPathBounces bounces) over a binary BVH below kPixelLatencyBoundTris:
// kPixelLatencyBlocks from kPixelTinyTris triangles, 3 below. H200, 2 bounces, 8 blocks against 3
// (docs/notes/gpu-log.md, "Long paths at 5 blocks" and "Short paths over meshes at 8 blocks"):
// paper-cornell-ico:1 (94 triangles) 0.960 / 0.962, ico:2 (334) 0.954 / 0.955, ico:3 (1,294) 0.952 /
// 0.953, ico:4 (5,134) 0.924 / 0.923, ico:5 (20,494) 0.888; the tiniest did not all gain:
// cornell-box (38) 1.077 / 1.078, cornell-materials (50) 0.975 / 0.973 (5 blocks 1.064, 1.018).
constexpr uint32_t kPixelTinyTris = 64;
// l2_bytes: the device's L2 (RenderSetup's DeviceInfo, the cache's copy where one is kept); spp:
// the frame's samples a pixel (PixelOccupancy::lanes_ordered); bounces: the frame's max_bounces
// (-1: unbounded).
PixelOccupancy pixel_occupancy(const GpuScene::Impl& g, uint64_t l2_bytes, uint32_t spp, int32_t bounces);

// How many of the last full rounds of a wavefront stage's grid stride its warps take from
// a counter (work_chunks.cuh): more where traversals diverge (from kPixelLatencyBoundTris
// triangle references on), where static shares end most unevenly. H100, interleaved
// (results/nvidia-h100-80gb-hbm3/archive/work-chunks): paper-cornell 1 round 15.63 ms, 4 rounds
// 16.15; ico:8 (100 spp) 1 round 8.30, 4 rounds 7.70 (grid stride alone: 8.87). With the
// appends in one atomic (wavefront_state.cuh), no full round from the counter (only the
// partial one) took paper-cornell's wavefront 11.19 -> 10.34 ms, 2048x2048x64 62.5 -> 57.3
// and 128x128x16 0.129 -> 0.117; paper-queue and the meshes (4 rounds) unchanged
// (results/nvidia-h100-80gb-hbm3/archive/wavefront-appends-408198e).
constexpr uint32_t kWavefrontCounterRounds = 0, kWavefrontCounterRoundsLatencyBound = 4;

// The pixel megakernel's counters on the device, zeroed before each frame: the stats,
// and the next chunk of 32 samples to hand out (k_pixel takes its work from it).
struct PixelCounters {
  Stats stats;
  unsigned long long chunks;
};

// The pixel megakernel over `total` samples (c.spp per pixel), compiled for the scene's
// material kinds; `counters` is its counter block on the device; `min_blocks` from
// pixel_occupancy (float and watertight only: the accuracy variants keep the compiler's).
FrameResult run_pixel(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c,
                      uint64_t total, FilmDev film, bool variance, Precision precision, bool watertight,
                      DeviceBuffer<PixelCounters>& counters, int min_blocks, bool parked = false);

}  // namespace pb::gpu
