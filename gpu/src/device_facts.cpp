#include "pathbench/gpu/device_facts.h"

#include <cuda_runtime.h>
#include <dlfcn.h>
#include <fmt/core.h>

#include <fstream>
#include <string>

#include "pathbench/common/fingerprint.h"
#include "pathbench/gpu/render.h"

namespace pb::gpu {

namespace {

// The few NVML entry points used, declared here so that building needs no nvml.h
// (the CUDA toolkit of the offline GPU host may lack it); their ABI is stable.
using NvmlDevice = void*;
using NvmlInit = int (*)();
using NvmlShutdown = int (*)();
using NvmlByPci = int (*)(const char*, NvmlDevice*);
using NvmlUint = int (*)(NvmlDevice, unsigned*);
using NvmlClock = int (*)(NvmlDevice, int, unsigned*);
using NvmlMig = int (*)(NvmlDevice, unsigned*, unsigned*);
constexpr int kNvmlClockSm = 1, kNvmlClockMem = 2;

template <class F>
F sym(void* lib, const char* name) {
  return reinterpret_cast<F>(dlsym(lib, name));
}

void add_nvml_facts(int device, nlohmann::json& j) {
  for (const char* k : {"sm_clock_max_mhz", "memory_clock_max_mhz", "sm_clock_mhz", "memory_clock_mhz",
                        "power_limit_w", "mig_mode"})
    j[k] = nullptr;
  void* lib = dlopen("libnvidia-ml.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    j["nvml"] = "libnvidia-ml.so.1 not found";
    return;
  }
  auto init = sym<NvmlInit>(lib, "nvmlInit_v2");
  auto shutdown = sym<NvmlShutdown>(lib, "nvmlShutdown");
  auto by_pci = sym<NvmlByPci>(lib, "nvmlDeviceGetHandleByPciBusId_v2");
  char bus[32] = {0};
  NvmlDevice dev = nullptr;
  if (!init || !shutdown || !by_pci || init() != 0) {
    j["nvml"] = "nvmlInit failed";
    dlclose(lib);
    return;
  }
  if (cudaDeviceGetPCIBusId(bus, sizeof bus, device) != cudaSuccess || by_pci(bus, &dev) != 0) {
    (void)cudaGetLastError();
    j["nvml"] = "device not found by PCI bus id";
  } else {
    j["nvml"] = "ok";
    j["pci_bus_id"] = bus;
    unsigned v = 0, pending = 0;
    if (auto f = sym<NvmlClock>(lib, "nvmlDeviceGetMaxClockInfo")) {
      if (f(dev, kNvmlClockSm, &v) == 0) j["sm_clock_max_mhz"] = v;
      if (f(dev, kNvmlClockMem, &v) == 0) j["memory_clock_max_mhz"] = v;
    }
    if (auto f = sym<NvmlClock>(lib, "nvmlDeviceGetClockInfo")) {
      if (f(dev, kNvmlClockSm, &v) == 0) j["sm_clock_mhz"] = v;
      if (f(dev, kNvmlClockMem, &v) == 0) j["memory_clock_mhz"] = v;
    }
    if (auto f = sym<NvmlUint>(lib, "nvmlDeviceGetEnforcedPowerLimit"); f && f(dev, &v) == 0)
      j["power_limit_w"] = double(v) / 1000.0;  // NVML reports milliwatts
    if (auto f = sym<NvmlMig>(lib, "nvmlDeviceGetMigMode"); f && f(dev, &v, &pending) == 0)
      j["mig_mode"] = v ? "enabled" : "disabled";
    else
      j["mig_mode"] = "not supported";
  }
  shutdown();
  dlclose(lib);
}

std::string kernel_driver_line() {
  std::ifstream in("/proc/driver/nvidia/version");
  std::string line;
  std::getline(in, line);
  return line;
}

int attribute(cudaDeviceAttr a, int device) {
  int v = 0;
  if (cudaDeviceGetAttribute(&v, a, device) != cudaSuccess) {
    (void)cudaGetLastError();
    return -1;
  }
  return v;
}

}  // namespace

nlohmann::json device_fingerprint() {
  const DeviceInfo info = device_info();
  nlohmann::json j;
  j["name"] = info.name;
  j["compute_capability"] = fmt::format("{}.{}", info.compute_major, info.compute_minor);
  j["multiprocessors"] = info.multiprocessors;
  j["memory_bytes"] = info.total_memory;
  j["ecc_enabled"] = attribute(cudaDevAttrEccEnabled, info.device) == 1;
  j["driver"] = kernel_driver_line();
  j["cuda_driver_api"] = fmt::format("{}.{}", info.driver_version / 1000, (info.driver_version % 1000) / 10);
  j["cuda_runtime"] = fmt::format("{}.{}", info.runtime_version / 1000, (info.runtime_version % 1000) / 10);
  j["cuda_architectures_built"] = PATHBENCH_CUDA_ARCHS;
  add_nvml_facts(info.device, j);
  // Identity: what the card is, not how it is clocked now (MIG changes the SM count
  // CUDA sees, and so the id, as it should: a MIG slice is another machine).
  const std::string identity =
      fmt::format("name={}\ncompute_capability={}\nmultiprocessors={}\nmemory_gib={}\nsm_clock_max_mhz={}\n",
                  info.name, j["compute_capability"].get<std::string>(), info.multiprocessors,
                  (info.total_memory + (1ULL << 29)) >> 30, j["sm_clock_max_mhz"].is_null() ? 0 : j["sm_clock_max_mhz"].get<unsigned>());
  j["gpu_id"] = fnv1a64_hex(identity);
  return j;
}

}  // namespace pb::gpu
