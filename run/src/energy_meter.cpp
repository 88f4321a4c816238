#include "pathbench/run/energy.h"

#include <dlfcn.h>
#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "pathbench/run/run_context.h"

namespace pb::run {

namespace {

using Clock = std::chrono::steady_clock;

// ---- NVML (dlopen; the entry points' ABI is stable, so no nvml.h is needed) ----------
using NvmlDevice = void*;
struct Nvml {
  int (*init)() = nullptr;
  int (*by_pci)(const char*, NvmlDevice*) = nullptr;
  int (*by_index)(unsigned, NvmlDevice*) = nullptr;
  int (*energy)(NvmlDevice, unsigned long long*) = nullptr;  // mJ
  int (*clock)(NvmlDevice, int, unsigned*) = nullptr;
  int (*temperature)(NvmlDevice, int, unsigned*) = nullptr;
  int (*power)(NvmlDevice, unsigned*) = nullptr;  // mW
  int (*reasons)(NvmlDevice, unsigned long long*) = nullptr;
  NvmlDevice device = nullptr;
  std::string why_not;  // empty: usable
};

template <class F>
void bind(void* lib, F& f, const char* name) {
  f = reinterpret_cast<F>(dlsym(lib, name));
}

// Opened once per process, for the device this process renders on (CUDA's device 0,
// found in NVML by its PCI bus id, so CUDA_VISIBLE_DEVICES is honoured).
const Nvml& nvml() {
  static const Nvml n = [] {
    Nvml n;
    void* lib = dlopen("libnvidia-ml.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      n.why_not = "NVML (libnvidia-ml.so.1) not found";
      return n;
    }
    bind(lib, n.init, "nvmlInit_v2");
    bind(lib, n.by_pci, "nvmlDeviceGetHandleByPciBusId_v2");
    bind(lib, n.by_index, "nvmlDeviceGetHandleByIndex_v2");
    bind(lib, n.energy, "nvmlDeviceGetTotalEnergyConsumption");
    bind(lib, n.clock, "nvmlDeviceGetClockInfo");
    bind(lib, n.temperature, "nvmlDeviceGetTemperature");
    bind(lib, n.power, "nvmlDeviceGetPowerUsage");
    bind(lib, n.reasons, "nvmlDeviceGetCurrentClocksEventReasons");
    if (!n.reasons) bind(lib, n.reasons, "nvmlDeviceGetCurrentClocksThrottleReasons");
    if (!n.init || n.init() != 0) {
      n.why_not = "nvmlInit failed";
      return n;
    }
    const nlohmann::json fp = run_fingerprint(true);
    std::string bus;
    if (fp.contains("gpu") && fp["gpu"].contains("pci_bus_id") && fp["gpu"]["pci_bus_id"].is_string())
      bus = fp["gpu"]["pci_bus_id"].get<std::string>();
    int rc = -1;
    if (!bus.empty() && n.by_pci) rc = n.by_pci(bus.c_str(), &n.device);
    if (rc != 0 && n.by_index) rc = n.by_index(0, &n.device);
    if (rc != 0) n.why_not = "NVML has no handle for the CUDA device";
    else if (!n.energy) n.why_not = "this NVML has no nvmlDeviceGetTotalEnergyConsumption";
    return n;
  }();
  return n;
}

// ---- RAPL --------------------------------------------------------------------------
struct RaplDomain {
  std::string file;
  uint64_t max_range_uj = 0;
};

std::string powercap_root() {
  if (const char* env = std::getenv("PATHBENCH_POWERCAP_ROOT"); env && *env) return env;
  return "/sys/class/powercap";
}

bool read_u64(const std::string& path, uint64_t& v, std::string* why) {
  std::ifstream in(path);
  if (!in) {
    if (why) *why = fmt::format("{}: {}", path, std::strerror(errno ? errno : EACCES));
    return false;
  }
  if (!(in >> v)) {
    if (why) *why = fmt::format("{}: not a number", path);
    return false;
  }
  return true;
}

// The package domains (intel-rapl:N, no sub-zone; AMD's are named so too), or why none.
std::vector<RaplDomain> rapl_domains(std::string& why) {
  namespace fs = std::filesystem;
  const std::string root = powercap_root();
  std::vector<RaplDomain> out;
  std::error_code ec;
  if (!fs::is_directory(root, ec)) {
    why = fmt::format("{} does not exist (no RAPL here: a VM or a CPU without it)", root);
    return out;
  }
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(root, ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("intel-rapl:", 0) == 0 && n.find(':', 11) == std::string::npos) names.push_back(n);
  }
  std::sort(names.begin(), names.end());
  if (names.empty()) {
    why = fmt::format("{} has no intel-rapl:N package domain (no RAPL here: a VM or a CPU without it)", root);
    return out;
  }
  for (const auto& n : names) {
    RaplDomain d{root + "/" + n + "/energy_uj", 0};
    uint64_t v = 0;
    std::string err;
    if (!read_u64(d.file, v, &err)) {
      why = err + " (RAPL is readable by root only since Linux 5.10)";
      return {};
    }
    if (!read_u64(root + "/" + n + "/max_energy_range_uj", d.max_range_uj, &err)) d.max_range_uj = 0;
    out.push_back(d);
  }
  return out;
}

}  // namespace

