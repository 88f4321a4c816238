#include "loading_bench.h"

#include <benchmark/benchmark.h>
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/common/scene_warnings.h"

namespace pb::bench {

namespace {

namespace fs = std::filesystem;

// The generated files, in one folder removed when the program ends.
struct Folder {
  fs::path dir = fs::temp_directory_path() / fmt::format("pathbench-loading-{}", ::getpid());
  Folder() { fs::create_directories(dir); }
  ~Folder() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

fs::path folder() {
  static Folder f;
  return f.dir;
}

// `name` in the folder, written by `make` the first time it is asked for.
std::string generated(const std::string& name, const std::function<std::string()>& make) {
  const fs::path path = folder() / name;
  if (!fs::exists(path)) std::ofstream(path, std::ios::binary) << make();
  return path.string();
}

// One triangle as a base64 data URI (36 bytes of floats: (0,0,0), (1,0,0), (0,1,0)).
const char* const kTriangleUri = "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";

std::string repeated(const std::string& item, uint64_t n) {
  std::string out;
  out.reserve(n * (item.size() + 2));
  for (uint64_t i = 0; i < n; ++i) out += (i ? ", " : "") + item;
  return out;
}

// Node 0 names node 1 n/1000 times, node 1 names node 2 (the mesh) 1000 times.
std::string gltf_placements(uint64_t n) {
  return fmt::format(R"({{"asset": {{"version": "2.0"}}, "buffers": [{{"byteLength": 36, "uri": "{}"}}],
"bufferViews": [{{"buffer": 0, "byteLength": 36}}],
"accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
"materials": [], "nodes": [{{"children": [{}]}}, {{"children": [{}]}}, {{"mesh": 0, "translation": [0.5, 0.25, 0]}}],
"scenes": [{{"nodes": [0]}}]}})",
                     kTriangleUri, repeated("1", n / 1000), repeated("2", 1000));
}

std::string json_instances(uint64_t n) {
  generated("quad.obj", [] { return std::string("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"); });
  std::string list;
  list.reserve(n * 40);
  for (uint64_t i = 0; i < n; ++i)
    list += fmt::format("{}{{\"translate\": [{}, {}, 0]}}", i ? ",\n" : "", i % 1000, i / 1000);
  return R"({"camera": {"position": [500, 500, 2000], "look_at": [500, 500, 0], "fov_y_deg": 40},
"materials": {"grey": {"albedo": [0.5, 0.5, 0.5], "emission": [1, 1, 1]}},
"meshes": [{"file": "quad.obj", "material": "grey", "instances": [)" +
         list + "]}]}";
}

std::string mitsuba_spheres(uint64_t n) {
  std::string out = R"(<scene version="3.0.0"><sensor type="perspective"><transform name="to_world">
<lookat origin="32, 32, 200" target="32, 32, 0" up="0, 1, 0"/></transform></sensor>
)";
  for (uint64_t i = 0; i < n; ++i)
    out += fmt::format(R"(<shape type="sphere"><point name="center" x="{}" y="{}" z="0"/><float name="radius" value="0.4"/></shape>)"
                       "\n", i % 64, i / 64);
  return out + "</scene>\n";
}

void register_family(const char* name, const char* ext, const std::function<std::string(uint64_t)>& make,
                     std::initializer_list<int64_t> sizes, uint64_t placements_per_n) {
  auto* b = benchmark::RegisterBenchmark(name, [=](benchmark::State& state) {
    const uint64_t n = uint64_t(state.range(0));
    std::string file = fmt::format("{}-{}{}", name, n, ext);
    std::replace(file.begin(), file.end(), '/', '-');
    const std::string path = generated(file, [&] { return make(n); });
    uint64_t triangles = 0;
    SceneWarningCollector quiet;  // a warning per iteration would bury the table
    for (auto _ : state) {
      try {
        triangles = load_scene(path).triangles.size();
      } catch (const InputError& e) {
        state.SkipWithError(e.what());
        return;
      }
    }
    state.SetComplexityN(int64_t(n));
    state.counters["placements_per_second"] =
        benchmark::Counter(double(n * placements_per_n), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["triangles"] = double(triangles);
    state.counters["file_bytes"] = double(fs::file_size(path));
  });
  for (int64_t n : sizes) b->Arg(n);
  b->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN)->MeasureProcessCPUTime()->UseRealTime();
}

}  // namespace

void preset_loading() {
  register_family("load/gltf/placements", ".gltf", gltf_placements, {100000, 200000, 500000, 1000000}, 1);
  register_family("load/json/instances", ".json", json_instances, {100000, 200000, 500000, 1000000}, 1);
  register_family("load/mitsuba/spheres", ".xml", mitsuba_spheres, {256, 512, 1024, 2048, 4096}, 1);
}

}  // namespace pb::bench
