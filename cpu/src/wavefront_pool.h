#pragma once
// The CPU wavefront's pool of paths in flight (one slice per thread) and the hand-out of
// (pixel, sample) pairs it refills from. Private to render_wavefront.cpp (each of its
// translation units: the material kinds are compiled per file), hence the unnamed namespace.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "pathbench/common/path.h"
#include "pathbench/common/report.h"
#include "shade_batch.h"

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
  uint32_t pixels() const { return pixels_; }

 private:
  std::atomic<uint64_t> next_{0};
  uint64_t total_;
  uint32_t pixels_;
  uint32_t first_;  // samples [first_, first_ + total_ / pixels_) of each pixel
};

// One thread's share of the paths in flight. Every slot is in exactly one place at a
// time: `free`, `live` (its next ray is a closest-hit query), `final` (at its last
// vertex: the emitter query), or the pending shadow rays (PendingShadows, outside the
// pool). The lists are fixed arrays with counts, not growing vectors: the stages append
// with one store each, and `live` is compacted in place by the pass that reads it
// (render_wavefront.cpp). With the batched path step, `ray` holds the live paths' rays
// by position in `live` (six arrays: org x, y, z, dir x, y, z), written by the kernels
// (begin_paths, the shading's `next` stream) and traced from in place: no transpose.
template <class T> struct PoolSlice {
  PoolSlice(size_t n, bool soa_rays) : state(n), free(n), live(n), final(n), n_free(uint32_t(n)) {
    for (size_t i = 0; i < n; ++i) free[i] = uint32_t(n - 1 - i);
    // A packet at the end of `live` reads (and ignores) up to a packet's width past it.
    if (soa_rays)
      for (auto& r : ray) r.assign(n + kMaxShadeLanes, 0.0f);
  }
  std::vector<PathState<T>> state;
  std::vector<uint32_t> free, live, final;
  std::vector<float> ray[6];
  uint32_t n_free, n_live = 0, n_final = 0;

  // (The rays count whether used or not: an upper bound.)
  static constexpr size_t bytes_per_path = sizeof(PathState<T>) + sizeof(float) * 6 + sizeof(uint32_t) * 3;
};

// The shadow rays waiting for a full packet of W, as arrays (the shading kernel appends
// to them as its `shadow` stream): fewer than W before a batch appends up to W more.
// Tags are pool slots, | ShadeStream::kEnds where the path is done once its ray is
// answered. Contributions in T (a double path step adds double radiance).
template <class T, int W> struct PendingShadows {
  alignas(64) float ray[6][2 * W];
  alignas(64) T contribution[3][2 * W];
  alignas(64) uint32_t tag[2 * W];
  uint32_t n = 0;

  // One query of the scalar path step or of a final vertex.
  void push(uint32_t slot_and_ends, const ShadowQuery<T>& q) {
    const float r[6] = {float(q.ray.o.x), float(q.ray.o.y), float(q.ray.o.z),
                        float(q.ray.d.x), float(q.ray.d.y), float(q.ray.d.z)};  // to_embree's rounding
    for (int j = 0; j < 6; ++j) ray[j][n] = r[j];
    contribution[0][n] = q.contribution.x;
    contribution[1][n] = q.contribution.y;
    contribution[2][n] = q.contribution.z;
    tag[n++] = slot_and_ends;
  }
  // Where the batched shading appends (T = float).
  ShadeStream stream() {
    ShadeStream s{};
    for (int j = 0; j < 6; ++j) s.ray[j] = ray[j];
    if constexpr (std::is_same_v<T, float>)
      for (int j = 0; j < 3; ++j) s.contribution[j] = contribution[j];
    s.tag = tag;
    s.n = n;
    return s;
  }
  // The first `used` entries were traced: the rest to the front.
  void drop(uint32_t used) {
    const uint32_t rest = n - used;
    if (rest > 0) {
      for (auto& r : ray) std::memmove(r, r + used, rest * sizeof(float));
      for (auto& c : contribution) std::memmove(c, c + used, rest * sizeof(T));
      std::memmove(tag, tag + used, rest * sizeof(uint32_t));
    }
    n = rest;
  }
};

struct Local {
  RayCounts rays;
  uint64_t paths = 0, discarded = 0;
};

}  // namespace
}  // namespace pb::cpu
