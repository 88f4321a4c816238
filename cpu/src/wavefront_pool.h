#pragma once
// The CPU wavefront's pool of paths in flight (one slice per thread) and the hand-out of
// (pixel, sample) pairs it refills from. Private to render_wavefront.cpp (each of its
// translation units: the material kinds are compiled per file), hence the unnamed namespace.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

#include "pathbench/common/path.h"
#include "pathbench/common/report.h"

namespace pb::cpu {
namespace {

// Hands out (pixel, sample) pairs in pixel-fastest order, so paths started together
// are neighbours on the image (coherent camera rays): `pixels` pixels from `first_pixel`
// on (whole rows: an MPI rank's chunk may be a band of the frame), each with samples
// [first_sample, first_sample + total / pixels).
class SampleSource {
 public:
  SampleSource(uint64_t total, uint32_t first_pixel, uint32_t pixels, uint32_t first_sample)
      : total_(total), first_pixel_(first_pixel), pixels_(pixels), first_(first_sample) {}
  // Claims up to n samples; returns the first global index and sets n to the count.
  uint64_t claim(uint64_t& n) {
    uint64_t start = next_.fetch_add(n, std::memory_order_relaxed);
    n = start >= total_ ? 0 : std::min(n, total_ - start);
    return start;
  }
  uint32_t pixel_of(uint64_t g) const { return first_pixel_ + uint32_t(g % pixels_); }
  uint32_t sample_of(uint64_t g) const { return first_ + uint32_t(g / pixels_); }
  uint32_t first_pixel() const { return first_pixel_; }
  uint32_t end_pixel() const { return first_pixel_ + pixels_; }

 private:
  std::atomic<uint64_t> next_{0};
  uint64_t total_;
  uint32_t first_pixel_, pixels_;
  uint32_t first_;  // samples [first_, first_ + total_ / pixels_) of each pixel
};

// One thread's share of the paths in flight. Every slot is in exactly one place at a
// time: `free`, `live` (its next ray is a closest-hit query), `final` (at its last
// vertex: the emitter query), or a pending shadow packet of the stages (at most one
// packet's worth, outside the pool). The lists are fixed arrays with counts, not
// growing vectors: the stages append with one store each, and `live` is compacted in
// place by the pass that reads it (render_wavefront.cpp).
template <class T> struct PoolSlice {
  explicit PoolSlice(size_t n) : state(n), shadow(n), free(n), live(n), final(n), n_free(uint32_t(n)) {
    for (size_t i = 0; i < n; ++i) free[i] = uint32_t(n - 1 - i);
  }
  std::vector<PathState<T>> state;
  std::vector<ShadowQuery<T>> shadow;
  std::vector<uint32_t> free, live, final;
  uint32_t n_free, n_live = 0, n_final = 0;

  static constexpr size_t bytes_per_path = sizeof(PathState<T>) + sizeof(ShadowQuery<T>) + sizeof(uint32_t) * 3;
};

struct Local {
  RayCounts rays;
  uint64_t paths = 0, discarded = 0;
};

}  // namespace
}  // namespace pb::cpu
