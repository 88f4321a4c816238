// Hostile input (issue 12): special files, size limits, the supported coordinate and
// emission ranges, and the guard against a film of discarded samples. Every case is
// one InputError naming the file and the limit, and none may hang or read without end.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "pathbench/analysis/bench_compare.h"
#include "pathbench/run/run.h"
#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/limits.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb {
namespace {

namespace fs = std::filesystem;
const std::string kData = std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/scenes/";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// A fresh folder per test, removed afterwards.
class SpecialFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pathbench-hostile-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const char* name) const { return (dir_ / name).string(); }
  void write(const char* name, const std::string& text) const { std::ofstream(path(name)) << text; }
  fs::path dir_;
};

TEST_F(SpecialFiles, FifoSceneIsRefusedWithoutBlocking) {
  ASSERT_EQ(::mkfifo(path("fifo.json").c_str(), 0600), 0);
  EXPECT_NE(error_of([&] { load_scene(path("fifo.json")); }).find("is a FIFO; a scene file (JSON) must be a regular file"),
            std::string::npos);
}

TEST_F(SpecialFiles, DeviceBehindASymlinkIsRefused) {
  fs::create_symlink("/dev/zero", path("zero.json"));
  fs::create_symlink("/dev/urandom", path("random.obj"));
  EXPECT_NE(error_of([&] { load_scene(path("zero.json")); }).find("is a character device"), std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(path("random.obj")); }).find("a mesh file (OBJ) must be a regular file"),
            std::string::npos);
}

TEST_F(SpecialFiles, FifoMaterialLibraryIsRefused) {
  ASSERT_EQ(::mkfifo(path("fifo.mtl").c_str(), 0600), 0);
  write("m.obj", "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(error_of([&] { load_scene(path("m.obj")); }).find("fifo.mtl: is a FIFO; a material library (MTL)"),
            std::string::npos);
}

TEST_F(SpecialFiles, DirectoryAndSymlinkLoop) {
  fs::create_directories(path("dir.json"));
  fs::create_symlink(path("loop.json"), path("loop.json"));
  EXPECT_NE(error_of([&] { load_scene(path("dir.json")); }).find("is a directory"), std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(path("loop.json")); }).find("too many levels of symbolic links"),
            std::string::npos);
}

// A sparse file over the limit is refused from its size, before anything is read.
TEST_F(SpecialFiles, OversizedFilesNameTheLimit) {
  for (const char* name : {"big.json", "big.obj"}) {
    std::ofstream(path(name)).close();
    fs::resize_file(path(name), limits::kMaxMeshBytes + 1);
  }
  EXPECT_NE(error_of([&] { load_scene(path("big.json")); }).find("scene file (JSON)s are limited to 64 MiB"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(path("big.obj")); }).find("mesh file (OBJ)s are limited to 256 MiB"),
            std::string::npos);
  write("small.txt", "0123456789");
  EXPECT_NE(error_of([&] { read_input_file(path("small.txt"), "test file", 4); })
                .find("test files are limited to 4 bytes (this one has 10 bytes)"),
            std::string::npos);
  EXPECT_EQ(read_input_file(path("small.txt"), "test file", 10), "0123456789");
}

// One JSON scene naming the same mesh many times: the mesh files share one budget.
TEST_F(SpecialFiles, MeshBytesAddUpPerScene) {
  // Just over half the budget, as one long comment (cheap to parse): the second use
  // of the file goes over.
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n#";
  obj.resize(size_t(limits::kMaxMeshBytes / 2 + 1), 'x');
  obj += "\n";
  write("m.obj", obj);
  write("s.json", R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov_y_deg": 40},
    "materials": {"grey": {"albedo": [0.5, 0.5, 0.5], "emission": [1, 1, 1]}},
    "meshes": [{"file": "m.obj", "material": "grey"}, {"file": "m.obj", "material": "grey"}]})");
  EXPECT_NE(error_of([&] { load_scene(path("s.json")); })
                .find("the mesh files (OBJ, PLY, OFF) of one scene are limited to 256 MiB in all"),
            std::string::npos);
}

