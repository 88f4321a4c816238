#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <filesystem>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb {

namespace {

// Parses the comma-separated numbers after "name:".
std::vector<double> parse_params(const std::string& spec, const std::string& params, size_t expected_max) {
  std::vector<double> out;
  size_t start = 0;
  while (start <= params.size() && !params.empty()) {
    size_t end = params.find(',', start);
    if (end == std::string::npos) end = params.size();
    std::string tok = params.substr(start, end - start);
    double v = 0;
    auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || ptr != tok.data() + tok.size())
      throw InputError(fmt::format("scene '{}': parameter '{}' is not a number", spec, tok));
    out.push_back(v);
    start = end + 1;
    if (end == params.size()) break;
  }
  if (out.size() > expected_max)
    throw InputError(fmt::format("scene '{}': at most {} parameter(s) expected", spec, expected_max));
  return out;
}

// The one whole-number parameter of `spec` ("name:value"), in [lo, hi].
int64_t integer_param(const std::string& spec, const std::string& base, const std::string& params, const char* what,
                      int64_t lo, int64_t hi) {
  if (params.empty())
    throw InputError(fmt::format("scene '{}' needs a parameter: the {} from {} to {} (e.g. {}:{})", spec, what, lo,
                                 hi, base, hi / 2));
  const double v = parse_params(spec, params, 1).at(0);
  if (v != std::floor(v))
    throw InputError(fmt::format("scene '{}': the {} must be a whole number from {} to {}", spec, what, lo, hi));
  if (!(v >= double(lo) && v <= double(hi)))
    throw InputError(fmt::format("scene '{}': the {} {} is out of range ({} to {})", spec, what, params, lo, hi));
  return int64_t(v);
}

}  // namespace

const std::vector<BuiltinSceneInfo>& builtin_scenes() {
  static const std::vector<BuiltinSceneInfo> list = {
      {"paper-cornell", "the 2015 paper's 14-triangle Cornell box (../shared/paper-scene.md)"},
      {"furnace:A,LE", "white furnace: closed cube, every wall albedo A (default 0.5), emission LE (default 1)"},
      {"cornell-box", "the Cornell box from Cornell University's published measurements (38 triangles)"},
      {"cornell-box:V", "the Cornell box with V = mirror (tall block), glass (short block), spheres (mirror + glass, "
                        "no blocks) or ggx (tall block rough metal)"},
      {"paper-cornell-ico:L", "paper-cornell plus an icosphere of level L = 0..10 (20*4^L triangles; L=8: 1,310,720)"},
      {"scaling:N", "paper-cornell plus a tessellated sphere: about N triangles in all (N = 10..10^7)"},
  };
  return list;
}

Scene load_scene(const std::string& spec, const SceneLoadOptions& options) {
  if (spec.empty()) throw InputError("--scene: empty scene name");
  // A file: a known extension, a '/', or any extension on a name without the colon of a
  // built-in's parameters ("furnace:0.5" has an "extension" too).
  if (is_scene_file_name(spec) || spec.find('/') != std::string::npos ||
      (spec.find(':') == std::string::npos && std::filesystem::path(spec).has_extension())) {
    // exists() with an error code: a symlink loop or a long name is read_input_file's
    // to report, not an exception here.
    std::error_code ec;
    if (!std::filesystem::exists(spec, ec) && !ec) throw InputError(fmt::format("{}: no such file", spec));
    return load_scene_file(spec, options.strict);
  }
  const size_t colon = spec.find(':');
  const std::string base = spec.substr(0, colon);
  const std::string params = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (base == "paper-cornell" && colon != std::string::npos)
    throw InputError(fmt::format("scene '{}': '{}' takes no parameters", spec, base));
  if (base == "paper-cornell") return make_paper_cornell();
  if (base == "cornell-box") {
    if (colon != std::string::npos && params.empty())
      throw InputError(fmt::format("scene '{}': give a variant after the colon (mirror, glass, spheres, ggx)", spec));
    return make_cornell_box(params);
  }
  if (base == "paper-cornell-ico") return make_paper_cornell_ico(int(integer_param(spec, base, params, "level", 0, 10)));
  if (base == "scaling") return make_scaling(uint64_t(integer_param(spec, base, params, "triangle count", 10, 10000000)));
  if (base == "furnace") {
    auto p = parse_params(spec, params, 2);
    float a = p.size() > 0 ? float(p[0]) : 0.5f;
    float le = p.size() > 1 ? float(p[1]) : 1.0f;
    if (!(a >= 0 && a <= 1)) throw InputError(fmt::format("scene '{}': albedo must be in [0, 1]", spec));
    if (!(le >= 0)) throw InputError(fmt::format("scene '{}': emission must be >= 0", spec));
    return make_furnace(a, le);
  }
  std::string names;
  for (const auto& b : builtin_scenes()) names += (names.empty() ? "" : ", ") + b.name;
  throw InputError(fmt::format("unknown scene '{}' (built-ins: {}; or a scene file: .json, .obj, .ply, .off, .gltf, .glb, .xml)", spec, names));
}

}  // namespace pb
