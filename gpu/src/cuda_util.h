#pragma once
// CUDA plumbing for the tracer: checked calls (with the call site), tracked device
// allocations (own count + cudaMemGetInfo), and the one named launch wrapper that
// picks block sizes and times every launch with CUDA events per stage name.
#include <cuda_runtime.h>
#include <fmt/core.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pathbench/common/errors.h"

namespace pb::gpu {

[[noreturn]] void cuda_fail(cudaError_t e, const char* what, const char* file, int line);
inline void cuda_check(cudaError_t e, const char* what, const char* file, int line) {
  if (e != cudaSuccess) cuda_fail(e, what, file, line);
}
#define PB_CUDA_CHECK(expr) ::pb::gpu::cuda_check((expr), #expr, __FILE__, __LINE__)

// Every device allocation of the tracer goes through here.
class DeviceMemory {
 public:
  static DeviceMemory& instance();
  // `what`: what the memory is for; `lower`: the setting(s) a user can lower when it
  // does not fit. Checks cudaMemGetInfo first and throws InputError naming both.
  void* allocate(uint64_t bytes, const char* what, const char* lower);
  void release(void* p);
  // Starts a new peak measurement: own bytes and the device's free memory now.
  void begin_measurement();
  void sample();  // notes the device's free memory (call after allocations / launches)
  uint64_t peak_allocated() const { return peak_; }
  uint64_t peak_meminfo_delta() const { return free_at_begin_ > min_free_ ? free_at_begin_ - min_free_ : 0; }
  static uint64_t free_bytes();

 private:
  std::map<void*, uint64_t> sizes_;
  uint64_t current_ = 0, peak_ = 0;
  uint64_t free_at_begin_ = 0, min_free_ = 0;
};

template <class T> class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(uint64_t n, const char* what, const char* lower) { allocate(n, what, lower); }
  ~DeviceBuffer() { reset(); }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  DeviceBuffer(DeviceBuffer&& o) noexcept : p_(o.p_), n_(o.n_) { o.p_ = nullptr; o.n_ = 0; }
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    if (this != &o) { reset(); p_ = o.p_; n_ = o.n_; o.p_ = nullptr; o.n_ = 0; }
    return *this;
  }
  void allocate(uint64_t n, const char* what, const char* lower) {
    reset();
    if (n == 0) return;
    p_ = static_cast<T*>(DeviceMemory::instance().allocate(n * sizeof(T), what, lower));
    n_ = n;
  }
  void reset() {
    if (p_) DeviceMemory::instance().release(p_);
    p_ = nullptr;
    n_ = 0;
  }
  // Allocates v.size() elements and copies v into them.
  void assign(const std::vector<T>& v, const char* what, const char* lower) {
    allocate(v.size(), what, lower);
    upload(v.data(), v.size());
  }
  void upload(const T* src, uint64_t n) {
    if (n) PB_CUDA_CHECK(cudaMemcpy(p_, src, n * sizeof(T), cudaMemcpyHostToDevice));
  }
  void download(T* dst, uint64_t n) const {
    if (n) PB_CUDA_CHECK(cudaMemcpy(dst, p_, n * sizeof(T), cudaMemcpyDeviceToHost));
  }
  T* get() const { return p_; }
  uint64_t size() const { return n_; }
  uint64_t bytes() const { return n_ * sizeof(T); }

 private:
  T* p_ = nullptr;
  uint64_t n_ = 0;
};

// A stream and an event that are destroyed with their scope (timing brackets, the
// render's own stream).
struct ScopedStream {
  cudaStream_t s = nullptr;
  ScopedStream() { PB_CUDA_CHECK(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking)); }
  ~ScopedStream() { if (s) cudaStreamDestroy(s); }
};
struct ScopedEvent {
  cudaEvent_t e = nullptr;
  ScopedEvent() { PB_CUDA_CHECK(cudaEventCreate(&e)); }
  ~ScopedEvent() { if (e) cudaEventDestroy(e); }
};

// The launch wrapper. Every kernel launched through it must begin with pdl_wait()
// (kernel_sync.h). Each kernel's block size comes from the occupancy calculator
// (cached); launches are counted per stage name and, when profiling, bracketed by CUDA
// events whose times are summed per name after the frame.
class Launcher {
 public:
  Launcher(cudaStream_t stream, bool profile) : stream_(stream), profile_(profile) {}
  ~Launcher();
  Launcher(const Launcher&) = delete;
  Launcher& operator=(const Launcher&) = delete;

