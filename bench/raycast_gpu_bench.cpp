// Raw ray casts through the GPU BVH (no shading): the GPU tracers' ceiling, beside the
// Embree ones of raycast_bench.cpp and on the same stored rays.
//   raycast/gpu/<closest|any>/<coherent|incoherent>/<scene>           (the default layout)
//   raycast/gpu/<closest|any>/<coherent|incoherent>/<scene>/<layout>  (binary, wide4, wide8,
//                                                                     brute, leaves: bvh_layout.h)
// Each iteration is one launch of the traversal kernel over every ray (the stored rays
// repeated to at least 4 M), timed with CUDA events after a warm-up launch
// (UseManualTime).
#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <memory>

#include "pathbench/common/errors.h"
#include "pathbench/cpu/embree_scene.h"
#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/run/run.h"
#include "pathbench/run/tracer.h"
#include "raycast_bench.h"
#include "scene_cache.h"

namespace pb::bench {

namespace {

struct GpuPrepared {
  std::unique_ptr<run::PreparedScene> scene;  // the GPU's BVH, uploaded (run/tracer.h)
  std::vector<run::RayQuery> coherent, incoherent;
};

// The stored rays, repeated until one launch holds at least kMinRays: 65,536 camera rays
// alone leave an H100 mostly idle and measure launch latency, not traversal.
constexpr size_t kMinRays = size_t(1) << 22;

std::vector<run::RayQuery> to_queries(const RaySet& s, bool any_hit) {
  std::vector<run::RayQuery> q;
  if (s.size() == 0) return q;
  const size_t copies = (kMinRays + s.size() - 1) / s.size();
  q.reserve(copies * s.size());
  for (size_t c = 0; c < copies; ++c)
    for (size_t i = 0; i < s.size(); ++i)
      q.push_back({{s.ox[i], s.oy[i], s.oz[i]}, {s.dx[i], s.dy[i], s.dz[i]}, any_hit ? s.t_occluded[i] : 3.402823466e38f});
  return q;
}

// Brute force tests every triangle for every ray: past this many it only burns time.
constexpr size_t kBruteBenchMaxTriangles = 4096;

// `layout` Auto: the options from the environment (what renders use).
void run_gpu_raycast(benchmark::State& state, const RaycastCase& c, bool any_hit, bool coherent,
                     bvh::GpuBvhLayout layout) {
  std::string why;
  if (!run::gpu_available(&why)) {
    state.SkipWithError(("no GPU: " + why).c_str());
    return;
  }
  std::shared_ptr<GpuPrepared> prep;
  const std::string kind = fmt::format("gpu-raycast:{}x{}:{}:{}", c.width, c.height, any_hit ? "any" : "closest",
                                       bvh::to_string(layout));
  try {
    prep = std::static_pointer_cast<GpuPrepared>(cached_extra(c.scene, kind));
    if (!prep) {
      std::shared_ptr<const Scene> scene = cached_scene(c.scene);
      if (layout == bvh::GpuBvhLayout::Brute && scene->triangles.size() > kBruteBenchMaxTriangles) {
        state.SkipWithError(fmt::format("brute force on {} triangles: over {}", scene->triangles.size(),
                                        kBruteBenchMaxTriangles).c_str());
        return;
      }
      if (layout == bvh::GpuBvhLayout::Leaves && scene->triangles.size() > bvh::kLeavesMaxTriangles) {
        state.SkipWithError(fmt::format("leaves on {} triangles: over {}", scene->triangles.size(),
                                        bvh::kLeavesMaxTriangles).c_str());
        return;
      }
      const RaySets rays = make_ray_sets(*scene, *cpu::make_embree_scene(*scene, RenderSettings{}.watertight), c.width,
                                         c.height);
      prep = std::make_shared<GpuPrepared>();
      bvh::GpuBvhOptions options = bvh::GpuBvhOptions::from_env();
      if (layout != bvh::GpuBvhLayout::Auto) options.layout = layout;
      prep->scene = run::gpu_tracer().prepare_bvh(*scene, options);
      prep->coherent = to_queries(rays.coherent, any_hit);
      prep->incoherent = to_queries(rays.incoherent, any_hit);
      store_extra(c.scene, kind, prep);
    }
  } catch (const InputError& e) {
    state.SkipWithError(fmt::format("scene not available: {}", e.what()).c_str());
    return;
  }
  const std::vector<run::RayQuery>& rays = coherent ? prep->coherent : prep->incoherent;
  if (rays.empty()) {
    state.SkipWithError("no rays: every camera ray missed the scene");
    return;
  }
  for (auto _ : state) {
    try {
      state.SetIterationTime(prep->scene->time_rays(rays, any_hit, 1).front());
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      break;
    }
  }
  using benchmark::Counter;
  state.counters["rays_per_second"] = Counter(double(rays.size()), Counter::kIsIterationInvariantRate);
  state.counters["rays"] = double(rays.size());
  state.counters["triangles"] = double(cached_scene(c.scene)->triangles.size());
}

}  // namespace

void register_gpu_raycast_benchmarks(const RaycastCase& c) { register_gpu_raycast_benchmarks(c, {bvh::GpuBvhLayout::Auto}); }

void register_gpu_raycast_benchmarks(const RaycastCase& c, const std::vector<bvh::GpuBvhLayout>& layouts) {
  for (bvh::GpuBvhLayout layout : layouts)
    for (bool any_hit : {false, true})
      for (bool coherent : {true, false}) {
        std::string name = fmt::format("raycast/gpu/{}/{}/{}", any_hit ? "any" : "closest",
                                       coherent ? "coherent" : "incoherent", c.scene);
        if (layout != bvh::GpuBvhLayout::Auto) name += std::string("/") + bvh::to_string(layout);
        benchmark::RegisterBenchmark(name.c_str(), [c, any_hit, coherent, layout](benchmark::State& st) {
          run_gpu_raycast(st, c, any_hit, coherent, layout);
        })->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(20);  // each re-uploads the rays (untimed)
      }
}

}  // namespace pb::bench