nlohmann::json throttle_reason_names(uint64_t mask) {
  static const std::pair<uint64_t, const char*> bits[] = {
      {0x1, "gpu_idle"},          {0x2, "applications_clocks"},  {0x4, "sw_power_cap"},
      {0x8, "hw_slowdown"},       {0x10, "sync_boost"},          {0x20, "sw_thermal_slowdown"},
      {0x40, "hw_thermal_slowdown"}, {0x80, "hw_power_brake_slowdown"}, {0x100, "display_clock"}};
  nlohmann::json names = nlohmann::json::array();
  for (auto [bit, name] : bits)
    if (mask & bit) names.push_back(name);
  return names;
}

struct EnergyMeter::Impl {
  Device device;
  Clock::time_point t0;
  std::string why_not;
  nlohmann::json result;
  bool stopped = false;
  // RAPL
  std::vector<RaplDomain> domains;
  std::vector<uint64_t> start_uj;
  // NVML
  unsigned long long start_mj = 0;
  std::thread sampler;
  std::mutex m;
  std::condition_variable cv;
  bool stop_flag = false;
  uint64_t reasons = 0;
  unsigned samples = 0, clock_min = ~0u, clock_max = 0, temp_max = 0, power_max_mw = 0;
  unsigned reason_reads = 0, temp_reads = 0, power_reads = 0, clock_reads = 0;  // successful reads: no figure without one
  double clock_sum = 0;

  void sample() {
    const Nvml& n = nvml();
    unsigned v = 0;
    unsigned long long r = 0;
    std::lock_guard<std::mutex> lock(m);
    ++samples;
    if (n.clock && n.clock(n.device, 1 /* NVML_CLOCK_SM */, &v) == 0) {
      clock_min = std::min(clock_min, v);
      clock_max = std::max(clock_max, v);
      clock_sum += v;
      ++clock_reads;
    }
    if (n.temperature && n.temperature(n.device, 0 /* NVML_TEMPERATURE_GPU */, &v) == 0) {
      temp_max = std::max(temp_max, v);
      ++temp_reads;
    }
    if (n.power && n.power(n.device, &v) == 0) {
      power_max_mw = std::max(power_max_mw, v);
      ++power_reads;
    }
    if (n.reasons && n.reasons(n.device, &r) == 0) {
      reasons |= r;
      ++reason_reads;
    }
  }
};