  // `threads` total threads (grid = ceil(threads / block)); 0: one full wave of the
  // device (blocks per multiprocessor at full occupancy x multiprocessors), for kernels
  // that loop over a count they read on the device.
  template <class... KArgs, class... Args>
  void launch(const char* name, void (*kernel)(KArgs...), uint64_t threads, Args&&... args) {
    Stage& st = stage(name, reinterpret_cast<const void*>(kernel));
    launch_blocks(st, name, kernel, threads == 0 ? uint64_t(st.full_wave_blocks) : (threads + st.block - 1) / st.block,
                  std::forward<Args>(args)...);
  }
  // A persistent kernel (it loops over its work): one full wave, or fewer blocks where
  // `threads`, the most its work can keep busy, is less (idle warps would still run its
  // prologue, and claim work from a counter: work_chunks.cuh).
  template <class... KArgs, class... Args>
  void launch_persistent(const char* name, void (*kernel)(KArgs...), uint64_t threads, Args&&... args) {
    Stage& st = stage(name, reinterpret_cast<const void*>(kernel));
    const uint64_t wave = uint64_t(st.full_wave_blocks) * uint64_t(st.block);
    const bool fewer = threads != 0 && threads < wave;  // 0: a full wave, as launch() takes it
    launch_blocks(st, name, kernel, fewer ? (threads + st.block - 1) / st.block : uint64_t(st.full_wave_blocks),
                  std::forward<Args>(args)...);
  }
  // The stream later launches go to (the wavefront's pools take turns on theirs: run_pools).
  void set_stream(cudaStream_t stream) { stream_ = stream; }
  // Whether launches may start before the previous kernel of their stream ends (PDL, below).
  void set_pdl(bool on) { pdl_ = on; }
  cudaStream_t stream() const { return stream_; }
  int block_size(const char* name) const;
  // After the stream is synchronised: per-stage table, and its JSON form.
  nlohmann::json collect();
  static std::string format_table(const nlohmann::json& profile);
  void clear();  // forget counts and times (after a warm-up)

 private:
  struct Stage {
    const void* kernel = nullptr;
    int block = 256;
    int full_wave_blocks = 1;
    uint64_t launches = 0;
    std::vector<std::pair<cudaEvent_t, cudaEvent_t>> events;
  };
  // `grid` blocks of the stage's size on the current stream.
  template <class... KArgs, class... Args>
  void launch_blocks(Stage& st, const char* name, void (*kernel)(KArgs...), uint64_t grid, Args&&... args) {
    if (grid == 0) return;
    if (grid > 0x7FFFFFFFull) grid = 0x7FFFFFFFull;  // kernels loop (grid stride)
    cudaEvent_t ev[2] = {nullptr, nullptr};
    if (profile_) {
      ev[0] = next_event();
      ev[1] = next_event();
      PB_CUDA_CHECK(cudaEventRecord(ev[0], stream_));
    }
    // Programmatic dependent launch (Hopper): the next kernel in the stream may be
    // placed on the GPU while this one drains, and waits in pdl_wait() (kernel_sync.h)
    // until this one has finished and its writes are visible. Hides the launch gap
    // between the wavefront's many short dependent stages. Off while profiling, so each
    // stage's events bracket only its own work.
    cudaLaunchAttribute attr[1];
    attr[0].id = cudaLaunchAttributeProgrammaticStreamSerialization;
    attr[0].val.programmaticStreamSerializationAllowed = 1;
    cudaLaunchConfig_t cfg{};
    cfg.gridDim = dim3(unsigned(grid));
    cfg.blockDim = dim3(unsigned(st.block));
    cfg.dynamicSmemBytes = 0;
    cfg.stream = stream_;
    cfg.attrs = attr;
    cfg.numAttrs = profile_ || !pdl_ ? 0 : 1;
    cudaError_t e = cudaLaunchKernelEx(&cfg, kernel, std::forward<Args>(args)...);
    if (e == cudaSuccess) e = cudaGetLastError();
    if (e != cudaSuccess) cuda_fail(e, name, __FILE__, __LINE__);
    ++st.launches;
    if (profile_) {
      PB_CUDA_CHECK(cudaEventRecord(ev[1], stream_));
      st.events.push_back({ev[0], ev[1]});
    }
  }
  Stage& stage(const char* name, const void* kernel);
  cudaEvent_t next_event();
  cudaStream_t stream_;
  bool profile_;
  bool pdl_ = true;
  std::map<std::string, Stage> stages_;
  std::vector<std::string> order_;
  std::vector<cudaEvent_t> pool_;
  size_t pool_used_ = 0;
};

}  // namespace pb::gpu
