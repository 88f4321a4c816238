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
// are neighbours on the image (coherent camera rays).
class SampleSource {
 public:
  SampleSource(uint64_t total, uint32_t pixels, uint32_t first_sample)
      : total_(total), pixels_(pixels), first_(first_sample) {}
  // Claims up to n samples; returns the first global index and sets n to the count.
  uint64_t claim(uint64_t& n) {
    uint64_t start = next_.fetch_add(n, std::memory_order_relaxed);
    n = start >= total_ ? 0 : std::min(n, total_ - start);
    return start;
  }
  uint32_t pixel_of(uint64_t g) const { return uint32_t(g % pixels_); }
  uint32_t sample_of(uint64_t g) const { return first_ + uint32_t(g / pixels_); }

 private:
  std::atomic<uint64_t> next_{0};
  uint64_t total_;
  uint32_t pixels_;
  uint32_t first_;  // samples [first_, first_ + total_ / pixels_) of each pixel
};

template <class T> struct PoolSlice {
  explicit PoolSlice(size_t n) : state(n), shadow(n), prim(n) {
    free.reserve(n);
    live.reserve(n);
    next_live.reserve(n);
    shadowed.reserve(n);
    done.reserve(n);
    for (size_t i = n; i-- > 0;) free.push_back(uint32_t(i));
  }
  std::vector<PathState<T>> state;
  std::vector<ShadowQuery<T>> shadow;
  std::vector<uint32_t> prim;  // hit triangle, or RTC_INVALID_GEOMETRY_ID
  std::vector<uint32_t> free, live, next_live, shadowed, done;

  static constexpr size_t bytes_per_path =
      sizeof(PathState<T>) + sizeof(ShadowQuery<T>) + sizeof(uint32_t) * 6;
};

struct Local {
  RayCounts rays;
  uint64_t paths = 0, discarded = 0;
};

}  // namespace
}  // namespace pb::cpu
