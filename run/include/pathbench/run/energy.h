#pragma once
// Energy and clocks around a stretch of work on one device (issue 28), never a made-up
// figure: where a counter cannot be read, "joules" is null and "reason" says why.
//
//   GPU  NVML, opened with dlopen("libnvidia-ml.so.1") (no link dependency):
//        nvmlDeviceGetTotalEnergyConsumption (mJ since the driver loaded; it updates every
//        20-100 ms, so a window shorter than kMinNvmlWindowSeconds gives no figure), and a
//        sampler thread (every 20 ms) reading the SM clock, the temperature, the power and
//        the clock-event (throttle) reasons.
//   CPU  RAPL package energy from /sys/class/powercap/intel-rapl:N/energy_uj (every
//        package, counter wrap handled with max_energy_range_uj); PATHBENCH_POWERCAP_ROOT
//        replaces /sys/class/powercap (tests). A VM usually has none: then null + reason.
//
// The record (EnergyMeter::stop):
//   {"source": "nvml"|"rapl", "joules": J|null, "reason": "..." (only when null),
//    "window_seconds": s, "average_watts": W|null,
//    GPU only: "samples": n, "sm_clock_mhz": {"min","mean","max"}, "temperature_c": {"max"},
//              "power_watts": {"max"}, "throttle_reasons": mask (OR of every sample),
//              "throttle": ["sw_power_cap", ...] (names of the mask's bits),
//              "throttled": bool (a slowdown bit: power cap, thermal, HW slowdown, power brake)}
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "pathbench/common/settings.h"

namespace pb::run {

constexpr double kMinNvmlWindowSeconds = 1.0;
// NVML clock-event reasons that mean the clocks were lowered (not idle, not app clocks).
constexpr uint64_t kThrottleMask = 0x4 | 0x8 | 0x20 | 0x40 | 0x80;

class EnergyMeter {
 public:
  // Reads the counters now and, on the GPU, starts sampling clocks.
  explicit EnergyMeter(Device device);
  ~EnergyMeter();
  EnergyMeter(const EnergyMeter&) = delete;
  EnergyMeter& operator=(const EnergyMeter&) = delete;
  // Stops sampling and returns the record above (once; later calls return the same).
  nlohmann::json stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Adds "joules_per_frame" and "rays_per_joule" to a record with joules (nothing otherwise).
void add_energy_rates(nlohmann::json& record, uint64_t rays, uint64_t frames);

// Names of the NVML clock-event reason bits set in `mask`.
nlohmann::json throttle_reason_names(uint64_t mask);

}  // namespace pb::run