EnergyMeter::EnergyMeter(Device device) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.device = device;
  if (device == Device::Cpu) {
    s.domains = rapl_domains(s.why_not);
    for (const auto& d : s.domains) {
      uint64_t v = 0;
      // A start that cannot be read gives no figure (null with the reason), never one
      // counted from 0.
      if (!read_u64(d.file, v, &s.why_not)) break;
      s.start_uj.push_back(v);
    }
  } else {
    const Nvml& n = nvml();
    s.why_not = n.why_not;
    if (s.why_not.empty() && n.energy(n.device, &s.start_mj) != 0) s.why_not = "nvmlDeviceGetTotalEnergyConsumption failed";
    if (n.device) {
      s.sample();
      s.sampler = std::thread([&s] {
        std::unique_lock<std::mutex> lock(s.m);
        while (!s.cv.wait_for(lock, std::chrono::milliseconds(20), [&s] { return s.stop_flag; })) {
          lock.unlock();
          s.sample();
          lock.lock();
        }
      });
    }
  }
  s.t0 = Clock::now();
}

EnergyMeter::~EnergyMeter() { stop(); }

nlohmann::json EnergyMeter::stop() {
  Impl& s = *impl_;
  if (s.stopped) return s.result;
  s.stopped = true;
  const double window = std::chrono::duration<double>(Clock::now() - s.t0).count();
  nlohmann::json r;
  r["window_seconds"] = window;
  double joules = -1;
  if (s.device == Device::Cpu) {
    r["source"] = "rapl";
    if (s.why_not.empty()) {
      double uj = 0;
      for (size_t i = 0; i < s.domains.size(); ++i) {
        uint64_t now = 0;
        if (!read_u64(s.domains[i].file, now, &s.why_not)) break;
        // The counter wraps at max_energy_range_uj (about 65 kJ on many CPUs).
        uj += now >= s.start_uj[i] ? double(now - s.start_uj[i])
                                   : double(s.domains[i].max_range_uj - s.start_uj[i] + now);
      }
      if (s.why_not.empty()) joules = uj * 1e-6;
    }
  } else {
    r["source"] = "nvml";
    if (s.sampler.joinable()) {
      {
        std::lock_guard<std::mutex> lock(s.m);
        s.stop_flag = true;
      }
      s.cv.notify_all();
      s.sampler.join();
      s.sample();
    }
    const Nvml& n = nvml();
    unsigned long long end_mj = 0;
    if (s.why_not.empty() && n.energy(n.device, &end_mj) != 0) s.why_not = "nvmlDeviceGetTotalEnergyConsumption failed";
    if (s.why_not.empty() && window < kMinNvmlWindowSeconds)
      s.why_not = fmt::format("a window of {:.3f} s is shorter than the {:g} s NVML's energy counter needs (it "
                              "updates every 20-100 ms): repeat the frame (pathbench bench, pathbench suite)",
                              window, kMinNvmlWindowSeconds);
    if (s.why_not.empty()) joules = double(end_mj - s.start_mj) * 1e-3;
    if (s.samples > 0) {
      r["samples"] = s.samples;
      if (s.clock_reads)
        r["sm_clock_mhz"] = {{"min", s.clock_min}, {"mean", s.clock_sum / s.clock_reads}, {"max", s.clock_max}};
      if (s.temp_reads) r["temperature_c"] = {{"max", s.temp_max}};
      if (s.power_reads) r["power_watts"] = {{"max", s.power_max_mw * 1e-3}};
      if (s.reason_reads) {
        r["throttle_reasons"] = s.reasons;
        r["throttle"] = throttle_reason_names(s.reasons);
        r["throttled"] = (s.reasons & kThrottleMask) != 0;
      } else {
        r["throttled"] = nullptr;  // NVML gave no clock-event reasons: unknown, not "not throttled"
      }
    }
  }
  if (joules >= 0) {
    r["joules"] = joules;
    r["average_watts"] = window > 0 ? nlohmann::json(joules / window) : nlohmann::json(nullptr);
  } else {
    r["joules"] = nullptr;
    r["average_watts"] = nullptr;
    r["reason"] = s.why_not;
  }
  s.result = r;
  return r;
}

void add_energy_rates(nlohmann::json& record, uint64_t rays, uint64_t frames) {
  if (!record.contains("joules") || !record["joules"].is_number() || frames == 0) return;
  const double j = record["joules"].get<double>();
  record["joules_per_frame"] = j / double(frames);
  record["rays_per_joule"] = j > 0 ? nlohmann::json(double(rays) / j) : nlohmann::json(nullptr);
}

}  // namespace pb::run
