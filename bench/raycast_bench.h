#pragma once
// Raw ray-cast benchmarks, no shading: how fast Embree alone resolves the rays a path
// tracer casts, so each tracer's rays/s can be read against its ceiling.
//   raycast/cpu/<api>/<coherent|incoherent>/<scene>
// api: intersect1 (rtcIntersect1), intersect16 (rtcIntersect16 packets),
//      intersect1M (rtcIntersect1M streams), and the occluded1 / occluded16 /
//      occluded1M variants (rtcOccluded*).
// coherent:   one jittered camera ray per pixel, in image order.
// incoherent: a real diffuse bounce: from each camera ray's first hit, one
//             cosine-distributed direction about the normal facing the camera
//             (origin offset as the path step does); camera rays that miss are dropped.
// Occluded variants trace the same rays with tfar just short of their closest hit,
// so each must be proven unoccluded, like a shadow ray that reaches its light.
// Rays are made once per scene, outside the timed loop; the loop writes them into
// Embree's ray structures (as a tracer must) and casts them on all TBB threads.
// Counter rays_per_second (kIsRate, wall time).
//
// GPU: the GPU BVH ray-cast benchmarks (raycast/gpu/<closest|any>/<coherent|incoherent>/
// <scene>, raycast_gpu_bench.cpp) cast the same stored rays from make_ray_sets(); they
// are registered from bench_main.cpp where PATHBENCH_BENCH_GPU is set.
#include <cstdint>
#include <string>
#include <vector>

#include "pathbench/common/scene.h"

namespace pb::cpu {
class EmbreeScene;
}
namespace pb::bvh {
enum class GpuBvhLayout : uint32_t;
}

namespace pb::bench {

struct RaySet {  // structure of arrays
  std::vector<float> ox, oy, oz, dx, dy, dz;
  std::vector<float> t_occluded;  // tfar for the occluded variants
  size_t size() const { return ox.size(); }
};
struct RaySets {
  RaySet coherent, incoherent;
};
// Camera rays at width x height and their diffuse bounces, found with `embree`
// (built from `scene`), with the occluded variants' distances.
RaySets make_ray_sets(const Scene& scene, const cpu::EmbreeScene& embree, uint32_t width, uint32_t height);

struct RaycastCase {
  std::string scene;
  uint32_t width = 256, height = 256;  // camera rays: one per pixel
};
// Registers every api x {coherent, incoherent} for one scene.
void register_raycast_benchmarks(const RaycastCase& c);
// The GPU BVH's: raycast/gpu/<closest|any>/<coherent|incoherent>/<scene> (CUDA builds),
// in the default layout; with `layouts`, one row set per layout, named .../<scene>/<layout>
// (bvh::GpuBvhLayout, bvh_layout.h; Auto: the default rows), all in one process.
void register_gpu_raycast_benchmarks(const RaycastCase& c);
void register_gpu_raycast_benchmarks(const RaycastCase& c, const std::vector<bvh::GpuBvhLayout>& layouts);

}  // namespace pb::bench
