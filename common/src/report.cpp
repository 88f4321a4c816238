#include "pathbench/common/report.h"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <thread>

#include "pathbench/common/fingerprint.h"

namespace pb {

extern const char* const kGitRevision;  // generated at build time (cmake/git_revision.cmake)

nlohmann::json RunReport::to_json() const {
  nlohmann::json j;
  j["scene"] = scene;
  j["triangles"] = triangles;
  j["width"] = settings.width;
  j["height"] = settings.height;
  j["spp"] = settings.spp;
  j["bounces"] = settings.max_bounces < 0 ? nlohmann::json("unbounded") : nlohmann::json(settings.max_bounces);
  j["russian_roulette"] = settings.russian_roulette;
  j["sampling"] = to_string(settings.sampling);
  j["watertight"] = settings.watertight;
  j["precision"] = to_string(settings.precision);
  j["device"] = to_string(settings.device);
  j["strategy"] = to_string(settings.strategy);
  j["seed"] = settings.seed;
  j["seconds"] = seconds;
  if (settings.device == Device::Gpu) j["device_seconds"] = device_seconds;
  j["rays"] = {{"total", rays.total()}, {"camera", rays.camera}, {"bounce", rays.bounce}, {"shadow", rays.shadow}};
  j["rays_per_second"] = rays_per_second();
  j["paths"] = paths;
  j["samples_per_second"] = seconds > 0 ? double(paths) / seconds : 0.0;
  j["discarded_samples"] = discarded_samples;
  j["peak_host_bytes"] = peak_host_bytes;
  j["tracer_host_bytes"] = tracer_host_bytes;
  j["peak_device_bytes"] = peak_device_bytes;
  j["state_bytes_per_path"] = state_bytes_per_path;
  j["paths_in_flight"] = paths_in_flight;
  j["machine"] = {{"cpu", cpu_model()}, {"hardware_threads", hardware_threads()}, {"threads", threads}};
  j["git_revision"] = git_revision();
  j["compiler"] = compiler_id();
  j["fingerprint"] = fingerprint.is_null() ? machine_fingerprint() : fingerprint;
  if (!load.is_null()) j["load"] = load;
  for (auto& [k, v] : extra.items()) j[k] = v;
  return j;
}

nlohmann::json InstancingSummary::to_json() const {
  return {{"asked", to_string(asked)},
          {"used", used},
          {"why", why},
          {"scene_instances", scene_instances},
          {"scene_prototypes", scene_prototypes},
          {"instances", instances},
          {"prototypes", prototypes},
          {"instances_left_flat", instances_left_flat},
          {"flat_triangles", flat_triangles},
          {"accel_bytes", accel_bytes},
          {"accel_build_seconds", accel_build_seconds}};
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      auto pos = line.find(':');
      if (pos != std::string::npos) {
        std::string m = line.substr(pos + 1);
        m.erase(0, m.find_first_not_of(' '));
        return m;
      }
    }
  }
  return "unknown CPU";
}

int hardware_threads() { return int(std::max(1u, std::thread::hardware_concurrency())); }

std::string git_revision() { return kGitRevision; }

std::string compiler_id() {
#if defined(__clang__)
  return fmt::format("clang {}.{}.{}", __clang_major__, __clang_minor__, __clang_patchlevel__);
#elif defined(__GNUC__)
  return fmt::format("gcc {}.{}.{}", __GNUC__, __GNUC_MINOR__, __GNUC_PATCHLEVEL__);
#else
  return "unknown";
#endif
}

uint64_t peak_resident_bytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream ss(line.substr(6));
      uint64_t kb = 0;
      ss >> kb;
      return kb * 1024;
    }
  }
  return 0;
}

std::string machine_slug() {
  // "AMD EPYC 7B13 64-Core Processor" -> "amd-epyc-7b13-64-core": folder names only;
  // a machine is identified by its fingerprint's machine_id.
  std::string out = slugify(cpu_model(), "unknown-machine");
  for (std::string noise : {"-processor", "-cpu"})
    if (out.size() > noise.size() && out.compare(out.size() - noise.size(), noise.size(), noise) == 0)
      out.erase(out.size() - noise.size());
  return out;
}

}  // namespace pb
