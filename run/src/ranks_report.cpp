#include "pathbench/run/ranks_report.h"

#include <algorithm>
#include <map>
#include <sstream>

#include <fmt/core.h>

namespace pb::run {

nlohmann::json rank_entry(int rank, const std::string& host, const RenderSettings& s, const RunReport& r,
                          int gpu_index, uint64_t samples, int chunks, double wall_seconds) {
  const bool gpu = s.device == Device::Gpu;
  std::string name = cpu_model();
  if (gpu && r.extra.contains("gpu")) name = r.extra["gpu"].value("name", name);
  return {{"rank", rank},
          {"host", host},
          {"device", to_string(s.device)},
          {"device_name", name},
          // What traced the samples: "gpu", "embree", or "gpu-bvh-on-host" (a CPU rank
          // beside GPU ranks traces the GPU's samples: gpu/host_tracer.h).
          {"tracer", gpu ? std::string("gpu") : r.extra.value("tracer", std::string("embree"))},
          {"gpu_index", gpu_index >= 0 ? nlohmann::json(gpu_index) : nlohmann::json(nullptr)},
          {"threads", gpu ? nlohmann::json(nullptr) : nlohmann::json(r.threads)},
          {"samples", samples},  // (pixel, sample) pairs traced
          {"samples_per_pixel", double(samples) / (double(s.width) * s.height)},
          {"chunks", chunks},
          // Host wall clock of the tracer calls (GPU: with each call's warm-up and copies).
          {"tracer_seconds", r.seconds},
          {"device_seconds", gpu ? nlohmann::json(r.device_seconds) : nlohmann::json(nullptr)},
          {"wall_seconds", wall_seconds},
          {"rays", {{"camera", r.rays.camera}, {"bounce", r.rays.bounce}, {"shadow", r.rays.shadow}}},
          {"rays_total", r.rays.total()},
          {"rays_per_second", r.seconds > 0 ? double(r.rays.total()) / r.seconds : 0.0},
          {"paths", r.paths},
          {"discarded_samples", r.discarded_samples},
          {"peak_host_bytes", r.peak_host_bytes},
          {"peak_device_bytes", gpu ? nlohmann::json(r.peak_device_bytes) : nlohmann::json(nullptr)}};
}

void merge_ranks(RunReport& report, const std::vector<std::string>& ranks, double frame_seconds,
                 double reduce_seconds, const std::string& balance) {
  nlohmann::json per_rank = nlohmann::json::array();
  RayCounts rays;
  uint64_t paths = 0, discarded = 0, peak_device = 0, peak_host = 0;
  double busy_sum = 0, busy_max = 0, wall_max = 0;
  uint64_t spp_sum = 0;
  std::map<std::string, uint64_t> by_device;
  for (const std::string& text : ranks) {
    nlohmann::json e = nlohmann::json::parse(text);
    rays.camera += e["rays"]["camera"].get<uint64_t>();
    rays.bounce += e["rays"]["bounce"].get<uint64_t>();
    rays.shadow += e["rays"]["shadow"].get<uint64_t>();
    paths += e["paths"].get<uint64_t>();
    discarded += e["discarded_samples"].get<uint64_t>();
    if (!e["peak_device_bytes"].is_null()) peak_device = std::max(peak_device, e["peak_device_bytes"].get<uint64_t>());
    peak_host = std::max(peak_host, e["peak_host_bytes"].get<uint64_t>());
    const double busy = e["tracer_seconds"].get<double>();
    wall_max = std::max(wall_max, e["wall_seconds"].get<double>());
    busy_sum += busy;
    busy_max = std::max(busy_max, busy);
    const uint64_t traced = e["samples"].get<uint64_t>();
    spp_sum += traced;
    by_device[e["device"].get<std::string>()] += traced;
    per_rank.push_back(std::move(e));
  }
  const double n = double(std::max<size_t>(1, ranks.size()));
  report.rays = rays;
  report.paths = paths;
  report.discarded_samples = discarded;
  // The frame's time on every device: from the ranks' common start to the reduced film.
  report.seconds = frame_seconds;
  report.device_seconds = report.settings.device == Device::Gpu ? frame_seconds : 0.0;
  report.peak_device_bytes = std::max(report.peak_device_bytes, peak_device);
  nlohmann::json share = nlohmann::json::object();
  for (const auto& [device, spp] : by_device) share[device] = spp_sum ? double(spp) / double(spp_sum) : 0.0;
  const double mean = busy_sum / n;
  // Each rank times its part from its own exit of the common barrier; one that left the
  // barrier before rank 0 (a loaded host: milliseconds) traced longer than rank 0's frame.
  // The frame the efficiency is measured against lasts at least every rank's part.
  const double span = std::max(frame_seconds, wall_max);
  report.extra["ranks"] = {
      {"count", ranks.size()},
      {"balance", balance},
      {"frame_seconds", frame_seconds},
      {"reduce_seconds", reduce_seconds},
      {"load_balance", mean > 0 ? busy_max / mean : 1.0},
      {"parallel_efficiency", span > 0 ? busy_sum / (n * span) : 0.0},
      {"device_share", share},
      {"peak_host_bytes_max", peak_host},
      {"per_rank", per_rank},
      {"note",
       "load_balance: max/mean of the ranks' tracer seconds; parallel_efficiency: sum of tracer seconds / (ranks x "
       "frame seconds, or the longest rank's own wall seconds where longer); frame seconds: common start to the film "
       "reduced on rank 0"}};
}

std::string first_difference(const std::string& rank0, const std::string& mine) {
  std::istringstream a(rank0), b(mine);
  std::string wa, wb;
  while (true) {
    const bool ha = bool(a >> wa), hb = bool(b >> wb);
    if (!ha && !hb) return "none";
    if (!ha) wa = "(nothing)";
    if (!hb) wb = "(nothing)";
    if (wa != wb || !ha || !hb) return fmt::format("{} here, {} on rank 0", wb, wa);
  }
}

}  // namespace pb::run
