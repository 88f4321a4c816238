// Device facts: whether this build's kernels run on the device, its properties, the
// kernel driver's version from /proc, and the wavefront's default pool size.
#include "device_facts.h"

#include <cuda_runtime.h>
#include <fmt/core.h>

#include <cctype>
#include <cstdio>
#include <string>
#include <utility>

#include "cuda_util.h"
#include "pathbench/common/errors.h"
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

std::string slugify(const std::string& name) {
  std::string out;
  for (char ch : name) {
    if (std::isalnum(static_cast<unsigned char>(ch))) out += char(std::tolower(static_cast<unsigned char>(ch)));
    else if (!out.empty() && out.back() != '-') out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.empty() ? "unknown-gpu" : out;
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
  PB_CUDA_CHECK(cudaDriverGetVersion(&info.driver_version));
  PB_CUDA_CHECK(cudaRuntimeGetVersion(&info.runtime_version));
  info.slug = slugify(info.name);
  return info;
}

uint64_t default_paths_in_flight() {
  const DeviceInfo info = device_info();
  int threads_per_sm = 0;
  PB_CUDA_CHECK(cudaDeviceGetAttribute(&threads_per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, info.device));
  // Five full waves of threads: enough paths for every stage to fill the device
  // (about 1.35 million on an H100); at 192 bytes a path (with light sampling) the pool
  // takes ~260 MB, which leaves room for a 2048x2048 film under 512 MB.
  return uint64_t(info.multiprocessors) * uint64_t(threads_per_sm) * 5;
}

}  // namespace pb::gpu
