// The wavefront and paper-queue strategies' frame loop: trace (plans the iteration,
// traces the last iteration's shadow rays and this one's closest hits) and shade launched
// in turn on a pool's stream (no host wait between them), the pools of a frame taking
// turns (run_pools); whether a pool is done is read from mapped host memory its trace
// kernels write.
#include "path_pool.cuh"

#include <fmt/core.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <vector>

#include "pathbench/common/errors.h"

#include "wavefront_stages.cuh"

namespace pb::gpu {

namespace {

// What a trace kernel wrote into `slot` (mapped host memory: 1 if its iteration has
// paths, 0 if not), waiting for the GPU to get there; a failure in the stream is
// reported instead of waiting forever.
uint32_t wait_for_plan(cudaStream_t stream, const uint32_t& slot) {
  const volatile uint32_t& v = slot;
  for (uint32_t spins = 0;; ++spins) {
    if (v != kNotPlanned) return v;
    if (spins % 1024 == 1023) {
      const cudaError_t e = cudaStreamQuery(stream);
      if (e == cudaSuccess && v == kNotPlanned)
        throw std::logic_error("wavefront: the stream drained but the iteration's plan never arrived");
      if (e != cudaSuccess && e != cudaErrorNotReady) PB_CUDA_CHECK(e);
      std::this_thread::yield();
    }
  }
}

}  // namespace

void PathPool::begin(cudaStream_t stream, uint64_t first, uint64_t count, const GpuScene::Impl& g) {
  // The record iteration 0 plans from (it[1]) says that samples up to `first` are handed out.
  *host_ctr_ = WaveCounters{};
  host_ctr_->it[1].next_after = first;
  PB_CUDA_CHECK(cudaMemcpyAsync(ctr_.get(), host_ctr_, sizeof(WaveCounters), cudaMemcpyHostToDevice, stream));
  for (int k = 0; k < kPlanSlots; ++k) planned_[k] = kNotPlanned;
  end_ = first + count;
  it_ = 0;
  iterations_ = 0;
  stream_ = stream;
  counter_rounds_ =
      g.bvh_tris >= kPixelLatencyBoundTris ? kWavefrontCounterRoundsLatencyBound : kWavefrontCounterRounds;
}

bool PathPool::step(Launcher& launch, const GpuScene::Impl& g, const PathConfig& c, FilmDev film,
                    bool variance) {
  // Whether the frame is done is read from the plans the trace kernels write into
  // mapped host memory: no copy or synchronisation in the stream, so the GPU never
  // idles while the host looks (a synchronous look every 4 iterations drained the queue
  // 20 times a paper frame). The host stays kLag iterations ahead of what it reads, so
  // up to kLag empty iterations (kernels that find nothing to do) follow the last.
  constexpr uint64_t kLag = 3;
  static_assert(kLag < kPlanSlots, "a slot is read and reset before the GPU reaches it again");
  const ShadowSoA sh{sh_o_.get(), sh_d_.get(), sh_ct_.get(), sh_L_.get(), sh_d2_.get(), sh_c2_.get()};
  WaveCounters* ctr = ctr_.get();
  const uint64_t it = it_++;
  const PathSoA cur = buf_[it & 1].view(), next = buf_[(it + 1) & 1].view();
  const uint32_t parity = uint32_t(it & 1);
  const WaveStep step{parity, static_cast<unsigned long long>(end_), uint32_t(capacity_), &planned_[it % kPlanSlots],
                      counter_rounds_};
  with_traversal_kind(g.bvh, [&](auto kind) {  // trace compiled for the BVH layout
    constexpr int B = decltype(kind)::value;
    auto go = [&](auto kernel) {
      launch.launch("trace", kernel, 0, g.view, c, g.bvh, cur, prim_.get(), sh, ctr, step, film);
    };
    // Without shadow rays nothing in trace touches the film: no variance variant.
    if (!shadows_.records) go(k_wf_trace<false, false, B>);
    else if (variance) go(k_wf_trace<true, true, B>);
    else go(k_wf_trace<false, true, B>);
  });
  with_features(g.view.material_kinds, [&](auto kinds) {  // shade compiled for the scene's kinds
    constexpr uint32_t K = decltype(kinds)::value;
    if (variance) launch.launch("shade", k_wf_shade<true, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, parity, film, counter_rounds_);
    else launch.launch("shade", k_wf_shade<false, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, parity, film, counter_rounds_);
  });
  if (it < kLag) return true;
  const uint64_t seen = it - kLag;
  const uint32_t has_paths = wait_for_plan(stream_, planned_[seen % kPlanSlots]);
  planned_[seen % kPlanSlots] = kNotPlanned;
  if (has_paths) return true;
  iterations_ = seen + 1;  // an iteration with nothing to trace: no path continued, no sample is left
  return false;
}

FrameResult PathPool::finish(cudaStream_t stream) {
  // The empty iteration's trace booked every one before it and traced their last shadow
  // rays; every path has ended.
  PB_CUDA_CHECK(cudaMemcpyAsync(host_ctr_, ctr_.get(), sizeof(WaveCounters), cudaMemcpyDeviceToHost, stream));
  PB_CUDA_CHECK(cudaStreamSynchronize(stream));
  FrameResult r;
  r.iterations = iterations_;
  r.stats = host_ctr_->stats;
  r.stats.paths = r.stats.camera;
  r.state_bytes_per_path = state_bytes(shadows_);
  r.paths_in_flight = capacity_;
  r.counter_rounds = counter_rounds_;
  r.pool_bytes = capacity_ * state_bytes(shadows_) + sizeof(WaveCounters);
  return r;
}

int wavefront_pools(uint64_t total, uint64_t paths_in_flight) {
  const char* v = std::getenv("PATHBENCH_GPU_WAVEFRONT_POOLS");
  if (!v || !*v) return total > paths_in_flight ? kWavefrontPools : 1;
  const std::string_view s(v);
  if (s.size() == 1 && s[0] >= '1' && s[0] <= '4') return s[0] - '0';
  throw InputError(fmt::format("PATHBENCH_GPU_WAVEFRONT_POOLS: '{}' is not a pool count 1..4", s));
}

FrameResult run_pools(PathPool* const* pools, const cudaStream_t* streams, int n, Launcher& launch,
                      const GpuScene::Impl& g, const PathConfig& c, uint64_t total, FilmDev film,
                      bool variance) {
  const cudaStream_t home = launch.stream();
  // streams[k] past its work: the others start, or streams[0] ends, after it (one pool
  // needs none: nothing is made between the frame's start event and its first launch).
  std::vector<ScopedEvent> ready(n > 1 ? static_cast<size_t>(n) : 0);
  if (n > 1) PB_CUDA_CHECK(cudaEventRecord(ready[0].e, streams[0]));
  for (int k = 0; k < n; ++k) {
    if (k > 0) PB_CUDA_CHECK(cudaStreamWaitEvent(streams[k], ready[0].e, 0));
    pools[k]->begin(streams[k], total * uint64_t(k) / uint64_t(n), total * uint64_t(k + 1) / uint64_t(n) - total * uint64_t(k) / uint64_t(n), g);
  }
  // Without PDL: a pool's next kernel would be placed while its last drains, and hold the
  // SMs waiting that the other pool's kernels could use (H100, paper-cornell nee, two
  // pools: 14.88 ms with PDL, 14.74 without; one pool: the same either way).
  launch.set_pdl(n == 1);
  std::vector<bool> going(size_t(n), true);
  for (int left = n; left > 0;) {
    for (int k = 0; k < n; ++k) {
      if (!going[size_t(k)]) continue;
      launch.set_stream(streams[k]);
      if (!pools[k]->step(launch, g, c, film, variance)) {
        going[size_t(k)] = false;
        --left;
      }
    }
  }
  launch.set_stream(home);
  launch.set_pdl(true);
  FrameResult r;
  for (int k = n - 1; k >= 0; --k) {  // the others first: streams[0] then waits for them
    const FrameResult p = pools[k]->finish(streams[k]);
    if (k > 0) {
      PB_CUDA_CHECK(cudaEventRecord(ready[size_t(k)].e, streams[k]));
      PB_CUDA_CHECK(cudaStreamWaitEvent(streams[0], ready[size_t(k)].e, 0));
    }
    r.stats.camera += p.stats.camera;
    r.stats.bounce += p.stats.bounce;
    r.stats.shadow += p.stats.shadow;
    r.stats.paths += p.stats.paths;
    r.stats.discarded += p.stats.discarded;
    r.iterations = std::max(r.iterations, p.iterations);
    r.paths_in_flight += p.paths_in_flight;
    r.pool_bytes += p.pool_bytes;
    r.state_bytes_per_path = p.state_bytes_per_path;
    r.counter_rounds = p.counter_rounds;
  }
  return r;
}

}  // namespace pb::gpu