// JSON within its size limit that would still cost gigabytes or quadratic time.
TEST_F(SpecialFiles, JsonDepthAndKeysAreBounded) {
  write("deep.json", std::string(100000, '['));
  std::string keys = "{";
  for (int i = 0; i <= 10000; ++i) keys += (i ? ",\"k" : "\"k") + std::to_string(i) + "\": 0";
  write("keys.json", keys + "}");
  for (auto load : {std::function<void(const std::string&)>([](const std::string& p) { load_scene(p); }),
                    std::function<void(const std::string&)>([](const std::string& p) { analysis::load_benchmark_json(p, 2); })}) {
    EXPECT_NE(error_of([&] { load(path("deep.json")); }).find("deep.json: JSON nested deeper than 64 levels"),
              std::string::npos);
    EXPECT_NE(error_of([&] { load(path("keys.json")); }).find("keys.json: a JSON object with more than 10000 keys"),
              std::string::npos);
  }
}

TEST_F(SpecialFiles, CompareReadsRegularFilesOnly) {
  ASSERT_EQ(::mkfifo(path("fifo.json").c_str(), 0600), 0);
  EXPECT_NE(error_of([&] { analysis::load_benchmark_json(path("fifo.json"), 2); })
                .find("is a FIFO; a benchmark JSON file must be a regular file"),
            std::string::npos);
  EXPECT_NE(error_of([&] { analysis::load_benchmark_json(dir_.string(), 2); }).find("is a directory"), std::string::npos);
  write("typed.json", R"({"context": {}, "benchmarks": [{"name": 5}]})");
  EXPECT_NE(error_of([&] { analysis::load_benchmark_json(path("typed.json"), 2); })
                .find("benchmarks[0].name: expected a string, got number 5"),
            std::string::npos);
  write("long.json", R"({"context": {}, "benchmarks": [{"name": ")" + std::string(2000, 'x') + R"("}]})");
  EXPECT_NE(error_of([&] { analysis::load_benchmark_json(path("long.json"), 2); })
                .find("a benchmark name of 2000 bytes (at most 1024)"),
            std::string::npos);
}

// A reference image whose header asks for 10^10 pixels it does not have.
TEST_F(SpecialFiles, PfmHeaderMustMatchItsData) {
  write("lie.pfm", std::string("PF\n100000 100000\n-1.0\n") + std::string(24, '\0'));
  unsigned w = 0, h = 0;
  EXPECT_NE(error_of([&] { read_image(path("lie.pfm"), w, h); })
                .find("a 100000x100000 PFM needs 120000000000 bytes of pixels, the file has 24"),
            std::string::npos);
  ASSERT_EQ(::mkfifo(path("fifo.pfm").c_str(), 0600), 0);
  EXPECT_NE(error_of([&] { read_image(path("fifo.pfm"), w, h); }).find("is a FIFO"), std::string::npos);
  const std::vector<float> rgb = {1, 2, 3, 4, 5, 6};  // 1 wide, 2 high: row order matters
  write_image(path("ok.pfm"), rgb, 1, 2);
  EXPECT_EQ(read_image(path("ok.pfm"), w, h), rgb);
  EXPECT_EQ(w, 1u);
  EXPECT_EQ(h, 2u);
}

TEST(Ranges, OutOfRangeScenesAreInputErrors) {
  const std::pair<const char*, const char*> cases[] = {
      {"huge-vertex.json", "vertex 1 (1e+20, 0, 0) is outside the supported coordinate range +-1e+15"},
      {"huge-scale.json", "outside the supported coordinate range +-1e+15 (after any transform)"},
      {"huge-camera.json", "the camera position (0, 0, 2e+15) is outside the supported coordinate range"},
      {"huge-triangle.json", "triangle 0 is too large for float arithmetic"},
      {"huge-emission.json", "material 'lamp' has emission 3e+38, above the supported maximum 1e+20"},
      {"mtllib-dev-zero.obj", "/dev/zero: is a character device"},
  };
  for (const auto& [file, message] : cases)
    EXPECT_NE(error_of([&] { load_scene(kData + file); }).find(message), std::string::npos) << file;
  EXPECT_NE(error_of([] { load_scene("furnace:0.5,3e38"); }).find("above the supported maximum 1e+20"),
            std::string::npos);
  EXPECT_NO_THROW(load_scene("furnace:0.5,1e20"));
}

TEST(Ranges, MostlyDiscardedRenderFails) {
  const Scene scene = load_scene("furnace");
  RenderSettings s;
  s.width = 4;
  s.height = 4;
  s.spp = 2;
  RunReport report;
  report.discarded_samples = 16;  // half: still accepted
  EXPECT_NO_THROW(run::check_discarded(scene, s, report));
  report.discarded_samples = 17;
  EXPECT_NE(error_of([&] { run::check_discarded(scene, s, report); })
                .find("17 of 32 samples (53.1%) were discarded as NaN, infinite or beyond the film's range"),
            std::string::npos);
}

}  // namespace
}  // namespace pb
