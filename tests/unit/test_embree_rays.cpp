// The CPU's Embree rays and the GPU's watertight test skip the same hits at the ray's own
// origin: t <= ray_t_min(o, d) (watertight.h; embree_rays.h sets it as tnear). The rays
// below are from paper-cornell renders (256x256x800, seeds 0-3) where the CPU's and the
// GPU's films differed: each leaves a corner of the box, offset off the wall it hit but
// still exactly in the plane of the other wall, and heads out through that plane. With
// tnear = 0 Embree met that wall at t = 0 (or -0), and the GPU's test at t = 1e-12 ..
// 5e-7 where rounding made it positive: blocked or hit on one device, clear on the other.
#include <gtest/gtest.h>

#include "embree_rays.h"
#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb::cpu {
namespace {

struct CornerRay {
  Vec3f o, d;
};
// Shadow rays (t in (0, 1) along d to a point of the light): clear on the GPU.
const CornerRay kCornerShadowRays[] = {
    {{10, 1.72981358f, -9.99975586f}, {-12.3443165f, 8.1699419f, 5.63750792f}},     // on x = 10
    {{10, -2.5304842f, -9.99975586f}, {-5.56071138f, 12.4302397f, 5.57181978f}},    // on x = 10
    {{-9.99975586f, -6.67440414f, -10}, {5.02982426f, 16.5741596f, 4.25053787f}},   // on z = -10
    {{1.81290627f, -9.99975586f, 22}, {-2.61548662f, 19.8995113f, -27.198185f}},    // on z = 22
    {{2.71856713f, -10, 21.9995117f}, {1.53906274f, 19.8997555f, -29.017374f}},     // on y = -10
};

TEST(EmbreeRays, AHitAtTZeroDoesNotCount) {
  const Scene scene = load_scene("paper-cornell");
  for (const EmbreeLayout layout : {EmbreeLayout::Triangles, EmbreeLayout::Quads}) {
    const auto embree = make_embree_scene(scene, /*watertight=*/true, layout);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (const CornerRay& r : kCornerShadowRays) {
      const Ray<float> ray{r.o, r.d};
      EXPECT_FALSE(occluded(*embree, ctx, ray, 1.0f)) << "layout " << int(layout) << ", origin " << r.o.x << " "
                                                      << r.o.y << " " << r.o.z;
      // The closest hit is the light, far along the ray: not the wall at the origin.
      const uint32_t prim = closest_triangle(*embree, ctx, ray);
      ASSERT_NE(prim, RTC_INVALID_GEOMETRY_ID);
      EXPECT_EQ(scene.material_ids[prim], 3u) << "the light";
    }
  }
}

// Closest-hit rays (unit directions) that the GPU's test met in the plane they start in
// (at t = 5e-7, 1.8e-11, 1.3e-11, 5.3e-7) and Embree did not.
const CornerRay kCornerBounceRays[] = {
    {{10, 9.99975586f, -2.2639389f}, {0.300628424f, -0.526233315f, -0.795425117f}},    // on x = 10, heading out
    {{-3.27794838f, 10, -9.99975586f}, {-0.291737974f, -0.297914326f, 0.908920228f}},  // on y = 10
    {{10, -5.40539646f, -9.99975586f}, {0.574718058f, -0.514556289f, 0.63634187f}},    // on x = 10, heading out
    {{-10, -9.99975586f, 1.83931351f}, {-0.173614994f, 0.623392761f, -0.762390554f}},  // on x = -10, heading out
};

// The same rays through the GPU's traversal (host+device code, run here): the shadow rays
// clear, the bounce rays' closest hits Embree's, never the plane they start in.
TEST(EmbreeRays, TheGpuTraversalAgrees) {
  const Scene scene = load_scene("paper-cornell");
  const bvh::SceneBvhHost bvh = bvh::build_scene_bvh(scene, bvh::GpuBvhOptions{});
  for (const CornerRay& r : kCornerShadowRays) EXPECT_FALSE(bvh::occluded(bvh.view(), r.o, r.d, 1.0f));
  const auto embree = make_embree_scene(scene, /*watertight=*/true, EmbreeLayout::Triangles);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  for (const CornerRay& r : kCornerBounceRays) {
    float t = 0;
    const uint32_t gpu_prim = bvh::intersect_closest(bvh.view(), r.o, r.d, INFINITY, t);
    const uint32_t cpu_prim = closest_triangle(*embree, ctx, Ray<float>{r.o, r.d});
    EXPECT_EQ(gpu_prim == bvh::kNoHit ? RTC_INVALID_GEOMETRY_ID : gpu_prim, cpu_prim)
        << "origin " << r.o.x << " " << r.o.y << " " << r.o.z;
    if (gpu_prim != bvh::kNoHit) EXPECT_GT(t, 0.01f) << "a hit at the ray's own origin";
  }
}

TEST(EmbreeRays, TMinIsAFewUlpsOfTheOrigin) {
  EXPECT_EQ(ray_t_min({0, 0, 0}, {0, 0, 1}), 0.0f);
  EXPECT_EQ(ray_t_min({8, -2, 1}, {0, 0, 1}), 8 * 0x1p-21f);       // 4 ulps of 8
  EXPECT_EQ(ray_t_min({8, -2, 1}, {0, -4, 1}), 8 * 0x1p-21f * 0.25f);  // t along d: |d|_inf = 4
  EXPECT_EQ(ray_t_min({1, 2, 3}, {0, 0, 0}), 0.0f);                // no direction: no bound
  // The triangle test's own evaluation (from the sheared ray) is the same number.
  for (const Vec3f d : {Vec3f{0.3f, -0.7f, 0.2f}, Vec3f{-5, 5, 1}, Vec3f{1e-3f, 2e-3f, -2e-3f}, Vec3f{0, 0, -3}}) {
    const Vec3f o{9.99975586f, -3.5f, 21.9995117f};
    EXPECT_EQ(t_min_of(make_watertight_ray(o, d)), ray_t_min(o, d));
  }
}

}  // namespace
}  // namespace pb::cpu
