// Scene files: scenes/paper-cornell.json is the built-in paper-cornell exactly; OBJ
// files bring their MTL materials, a framing camera and, without an emitter, a
// default light; JSON meshes are placed by their transforms.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "test_scene_helpers.h"

namespace pb {
namespace {

const std::string kScenes = std::string(PATHBENCH_SOURCE_DIR) + "/scenes/";

void expect_same_vec(Vec3f a, Vec3f b, const std::string& what) {
  EXPECT_EQ(a.x, b.x) << what;
  EXPECT_EQ(a.y, b.y) << what;
  EXPECT_EQ(a.z, b.z) << what;
}

using scene_test::expect_emitters_face_down;
using scene_test::material_named;

TEST(SceneJson, PaperCornellFileIsTheBuiltin) {
  const Scene a = make_paper_cornell();
  const Scene b = load_scene(kScenes + "paper-cornell.json");
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      expect_same_vec(a.positions[a.triangles[i].v[k]], b.positions[b.triangles[i].v[k]],
                      "triangle " + std::to_string(i) + " vertex " + std::to_string(k));
    EXPECT_EQ(a.material_ids[i], b.material_ids[i]) << "triangle " << i;
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  EXPECT_EQ(a.material_names, b.material_names);
  for (size_t i = 0; i < a.materials.size(); ++i) {
    expect_same_vec(a.materials[i].albedo, b.materials[i].albedo, "albedo of " + a.material_names[i]);
    expect_same_vec(a.materials[i].emission, b.materials[i].emission, "emission of " + a.material_names[i]);
  }
  expect_same_vec(a.camera.position, b.camera.position, "camera position");
  expect_same_vec(a.camera.forward, b.camera.forward, "camera forward");
  expect_same_vec(a.camera.right, b.camera.right, "camera right");
  expect_same_vec(a.camera.up, b.camera.up, "camera up");
  EXPECT_EQ(a.camera.tan_half_fov_y, b.camera.tan_half_fov_y);
  EXPECT_EQ(a.emitters, b.emitters);
  EXPECT_EQ(a.emitter_power_total, b.emitter_power_total);
}

TEST(SceneJson, MeshesArePlacedByTheirTransforms) {
  const Scene s = load_scene(kScenes + "mesh-example.json");
  EXPECT_EQ(s.triangles.size(), 2u * 12 + 4);
  // The blue cube: unit cube scaled by 1.2 and moved to (-1, 0.6, 0).
  const uint32_t blue = material_named(s, "blue");
  Vec3f lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (size_t i = 0; i < s.triangles.size(); ++i)
    if (s.material_ids[i] == blue)
      for (uint32_t v : s.triangles[i].v) {
        lo = vmin(lo, s.positions[v]);
        hi = vmax(hi, s.positions[v]);
      }
  EXPECT_NEAR(lo.x, -1.6f, 1e-5);
  EXPECT_NEAR(hi.x, -0.4f, 1e-5);
  EXPECT_NEAR(lo.y, 0.0f, 1e-5);
  EXPECT_NEAR(hi.y, 1.2f, 1e-5);
  EXPECT_EQ(s.emitters.size(), 2u);
}

TEST(SceneObj, MaterialsComeFromTheMtl) {
  testing::internal::CaptureStderr();
  const Scene s = load_scene(kScenes + "boxes.obj");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err.find("default area light"), std::string::npos) << err;
  EXPECT_EQ(s.triangles.size(), 2u + 2 + 12 + 12 + 2);
  const Material& red = s.materials[material_named(s, "red")];
  EXPECT_FLOAT_EQ(red.albedo.x, 0.63f);
  EXPECT_FLOAT_EQ(red.albedo.y, 0.065f);
  const Material& light = s.materials[material_named(s, "light")];
  EXPECT_FLOAT_EQ(light.emission.x, 12);
  expect_emitters_face_down(s, 2);
  // The framing camera looks at the middle of the model from in front (+z).
  EXPECT_GT(s.camera.position.z, s.bounds_max.z);
  EXPECT_LT(s.camera.forward.z, 0);
}

class TempDir : public ::testing::Test {
 protected:
  std::filesystem::path dir;
  void SetUp() override {
    dir = std::filesystem::temp_directory_path() /
          ("pathbench-scene-test-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir);
  }
  void TearDown() override { std::filesystem::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

using SceneObjFile = TempDir;

TEST_F(SceneObjFile, WithoutAnEmitterGetsADefaultLightAndSaysSo) {
  testing::internal::CaptureStderr();
  const Scene s = load_scene(kScenes + "cube.obj");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("cube.obj"), std::string::npos) << err;
  EXPECT_NE(err.find("default area light"), std::string::npos) << err;
  EXPECT_EQ(s.triangles.size(), 12u + 2);
  expect_emitters_face_down(s, 2);
  for (uint32_t e : s.emitters)
    for (uint32_t v : s.triangles[e].v) EXPECT_GT(s.positions[v].y, 0.5f) << "above the cube's top";
  // Faces without usemtl get the grey default.
  EXPECT_FLOAT_EQ(s.materials[s.material_ids[0]].albedo.x, 0.5f);
}

TEST_F(SceneObjFile, KdIsClampedAndKeEmits) {
  write("m.mtl", "newmtl hot\nKd 1.5 -0.2 0.3\nKe 2 3 4\n");
  const std::string obj = write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl hot\nf 1 2 3 4\n");
  const Scene s = load_scene(obj);
  ASSERT_EQ(s.triangles.size(), 2u) << "the quad is triangulated, no default light";
  const Material& m = s.materials[s.material_ids[0]];
  EXPECT_EQ(m.albedo.x, 1.0f);
  EXPECT_EQ(m.albedo.y, 0.0f);
  EXPECT_FLOAT_EQ(m.albedo.z, 0.3f);
  EXPECT_FLOAT_EQ(m.emission.z, 4.0f);
}

TEST_F(SceneObjFile, RelativeAndForwardIndicesAndPlusSignsWork) {
  const std::string obj = write("r.obj", "f 1 2 3\nv 0 0 0\nv +1 0 0\nv 0 1.0e+0 0\nf -3 -2 -1\n");
  testing::internal::CaptureStderr();
  const Scene s = load_scene(obj);
  testing::internal::GetCapturedStderr();
  EXPECT_EQ(s.triangles.size(), 2u + 2);
  EXPECT_EQ(s.positions[1].x, 1.0f);
}

TEST_F(SceneObjFile, TheLargestBadIndexIsReportedWithItsLine) {
  const std::string obj = write("b.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  try {
    load_scene(obj);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.obj:5: face refers to vertex 9"), std::string::npos) << e.what();
  }
}

TEST(SceneFiles, ZeroAreaTrianglesAreDroppedWithAWarning) {
  testing::internal::CaptureStderr();
  const Scene s = load_scene(std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/scenes/zero-area.json");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(s.dropped_triangles, 1u);
  EXPECT_NE(err.find("zero-area.json"), std::string::npos) << err;
  EXPECT_NE(err.find("dropped 1 zero-area triangle"), std::string::npos) << err;
}

}  // namespace
}  // namespace pb
