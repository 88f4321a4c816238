// The OFF reader (the suite's scanned meshes): the cube as OFF is the cube as PLY; hostile
// input is one clear error; COFF's colours are named as lost. The data folder
// ("data:meshes/..." in JSON, a missing file naming its Debian package) and Loop
// subdivision ("subdivide": N) at load time.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <unistd.h>

#include "pathbench/scene_io/data_dir.h"
#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "readers/readers.h"

namespace pb {
namespace {

const std::string kFormats = std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/scenes/formats/";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

scene_io::MeshData off(const std::string& text, const scene_io::Losses& losses = scene_io::Losses()) {
  return scene_io::read_off("t.off", text, losses);
}
std::string off_error(const std::string& text) { return error_of([&] { off(text); }); }

TEST(SceneOff, TheCubeIsThePlyCube) {
  const Scene a = load_scene(kFormats + "cube.off");
  const Scene b = load_scene(kFormats + "cube-ascii.ply");
  ASSERT_EQ(a.triangles.size(), 14u);  // 12 and the default light
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const Vec3f p = a.positions[a.triangles[i].v[k]], q = b.positions[b.triangles[i].v[k]];
      EXPECT_EQ(p.x, q.x);
      EXPECT_EQ(p.y, q.y);
      EXPECT_EQ(p.z, q.z);
    }
  EXPECT_EQ(a.camera.position.z, b.camera.position.z);
  EXPECT_EQ(a.emitters.size(), b.emitters.size());  // the default light, as for a bare PLY
}

TEST(SceneOff, CountsOnTheHeaderLineCommentsAndPolygons) {
  const auto m = off("OFF 5 2 0 # counts on the header line\n# a comment\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\n"
                     "0.5 2 0\n4 0 1 2 3\n3 3 2 4 # a comment after a face\n");
  ASSERT_EQ(m.positions.size(), 5u);
  ASSERT_EQ(m.triangles.size(), 3u);  // the quad fan-triangulated: (0 1 2) (0 2 3)
  EXPECT_EQ(m.triangles[1].v[0], 0u);
  EXPECT_EQ(m.triangles[1].v[1], 2u);
  EXPECT_EQ(m.triangles[1].v[2], 3u);
  EXPECT_EQ(m.positions[4].y, 2.0f);
}

TEST(SceneOff, HostileInputIsOneClearError) {
  const std::string tri = "0 0 0\n1 0 0\n0 1 0\n";
  const std::string tri2 = "0.0000 0 0\n1.0000 0 0\n0.0000 1 0\n";  // long enough for the byte check
  const std::pair<std::string, std::string> cases[] = {
      {"", "t.off: malformed OFF: the file is empty"},
      {"PLY\n3 1 0\n" + tri + "3 0 1 2\n", "not an OFF file (the first word is 'PLY'"},
      {"3 1 0\n" + tri + "3 0 1 2\n", "the header 'OFF' is missing"},
      {"OFF BINARY\n", "binary OFF is not read"},
      {"4OFF\n3 1 0\n", "only 3-dimensional OFF files are read"},
      {"OFF\n", "the file ends before the counts line"},
      {"OFF\n3 x 0\n", "face count: 'x' is not a whole number"},
      {"OFF\n3 -1 0\n", "face count: '-1' is not a whole number"},
      {"OFF\n99999999999 1 0\n" + tri, "more than the 18 bytes left can hold"},
      {"OFF\n3 1 0\n0 0 0\n1\n0 1 0\n3 0 1 2\n", "line 4: vertex 1: expected 'x y z', got 1 value(s)"},
      {"OFF\n3 2 0\n" + tri2 + "3 0 1 2\n", "the file ends after 1 of its 2 faces (truncated?)"},
      {"OFF\n4 1 0\n" + tri2, "the file ends after 3 of its 4 vertices (truncated?)"},
      {"OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "vertex 1 has a NaN or infinite coordinate"},
      {"OFF\n3 1 0\n0 0 0\n1 1e39 0\n0 1 0\n3 0 1 2\n", "vertex 1 has a NaN or infinite coordinate"},
      {"OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", "vertex 1: 'x' is not a number"},
      {"OFF\n3 1 0\n" + tri + "3 0 1 3\n", "line 6: face 0 refers to vertex 3, but the file has only 3 vertices"},
      {"OFF\n3 1 0\n" + tri + "2 0 1\n", "face 0 has 2 corners (at least 3)"},
      {"OFF\n3 1 0\n" + tri + "4 0 1 2\n", "face 0: 4 corners announced, 3 given"},
      {"OFF\n3 1 0\n" + tri + "3 0 1 2\n3 0 1 2\n", "data after the last face"},
      {"OFF\n3 0 0\n" + tri, "the file has no faces"},
      {"OFF\n3 1 0\n" + tri + "99999999999999999999999 0 1 2\n", "is too large"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string err = off_error(text);
    EXPECT_NE(err.find(expected), std::string::npos) << "input:\n" << text << "\nerror: " << err;
    EXPECT_EQ(err.rfind("t.off: malformed OFF: ", 0), 0u) << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << err;
  }
}

TEST(SceneOff, ColoursAreNamedAndStrictRefusesThem) {
  const std::string coff = "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n";
  testing::internal::CaptureStderr();
  const auto m = off(coff);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(m.triangles.size(), 1u);
  EXPECT_NE(err.find("t.off: per-vertex data of COFF"), std::string::npos) << err;
  EXPECT_NE(error_of([&] { off(coff, scene_io::Losses(true)); }).find("not modelled by pathbench (--strict)"),
            std::string::npos);
}

class DataDir : public testing::Test {
 protected:
  std::filesystem::path dir_ = std::filesystem::temp_directory_path() / ("pathbench-data-" + std::to_string(::getpid()));
  std::string saved_;
  bool had_ = false;
  void SetUp() override {
    std::filesystem::create_directories(dir_ / "data" / "meshes");
    if (const char* v = std::getenv("PATHBENCH_DATA_DIR")) had_ = true, saved_ = v;
    ::setenv("PATHBENCH_DATA_DIR", (dir_ / "data").c_str(), 1);
  }
  void TearDown() override {
    if (had_) ::setenv("PATHBENCH_DATA_DIR", saved_.c_str(), 1);
    else ::unsetenv("PATHBENCH_DATA_DIR");
    std::filesystem::remove_all(dir_);
  }
  std::string write(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  std::string scene_with(const std::string& file, const std::string& extra = "") {
    return write(dir_ / "s.json",
                 R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov_y_deg": 40},
                     "materials": {"white": {"albedo": [0.5, 0.5, 0.5]}, "light": {"emission": [1, 1, 1]}},
                     "meshes": [{"file": ")" + file + R"(", "material": "white")" + extra + R"(}],
                     "triangles": [{"material": "light", "vertices": [[-1, 3, -1], [1, 3, -1], [1, 3, 1]],
                                    "indices": [[0, 2, 1]]}]})");
  }
};

TEST_F(DataDir, TheFolderFollowsTheEnvironment) {
  EXPECT_EQ(data_dir(), (dir_ / "data").string());
  ::unsetenv("PATHBENCH_DATA_DIR");
  const char* xdg = std::getenv("XDG_DATA_HOME");
  const std::string saved_xdg = xdg ? xdg : "";
  ::setenv("XDG_DATA_HOME", "/x/share", 1);
  EXPECT_EQ(data_dir(), "/x/share/pathbench/data");
  if (xdg) ::setenv("XDG_DATA_HOME", saved_xdg.c_str(), 1);
  else ::unsetenv("XDG_DATA_HOME");
  EXPECT_EQ(resolve_data_path("cube.obj"), "cube.obj");
}

TEST_F(DataDir, AJsonMeshFromTheDataFolder) {
  std::filesystem::copy_file(kFormats + "cube.off", dir_ / "data" / "meshes" / "cube.off");
  const Scene s = load_scene(scene_with("data:meshes/cube.off"));
  EXPECT_EQ(s.triangles.size(), 13u);
}

TEST_F(DataDir, AMissingSuiteMeshNamesItsPackage) {
  const std::string err = error_of([&] { load_scene(scene_with("data:meshes/bunny00.off")); });
  EXPECT_NE(err.find("s.json: meshes[0].file: 'data:meshes/bunny00.off': no such file (looked for " +
                     (dir_ / "data" / "meshes" / "bunny00.off").string() +
                     "): it comes from the Debian package libcgal-demo; run scripts/install-deps.sh"),
            std::string::npos)
      << err;
  const std::string other = error_of([&] { load_scene(scene_with("data:meshes/mine.off")); });
  EXPECT_NE(other.find("'data:meshes/mine.off': no such file (looked for"), std::string::npos) << other;
  EXPECT_EQ(other.find("Debian package"), std::string::npos) << other;
}

TEST_F(DataDir, ATruncatedMeshIsNamed) {
  write(dir_ / "data" / "meshes" / "armadillo.off", "OFF\n26002 52000 0\n0 0 0\n");
  const std::string err = error_of([&] { load_scene(scene_with("data:meshes/armadillo.off")); });
  EXPECT_NE(err.find("armadillo.off: malformed OFF: line 2: 26002 vertices and 52000 faces: more than the"),
            std::string::npos)
      << err;
}

TEST(LoopSubdivide, ATetrahedronByLoopsWeights) {
  // A closed tetrahedron: every vertex has valence 3, so beta = 3/16; every edge is
  // interior: 3/8 (a + b) + 1/8 (c + d).
  scene_io::MeshData m;
  m.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  m.triangles = {{{0, 1, 2}}, {{0, 3, 1}}, {{0, 2, 3}}, {{1, 3, 2}}};
  m.material_ids = {-1, 0, -1, 0};
  const auto s = scene_io::loop_subdivide(m, 1);
  ASSERT_EQ(s.triangles.size(), 16u);
  ASSERT_EQ(s.positions.size(), 4u + 6u);  // V + E
  // Old vertex 0: (1 - 3 beta) v + beta (sum of the other three) = 7/16 v + 3/16 (-v) = v / 4.
  EXPECT_FLOAT_EQ(s.positions[0].x, 0.25f);
  EXPECT_FLOAT_EQ(s.positions[0].y, 0.25f);
  // Every edge point of a regular tetrahedron centred at 0: 3/8 (a + b) + 1/8 (c + d) = 1/4 (a + b).
  for (size_t e = 4; e < s.positions.size(); ++e) {
    const float r = std::sqrt(s.positions[e].x * s.positions[e].x + s.positions[e].y * s.positions[e].y +
                              s.positions[e].z * s.positions[e].z);
    EXPECT_NEAR(r, 0.5f, 1e-6f) << e;  // |a + b| / 4 with |a + b| = 2
  }
  EXPECT_EQ(s.material_ids[4], 0);  // children keep their parent's material
  EXPECT_EQ(s.material_ids[11], -1);
  // Winding kept: every child faces the same way as its parent (outwards).
  for (size_t f = 0; f < s.triangles.size(); ++f) {
    const Vec3f a = s.positions[s.triangles[f].v[0]], b = s.positions[s.triangles[f].v[1]],
                c = s.positions[s.triangles[f].v[2]];
    const Vec3f n = cross(b - a, c - a), centre = (a + b + c) * (1.0f / 3);
    EXPECT_GT(dot(n, centre), 0) << f;
  }
  EXPECT_EQ(scene_io::loop_subdivide(m, 3).triangles.size(), 4u * 64u);
}

TEST(LoopSubdivide, AnOpenTriangleKeepsItsBoundary) {
  scene_io::MeshData m;
  m.positions = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  m.triangles = {{{0, 1, 2}}};
  m.material_ids = {-1};
  const auto s = scene_io::loop_subdivide(m, 1);
  ASSERT_EQ(s.positions.size(), 6u);
  // A boundary corner: 3/4 v + 1/8 (its two boundary neighbours).
  EXPECT_FLOAT_EQ(s.positions[0].x, 0.5f);
  EXPECT_FLOAT_EQ(s.positions[0].y, 0.5f);
  EXPECT_FLOAT_EQ(s.positions[1].x, 3.0f);
  // A boundary edge point: the midpoint.
  bool found = false;
  for (size_t e = 3; e < 6; ++e) found = found || (s.positions[e].x == 2 && s.positions[e].y == 0);
  EXPECT_TRUE(found);
}

TEST(LoopSubdivide, ASceneTooLargeIsRefusedBeforeItIsBuilt) {
  scene_io::MeshData m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles.assign(70000, Triangle{{0, 1, 2}});
  EXPECT_NE(error_of([&] { scene_io::loop_subdivide(m, 4); }).find("70000 triangles subdivided 4 times make 17920000"),
            std::string::npos);
}

}  // namespace
}  // namespace pb
