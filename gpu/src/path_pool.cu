// The wavefront and paper-queue strategies' frame loop: intersect (which plans the
// iteration), shade and shadow launched in turn on one stream (no host wait between
// them), the counters read back every few iterations to see whether the frame is done.
#include "path_pool.cuh"

#include "wavefront_stages.cuh"

namespace pb::gpu {

FrameResult PathPool::run(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c, uint32_t spp,
                          uint64_t total, FilmDev film, bool variance) {
  PB_CUDA_CHECK(cudaMemsetAsync(ctr_.get(), 0, sizeof(WaveCounters), stream));
  const ShadowSoA sh{sh_o_.get(), sh_d_.get(), sh_ct_.get(), sh_L_.get(), sh_d2_.get(), sh_c2_.get()};
  WaveCounters* ctr = ctr_.get();
  const uint32_t cap = uint32_t(capacity_);
  FrameResult r;
  // Every kCheckEvery iterations the counters are copied to the host; the host then reads
  // the copy of the look before, kCheckEvery iterations older, which the GPU has long
  // finished: the host stays that far ahead and the GPU never idles while the host waits
  // (a synchronous look drained the queue 20 times a paper frame). The price: up to
  // 2 kCheckEvery - 1 iterations after the last, whose kernels find nothing to do.
  constexpr int kCheckEvery = 4;
  uint64_t looks = 0;
  const WaveCounters* last = nullptr;  // the copy that saw the frame done
  for (uint64_t it = 0;; ++it) {
    const PathSoA cur = buf_[it & 1].view(), next = buf_[(it + 1) & 1].view();
    const uint32_t parity = uint32_t(it & 1);
    const WaveStep step{parity, static_cast<unsigned long long>(total), cap};
    with_traversal_kind(g.bvh.kind, [&](auto kind) {  // intersect compiled for the BVH layout
      launch.launch("intersect", k_wf_intersect<decltype(kind)::value>, 0, g.view, c, g.bvh, cur, prim_.get(), ctr, step, spp);
    });
    with_features(g.view.material_kinds, [&](auto kinds) {  // shade compiled for the scene's kinds
      constexpr uint32_t K = decltype(kinds)::value;
      if (variance) launch.launch("shade", k_wf_shade<true, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, parity, film, spp);
      else launch.launch("shade", k_wf_shade<false, K>, 0, g.view, c, cur, next, prim_.get(), sh, ctr, parity, film, spp);
    });
    if (shadows_.records) {
      with_traversal_kind(g.bvh.kind, [&](auto kind) {
        constexpr int B = decltype(kind)::value;
        if (variance) launch.launch("shadow", k_wf_shadow<true, B>, 0, g.bvh, sh, next, ctr, parity, film);
        else launch.launch("shadow", k_wf_shadow<false, B>, 0, g.bvh, sh, next, ctr, parity, film);
      });
    }
    if (it % kCheckEvery == kCheckEvery - 1) {
      const int b = int(looks & 1);
      PB_CUDA_CHECK(cudaMemcpyAsync(&host_ctr_[b], ctr, sizeof(WaveCounters), cudaMemcpyDeviceToHost, stream));
      PB_CUDA_CHECK(cudaEventRecord(looked_[b], stream));
      if (looks++ > 0) {  // the look before: iteration it - kCheckEvery
        PB_CUDA_CHECK(cudaEventSynchronize(looked_[b ^ 1]));
        const uint64_t seen = it - kCheckEvery;
        // An iteration planned with nothing to trace: no path continued, no sample is left.
        if (host_ctr_[b ^ 1].it[seen & 1].n_cur == 0) {
          r.iterations = seen + 1;
          last = &host_ctr_[b ^ 1];
          break;
        }
      }
    }
  }
  // The empty iteration's intersect booked every one before it; every path has ended.
  r.stats = last->stats;
  r.stats.paths = r.stats.camera;
  r.state_bytes_per_path = state_bytes(shadows_);
  r.paths_in_flight = capacity_;
  r.pool_bytes = capacity_ * state_bytes(shadows_) + sizeof(WaveCounters);
  return r;
}

}  // namespace pb::gpu
