// The wavefront and paper-queue strategies' frame loop: trace (plans the iteration,
// traces the last iteration's shadow rays and this one's closest hits) and shade launched
// in turn on one stream (no host wait between them); whether the frame is done is read
// from mapped host memory the trace kernels write.
#include "path_pool.cuh"

#include <stdexcept>
#include <thread>

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

FrameResult PathPool::run(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c, uint32_t spp,
                          uint64_t total, FilmDev film, bool variance) {
  PB_CUDA_CHECK(cudaMemsetAsync(ctr_.get(), 0, sizeof(WaveCounters), stream));
  const ShadowSoA sh{sh_o_.get(), sh_d_.get(), sh_ct_.get(), sh_L_.get(), sh_d2_.get(), sh_c2_.get()};
  WaveCounters* ctr = ctr_.get();
  const uint32_t cap = uint32_t(capacity_);
  FrameResult r;
  // Whether the frame is done is read from the plans the trace kernels write into
  // mapped host memory: no copy or synchronisation in the stream, so the GPU never
  // idles while the host looks (a synchronous look every 4 iterations drained the queue
  // 20 times a paper frame). The host stays kLag iterations ahead of what it reads, so
  // up to kLag empty iterations (kernels that find nothing to do) follow the last.
  constexpr uint64_t kLag = 3;
  static_assert(kLag < kPlanSlots, "a slot is read and reset before the GPU reaches it again");
  for (int k = 0; k < kPlanSlots; ++k) planned_[k] = kNotPlanned;
  const uint32_t counter_rounds =
      g.bvh_tris >= kPixelLatencyBoundTris ? kWavefrontCounterRoundsLatencyBound : kWavefrontCounterRounds;
  for (uint64_t it = 0;; ++it) {
    const PathSoA cur = buf_[it & 1].view(), next = buf_[(it + 1) & 1].view();
    const uint32_t parity = uint32_t(it & 1);
    const WaveStep step{parity, static_cast<unsigned long long>(total), cap, &planned_[it % kPlanSlots], counter_rounds};
    with_traversal_kind(g.bvh, [&](auto kind) {  // trace compiled for the BVH layout
      constexpr int B = decltype(kind)::value;
      auto go = [&](auto kernel) {
        launch.launch("trace", kernel, 0, g.view, c, g.bvh, cur, prim_.get(), sh, ctr, step, film, spp);
      };
      // Without shadow rays nothing in trace touches the film: no variance variant.
      if (!shadows_.records) go(k_wf_trace<false, false, B>);
      else if (variance) go(k_wf_trace<true, true, B>);
      else go(k_wf_trace<false, true, B>);
    });
    with_features(g.view.material_kinds, [&](auto kinds) {  // shade compiled for the scene's kinds
      constexpr uint32_t K = decltype(kinds)::value;
      if (variance) launch.launch("shade", k_wf_shade<true, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, parity, film, spp, counter_rounds);
      else launch.launch("shade", k_wf_shade<false, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, parity, film, spp, counter_rounds);
    });
    if (it >= kLag) {
      const uint64_t seen = it - kLag;
      const uint32_t has_paths = wait_for_plan(stream, planned_[seen % kPlanSlots]);
      planned_[seen % kPlanSlots] = kNotPlanned;
      if (!has_paths) {  // an iteration with nothing to trace: no path continued, no sample is left
        r.iterations = seen + 1;
        break;
      }
    }
  }
  // The empty iteration's trace booked every one before it and traced their last shadow
  // rays; every path has ended.
  PB_CUDA_CHECK(cudaMemcpyAsync(host_ctr_, ctr, sizeof(WaveCounters), cudaMemcpyDeviceToHost, stream));
  PB_CUDA_CHECK(cudaStreamSynchronize(stream));
  r.stats = host_ctr_->stats;
  r.stats.paths = r.stats.camera;
  r.state_bytes_per_path = state_bytes(shadows_);
  r.paths_in_flight = capacity_;
  r.counter_rounds = counter_rounds;
  r.pool_bytes = capacity_ * state_bytes(shadows_) + sizeof(WaveCounters);
  return r;
}

}  // namespace pb::gpu
