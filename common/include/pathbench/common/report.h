#pragma once
// What every render returns: counts, times, memory and where it ran.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "pathbench/common/settings.h"

namespace pb {

struct RayCounts {
  uint64_t camera = 0, bounce = 0, shadow = 0;
  uint64_t total() const { return camera + bounce + shadow; }
  RayCounts& operator+=(const RayCounts& o) {
    camera += o.camera; bounce += o.bounce; shadow += o.shadow;
    return *this;
  }
};

// What a render's report says of --instancing (report.extra["instancing"]), the same on
// both devices: asked, used, why; the scene's instances and prototypes and those the
// acceleration structure built; instances left flat (they lost triangles to finalize()),
// triangles traced flat; the structure's bytes and build time.
struct InstancingSummary {
  Instancing asked = Instancing::Auto;
  bool used = false;
  const char* why = "";
  uint64_t scene_instances = 0, scene_prototypes = 0;
  uint64_t instances = 0, prototypes = 0, instances_left_flat = 0, flat_triangles = 0;
  uint64_t accel_bytes = 0;
  double accel_build_seconds = 0;
  nlohmann::json to_json() const;
};

struct RunReport {
  std::string scene;
  uint64_t triangles = 0;
  RenderSettings settings;
  double seconds = 0;            // wall time of the render (host clock)
  double device_seconds = 0;     // GPU time from CUDA events (GPU only)
  RayCounts rays;
  uint64_t paths = 0;
  uint64_t discarded_samples = 0;  // NaN / Inf / overflow, never added to the film
  uint64_t peak_host_bytes = 0;    // process peak resident set
  uint64_t tracer_host_bytes = 0;  // what the tracer itself allocated (film, path pool, BVH copy)
  uint64_t peak_device_bytes = 0;
  uint64_t state_bytes_per_path = 0;
  uint64_t paths_in_flight = 0;
  int threads = 0;
  nlohmann::json extra = nlohmann::json::object();  // device-specific: GPU name, profile, ...
  // The machine fingerprint (pathbench/common/fingerprint.h) with the tracer's own
  // sections; null: to_json writes the host's machine_fingerprint().
  nlohmann::json fingerprint;
  // Contention evidence: load average and process CPU time against wall time around
  // the render (pb::run::render fills it); null when not measured.
  nlohmann::json load;

  double rays_per_second() const { return seconds > 0 ? double(rays.total()) / seconds : 0; }
  nlohmann::json to_json() const;
};

// Machine and build facts for reports and benchmark JSON.
std::string cpu_model();
int hardware_threads();
std::string git_revision();
std::string compiler_id();
uint64_t peak_resident_bytes();   // VmHWM of this process
std::string machine_slug();       // results/<machine>/ folder name: pb::slugify of the CPU model

}  // namespace pb
