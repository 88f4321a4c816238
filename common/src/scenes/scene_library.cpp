#include <fmt/core.h>

#include <charconv>
#include <filesystem>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"

namespace pb {

namespace {

bool ends_with(const std::string& s, const char* suffix) {
  std::string_view sv(s), suf(suffix);
  return sv.size() >= suf.size() && sv.substr(sv.size() - suf.size()) == suf;
}

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

}  // namespace

const std::vector<BuiltinSceneInfo>& builtin_scenes() {
  static const std::vector<BuiltinSceneInfo> list = {
      {"paper-cornell", "the 2015 paper's 14-triangle Cornell box (../shared/paper-scene.md)"},
      {"furnace:A,LE", "white furnace: closed cube, every wall albedo A (default 0.5), emission LE (default 1)"},
  };
  return list;
}

Scene load_scene(const std::string& spec) {
  if (spec.empty()) throw InputError("--scene: empty scene name");
  if (ends_with(spec, ".json") || ends_with(spec, ".obj") || spec.find('/') != std::string::npos) {
    if (!std::filesystem::exists(spec)) throw InputError(fmt::format("{}: no such file", spec));
    if (ends_with(spec, ".json")) return load_scene_json(spec);
    if (ends_with(spec, ".obj")) return load_scene_obj(spec);
    throw InputError(fmt::format("{}: unknown scene file type (expected .json or .obj)", spec));
  }
  const size_t colon = spec.find(':');
  const std::string base = spec.substr(0, colon);
  const std::string params = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (base == "paper-cornell" && params.empty()) return make_paper_cornell();
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
  throw InputError(fmt::format("unknown scene '{}' (built-ins: {}; or a .json / .obj file)", spec, names));
}

}  // namespace pb
