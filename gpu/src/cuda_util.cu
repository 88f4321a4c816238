#include "cuda_util.h"

#include <algorithm>
#include <stdexcept>

namespace pb::gpu {

void cuda_fail(cudaError_t e, const char* what, const char* file, int line) {
  const char* base = file;
  for (const char* p = file; *p; ++p)
    if (*p == '/') base = p + 1;
  if (e == cudaErrorMemoryAllocation)
    throw InputError(fmt::format("out of device memory in {} ({}:{}): {}; lower --paths-in-flight, --spp or "
                                 "--width/--height",
                                 what, base, line, cudaGetErrorString(e)));
  if (e == cudaErrorNoDevice || e == cudaErrorInsufficientDriver)
    throw InputError(fmt::format("--device gpu: {} ({} at {}:{})", cudaGetErrorString(e), what, base, line));
  throw std::runtime_error(fmt::format("CUDA error {} ({}) in {} at {}:{}", int(e), cudaGetErrorString(e), what, base, line));
}

DeviceMemory& DeviceMemory::instance() {
  // Never destroyed: buffers held by other statics (the benchmark's scene cache) are
  // released during static destruction, in an order no one controls; a destroyed
  // ledger there was a crash at exit (pathbench-bench, signal 11).
  static DeviceMemory* m = new DeviceMemory;
  return *m;
}

uint64_t DeviceMemory::free_bytes() {
  size_t free_b = 0, total_b = 0;
  PB_CUDA_CHECK(cudaMemGetInfo(&free_b, &total_b));
  return free_b;
}

void* DeviceMemory::allocate(uint64_t bytes, const char* what, const char* lower) {
  const uint64_t free_b = free_bytes();
  // Leave a little room for the driver (local memory of launches, events).
  const uint64_t reserve = 64ull << 20;
  if (bytes + reserve > free_b)
    throw InputError(fmt::format("{} needs {:.1f} MB of device memory but only {:.1f} MB are free; lower {}", what,
                                 bytes / 1e6, free_b / 1e6, lower));
  void* p = nullptr;
  const cudaError_t e = cudaMalloc(&p, bytes);
  if (e == cudaErrorMemoryAllocation) {
    (void)cudaGetLastError();
    throw InputError(fmt::format("{}: cudaMalloc of {:.1f} MB failed (out of device memory); lower {}", what,
                                 bytes / 1e6, lower));
  }
  cuda_check(e, "cudaMalloc", __FILE__, __LINE__);
  sizes_[p] = bytes;
  current_ += bytes;
  peak_ = std::max(peak_, current_);
  sample();
  return p;
}

void DeviceMemory::release(void* p) {
  auto it = sizes_.find(p);
  if (it == sizes_.end()) return;
  current_ -= it->second;
  sizes_.erase(it);
  cudaFree(p);  // not checked: may run during unwinding
}

void DeviceMemory::begin_measurement() {
  peak_ = current_;
  free_at_begin_ = free_bytes() + current_;  // as if nothing of ours were allocated
  min_free_ = free_at_begin_;
  sample();
}

void DeviceMemory::sample() {
  size_t free_b = 0, total_b = 0;
  if (cudaMemGetInfo(&free_b, &total_b) == cudaSuccess) min_free_ = std::min<uint64_t>(min_free_ ? min_free_ : free_b, free_b);
}

Launcher::~Launcher() {
  for (cudaEvent_t e : pool_) cudaEventDestroy(e);
}

Launcher::Stage& Launcher::stage(const char* name, const void* kernel) {
  auto it = stages_.find(name);
  if (it != stages_.end() && it->second.kernel == kernel) return it->second;
  if (it == stages_.end()) order_.push_back(name);
  Stage& st = stages_[name];
  st.kernel = kernel;
  int min_grid = 0, block = 0;
  PB_CUDA_CHECK(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, kernel, 0, 0));
  // Prefer whole multiples of 64 threads up to 256: small blocks keep the tail short.
  st.block = std::max(64, std::min(block, 256) / 64 * 64);
  int per_sm = 0, device = 0, sms = 0;
  PB_CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, st.block, 0));
  PB_CUDA_CHECK(cudaGetDevice(&device));
  PB_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
  st.full_wave_blocks = std::max(1, per_sm) * sms;
  return st;
}

int Launcher::block_size(const char* name) const {
  auto it = stages_.find(name);
  return it == stages_.end() ? 0 : it->second.block;
}

cudaEvent_t Launcher::next_event() {
  if (pool_used_ == pool_.size()) {
    cudaEvent_t e;
    PB_CUDA_CHECK(cudaEventCreate(&e));
    pool_.push_back(e);
  }
  return pool_[pool_used_++];
}

void Launcher::clear() {
  for (auto& [name, st] : stages_) {
    st.launches = 0;
    st.events.clear();
  }
  pool_used_ = 0;
}

nlohmann::json Launcher::collect() {
  nlohmann::json stages = nlohmann::json::array();
  double total = 0;
  std::vector<double> ms(order_.size(), 0.0);
  for (size_t i = 0; i < order_.size(); ++i) {
    const Stage& st = stages_[order_[i]];
    for (auto [a, b] : st.events) {
      float m = 0;
      PB_CUDA_CHECK(cudaEventElapsedTime(&m, a, b));
      ms[i] += m;
    }
    total += ms[i];
  }
  for (size_t i = 0; i < order_.size(); ++i) {
    const Stage& st = stages_[order_[i]];
    if (st.launches == 0) continue;
    stages.push_back({{"name", order_[i]},
                      {"launches", st.launches},
                      {"block", st.block},
                      {"total_ms", ms[i]},
                      {"share", total > 0 ? ms[i] / total : 0.0}});
  }
  return {{"stages", stages}, {"total_ms", total}, {"timed", profile_}};
}

std::string Launcher::format_table(const nlohmann::json& profile) {
  std::string out = fmt::format("{:<24} {:>9} {:>6} {:>11} {:>7}\n", "stage", "launches", "block", "total ms", "share");
  for (const auto& s : profile["stages"])
    out += fmt::format("{:<24} {:>9} {:>6} {:>11.3f} {:>6.1f}%\n", s["name"].get<std::string>(),
                       s["launches"].get<uint64_t>(), s["block"].get<int>(), s["total_ms"].get<double>(),
                       100.0 * s["share"].get<double>());
  out += fmt::format("{:<24} {:>9} {:>6} {:>11.3f} {:>6.1f}%\n", "total", "", "", profile["total_ms"].get<double>(), 100.0);
  return out;
}

}  // namespace pb::gpu
