// The CPU's Embree rays count hits at t > 0, as the path step and the GPU's watertight
// test do (embree_rays.h, kEmbreeTnear). The rays below are from paper-cornell renders
// (256x256x800, seed 0) where the CPU's and the GPU's films differed: each leaves a corner
// of the box, offset off the wall it hit but still exactly in the plane of the other wall,
// and heads out through that plane. With tnear = 0 Embree met that wall at t = 0 (or -0).
#include <gtest/gtest.h>

#include "embree_rays.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/gpu/bvh_layout.h"

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

// The same rays through the GPU's traversal (host+device code, run here): clear too.
TEST(EmbreeRays, TheGpuTraversalAgrees) {
  const Scene scene = load_scene("paper-cornell");
  const gpu::SceneBvhHost bvh = gpu::build_scene_bvh(scene, gpu::GpuBvhOptions{});
  for (const CornerRay& r : kCornerShadowRays)
    EXPECT_FALSE(gpu::occluded(bvh.view(), r.o, r.d, 1.0f));
}

}  // namespace
}  // namespace pb::cpu
