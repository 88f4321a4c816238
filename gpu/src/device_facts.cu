// Device facts: whether this build's kernels run on the device, its properties, the
// kernel driver's version from /proc, the wavefront's default pool size, and the GPU's
// part of the machine fingerprint (NVML facts, opened at run time).
#include "device_facts.h"

#include <cuda_runtime.h>
#include <dlfcn.h>
#include <fmt/core.h>

#include <algorithm>
#include <fstream>

#include <cctype>
#include <cstdio>
#include <string>
#include <utility>

#include "cuda_util.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/gpu/device_facts.h"
#include "pathbench/gpu/render.h"

#ifndef PATHBENCH_CUDA_ARCHS
#define PATHBENCH_CUDA_ARCHS "?"
#endif

namespace pb::gpu {

namespace {
// Probe kernel: tells whether this build's machine code runs on the device.
__global__ void k_probe() {}

}  // namespace

std::string kernel_driver_version() {
  std::FILE* f = std::fopen("/proc/driver/nvidia/version", "r");
  if (!f) return {};
  char line[512] = {0};
  std::string v;
  if (std::fgets(line, sizeof line, f)) {
    const std::string l = line;
    // "NVRM version: NVIDIA UNIX [Open ]Kernel Module [for x86_64]  580.159.04  ...": the
    // first token after "Kernel Module" that starts with a digit and holds a dot.
    const size_t k = l.find("Kernel Module");
    size_t pos = k == std::string::npos ? 0 : k;
    while (pos < l.size()) {
      const size_t a = l.find_first_not_of(" \t\n", pos);
      if (a == std::string::npos) break;
      const size_t b = l.find_first_of(" \t\n", a);
      const std::string tok = l.substr(a, b == std::string::npos ? std::string::npos : b - a);
      if (std::isdigit(static_cast<unsigned char>(tok[0])) && tok.find('.') != std::string::npos) {
        v = tok;
        break;
      }
      if (b == std::string::npos) break;
      pos = b;
    }
  }
  std::fclose(f);
  return v;
}

void ensure_device() {
  std::string why;
  if (!device_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
}

namespace {
// The probe behind device_available, run once per process.
bool probe_device(std::string* why_not) {
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  if (e != cudaSuccess || n == 0) {
    (void)cudaGetLastError();
    if (why_not)
      *why_not = e != cudaSuccess ? fmt::format("no usable CUDA device ({})", cudaGetErrorString(e))
                                  : std::string("no CUDA device found");
    return false;
  }
  cudaFuncAttributes attr;
  e = cudaFuncGetAttributes(&attr, k_probe);
  if (e != cudaSuccess) {
    (void)cudaGetLastError();
    cudaDeviceProp prop{};
    cudaGetDeviceProperties(&prop, 0);
    if (why_not)
      *why_not = fmt::format("this build's kernels (CUDA architectures {}) cannot run on {} (sm_{}{}): {}; rebuild "
                             "with -DCMAKE_CUDA_ARCHITECTURES={}{}",
                             PATHBENCH_CUDA_ARCHS, prop.name, prop.major, prop.minor, cudaGetErrorString(e),
                             prop.major, prop.minor);
    return false;
  }
  return true;
}
}  // namespace

bool device_available(std::string* why_not) {
  // Once per process: every entry point (the run layer, GpuScene, device_info) asks,
  // and the answer cannot change while the process runs.
  static const std::pair<bool, std::string> answer = [] {
    std::string why;
    const bool ok = probe_device(&why);
    return std::make_pair(ok, why);
  }();
  if (!answer.first && why_not) *why_not = answer.second;
  return answer.first;
}

// Neither creates a context on device 0 (the probe of device_available does): an MPI
// rank picks its device first, so that 8 ranks do not all hold a context on GPU 0.
int device_count() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    (void)cudaGetLastError();
    return 0;
  }
  return n;
}

int select_device(int local_rank) {
  const int n = device_count();
  if (n == 0) return -1;  // device_available() says why
  const int device = (local_rank < 0 ? 0 : local_rank) % n;
  PB_CUDA_CHECK(cudaSetDevice(device));
  return device;
}

DeviceInfo device_info() {
  ensure_device();
  DeviceInfo info;
  PB_CUDA_CHECK(cudaGetDevice(&info.device));
  cudaDeviceProp prop{};
  PB_CUDA_CHECK(cudaGetDeviceProperties(&prop, info.device));
  info.name = prop.name;
  info.compute_major = prop.major;
  info.compute_minor = prop.minor;
  info.multiprocessors = prop.multiProcessorCount;
  info.total_memory = prop.totalGlobalMem;
  info.l2_bytes = uint64_t(prop.l2CacheSize);
  PB_CUDA_CHECK(cudaDriverGetVersion(&info.driver_version));
  PB_CUDA_CHECK(cudaRuntimeGetVersion(&info.runtime_version));
  info.slug = pb::slugify(info.name, "unknown-gpu");
  return info;
}

uint64_t default_paths_in_flight(uint64_t bytes_per_path, uint64_t bytes_in_use) {
  const DeviceInfo info = device_info();
  int threads_per_sm = 0;
  PB_CUDA_CHECK(cudaDeviceGetAttribute(&threads_per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, info.device));
  const uint64_t wave = uint64_t(info.multiprocessors) * uint64_t(threads_per_sm);
  // 7.5 full waves of threads (about 2 million paths on an H100), or what
  // kWavefrontBudgetBytes leaves beside the film and the scene (a 2048x2048 film: ~5.5
  // waves; ico:8's 140 MB scene: ~5.6), but never less than one wave.
  const uint64_t waves = wave * kWavefrontPoolWaveHalves / 2;
  const uint64_t room = bytes_in_use < kWavefrontBudgetBytes ? kWavefrontBudgetBytes - bytes_in_use : 0;
  const uint64_t fit = bytes_per_path ? room / bytes_per_path : waves;
  return std::max(wave, std::min(waves, fit));
}

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
