// The example scenes (scenes/examples/) load and render (a small frame, CPU) to a lit
// image; an instanced scene renders bit-identically to the same scene flattened by hand.
#include <gtest/gtest.h>

#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"

namespace pb {
namespace {

const std::string kRoot = std::string(PATHBENCH_SOURCE_DIR) + "/";

RenderSettings small() {
  RenderSettings s;
  s.width = 24;
  s.height = 18;
  s.spp = 4;
  s.threads = 1;
  s.progress = false;
  s.embree_layout = EmbreeLayout::Triangles;
  return s;
}

double mean_of(const Film& film) {
  double sum = 0;
  const std::vector<float> rgb = film.mean();
  for (float v : rgb) sum += v;
  return sum / double(rgb.size());
}

TEST(SceneExamples, EachRendersLit) {
  for (const char* name : {"instancing.json", "mitsuba-box.xml", "pyramids.gltf"}) {
    SCOPED_TRACE(name);
    testing::internal::CaptureStderr();
    const Scene scene = load_scene(kRoot + "scenes/examples/" + name);
    testing::internal::GetCapturedStderr();
    EXPECT_TRUE(scene.features.has_emitters);
    const run::Rendered r = run::render(scene, small());
    EXPECT_GT(mean_of(r.film), 0.01);
    EXPECT_EQ(r.report.discarded_samples, 0u);
  }
  // What the examples are there to show.
  const Scene inst = load_scene(kRoot + "scenes/examples/instancing.json");
  EXPECT_EQ(inst.instances.size(), 8u);
  testing::internal::CaptureStderr();
  const Scene xml = load_scene(kRoot + "scenes/examples/mitsuba-box.xml");
  const Scene gltf = load_scene(kRoot + "scenes/examples/pyramids.gltf");
  testing::internal::GetCapturedStderr();
  EXPECT_TRUE(xml.features.uses(MaterialKind::Dielectric));
  EXPECT_TRUE(xml.features.uses(MaterialKind::RoughConductor));
  EXPECT_TRUE(gltf.features.uses(MaterialKind::RoughConductor));  // the metallic pyramid
  EXPECT_EQ(gltf.instances.size(), 5u);
}

TEST(SceneExamples, InstancedAndFlattenedRenderTheSame) {
  const std::string dir = kRoot + "tests/data/scenes/formats/";
  const Scene instanced = load_scene(dir + "instanced.json");
  const Scene flat = load_scene(dir + "flattened.json");
  ASSERT_FALSE(instanced.instances.empty());
  EXPECT_TRUE(flat.instances.empty());
  ASSERT_EQ(instanced.positions.size(), flat.positions.size());
  for (size_t i = 0; i < flat.positions.size(); ++i) {
    EXPECT_EQ(instanced.positions[i].x, flat.positions[i].x) << i;
    EXPECT_EQ(instanced.positions[i].y, flat.positions[i].y) << i;
    EXPECT_EQ(instanced.positions[i].z, flat.positions[i].z) << i;
  }
  EXPECT_EQ(run::render(instanced, small()).film.raw_sums(), run::render(flat, small()).film.raw_sums());
}

}  // namespace
}  // namespace pb
