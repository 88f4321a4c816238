#include "suite_bench.h"

#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/common/settings.h"
#include "render_bench.h"

namespace pb::bench {

namespace {

std::string text(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.contains(key) || !j[key].is_string())
    throw std::runtime_error(fmt::format("{}: '{}' must be a string", where, key));
  return j[key].get<std::string>();
}

uint32_t count(const nlohmann::json& j, const char* key, const std::string& where, uint32_t lo) {
  if (!j[key].is_number_integer() || j[key].get<int64_t>() < lo || j[key].get<int64_t>() > (int64_t(1) << 31))
    throw std::runtime_error(fmt::format("{}: '{}' must be an integer >= {}", where, key, lo));
  return uint32_t(j[key].get<int64_t>());
}

RenderCase suite_case(const nlohmann::json& c, const std::string& where) {
  if (!c.is_object()) throw std::runtime_error(where + ": not an object");
  RenderCase rc;
  rc.name = text(c, "name", where);
  rc.scene = text(c, "scene", where);
  const nlohmann::json& s = c.contains("settings") ? c["settings"] : nlohmann::json::object();
  if (!s.is_object()) throw std::runtime_error(where + ": 'settings' must be an object");
  RenderChoices choices;
  choices.device = text(c, "device", where);
  for (auto& [k, v] : s.items()) {
    const std::string at = where + ".settings";
    if (k == "width") rc.settings.width = count(s, "width", at, 1);
    else if (k == "height") rc.settings.height = count(s, "height", at, 1);
    else if (k == "spp") rc.settings.spp = count(s, "spp", at, 1);
    else if (k == "bounces") rc.settings.max_bounces = int32_t(count(s, "bounces", at, 0));
    else if (k == "seed") rc.settings.seed = count(s, "seed", at, 0);
    else if (k == "converged") choices.converged = v.is_boolean() && v.get<bool>();
    else if (k == "sampling") choices.sampling = text(s, "sampling", at);
    else if (k == "strategy") choices.strategy = text(s, "strategy", at);
    else if (k == "isa") choices.isa = text(s, "isa", at);
    else if (k == "instancing") choices.instancing = text(s, "instancing", at);
    else if (k == "precision") choices.precision = text(s, "precision", at);
    else if (k == "embree_layout") choices.embree_layout = text(s, "embree_layout", at);
    else throw std::runtime_error(fmt::format("{}: unknown setting '{}'", at, k));
  }
  try {
    apply_choices(choices, rc.settings);
  } catch (const InputError& e) {
    throw std::runtime_error(fmt::format("{}: {}", where, e.what()));
  }
  if (c.contains("iterations")) rc.iterations = int(count(c, "iterations", where, 0));
  rc.build_once = true;  // the structure built once per benchmark: frames alone in the time and the energy
  return rc;
}

}  // namespace

std::string preset_suite(const std::string& cases_path) {
  if (cases_path.empty()) throw std::runtime_error("--preset suite needs --suite-cases FILE (written by pathbench suite)");
  std::ifstream in(cases_path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read the suite's cases", cases_path));
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("cases") || !j["cases"].is_array())
    throw std::runtime_error(fmt::format("{}: not a suite cases file (an object with a 'cases' array)", cases_path));
  for (const char* key : {"suite", "mode", "manifest_sha256", "device_label"})
    if (j.contains(key) && j[key].is_string())
      benchmark::AddCustomContext(std::string(key) == "suite" ? "suite" : std::string("suite_") + key,
                                  j[key].get<std::string>());
  if (j.contains("version") && j["version"].is_number_integer())
    benchmark::AddCustomContext("suite_version", std::to_string(j["version"].get<int64_t>()));
  for (size_t i = 0; i < j["cases"].size(); ++i) {
    RenderCase rc = suite_case(j["cases"][i], fmt::format("{}: cases[{}]", cases_path, i));
    register_render_benchmark(rc);
  }
  return j.value("mode", std::string("full")) == "quick" ? "suite-quick" : "suite";
}

}  // namespace pb::bench
