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

// Hands out (pixel, sample) pairs: the samples in groups of up to `group` (a packet's
// width), each group pixel by pixel, its samples of one pixel one after the other. Paths
// started together are then samples of one pixel and its neighbours (coherent camera
// rays, as the pixel strategy's packets), and paths that end together add to one film
// pixel, whose sums stay in cache (pixel-fastest order touched every film line once per
// pass over the image: a miss, under a locked add, per path; docs/notes/cpu-log.md). The order
// cannot change the image: each path's numbers come from its (pixel, sample) alone, and
// the film's sums are integers. Pixels [first_pixel, first_pixel + pixels), each with
// samples [first_sample, first_sample + spp).
class SampleSource {
 public:
  SampleSource(uint32_t first_pixel, uint32_t pixels, uint32_t spp, uint32_t first_sample, uint32_t group)
      : total_(uint64_t(pixels) * spp), first_pixel_(first_pixel), end_pixel_(first_pixel + pixels), pixels_(pixels),
        spp_(spp), first_(first_sample), group_(std::max(1u, group)) {}
  // Claims up to n samples; returns the first global index and sets n to the count.
  uint64_t claim(uint64_t& n) {
    uint64_t start = next_.fetch_add(n, std::memory_order_relaxed);
    n = start >= total_ ? 0 : std::min(n, total_ - start);
    return start;
  }
  // Where global index g is, and the next one (stepping without a division).
  struct Cursor {
    uint32_t pixel, sample;  // sample: within [first, first + spp)
    uint32_t in_group, group_size;
  };
  Cursor at(uint64_t g) const {
    const uint64_t full = uint64_t(pixels_) * group_;  // indices in a full group
    const uint64_t k = std::min<uint64_t>(g / full, spp_ / group_);
    const uint32_t size = std::min(group_, spp_ - uint32_t(k) * group_);
    const uint64_t r = g - k * full;
    return {first_pixel_ + uint32_t(r / size), first_ + uint32_t(k) * group_ + uint32_t(r % size), uint32_t(r % size),
            size};
  }
  void step(Cursor& c) const {
    ++c.sample;
    if (++c.in_group < c.group_size) return;
    c.in_group = 0;
    c.sample -= c.group_size;
    if (++c.pixel < end_pixel_) return;
    c.pixel = first_pixel_;  // the next group of samples
    c.sample += c.group_size;
    c.group_size = std::min(group_, first_ + spp_ - c.sample);
  }

 private:
  std::atomic<uint64_t> next_{0};
  uint64_t total_;
  uint32_t first_pixel_, end_pixel_, pixels_, spp_;
  uint32_t first_;  // samples [first_, first_ + spp_) of each pixel
  uint32_t group_;
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
  alignas(64) float ray[6][2 * W] = {};  // zero: the tiny test reads every lane of a packet (embree_rays.h)
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
  // The first `used` entries were traced: the rest (fewer than W) to the front, copied
  // as W entries of constant size (a few vector moves; a memmove of `rest` entries is a
  // library call per array).
  void drop(uint32_t used) {
    const uint32_t rest = n - used;
    if (rest > 0) {
      auto move = [&](auto* a) {
        std::remove_reference_t<decltype(*a)> tmp[W];
        std::memcpy(tmp, a + used, sizeof tmp);
        std::memcpy(a, tmp, sizeof tmp);
      };
      for (auto& r : ray) move(r);
      for (auto& c : contribution) move(c);
      move(tag);
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
