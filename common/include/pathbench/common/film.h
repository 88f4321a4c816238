#pragma once
// Per-pixel radiance sums in 64-bit fixed point. Integer addition is exact and
// associative, so the sum does not depend on the order samples arrive in (pixel vs
// ray-parallel, 1 or 64 threads, CPU atomics or CUDA atomicAdd): images from any
// strategy are bit-identical, and 10^6 samples do not drift the way a float or even a
// double running sum does. The scale is a power of two chosen per render from the
// scene's brightest emitter and the sample count, so the sum cannot overflow unless
// the mean pixel value exceeds 1024 x the brightest emission.
#if !defined(__CUDACC__)
#include <atomic>
#endif
#include <cmath>
#include <cstdint>
#include <vector>

#include "pathbench/common/math.h"

namespace pb {

// What a sample turns into on the film; the same function on CPU and GPU.
PB_HD int64_t quantize_radiance(float v, double scale) { return int64_t(std::llrint(double(v) * scale)); }

// Whether a sample may enter the film: every channel finite and strictly below `limit`
// (Film::sample_limit()), so that no sum can overflow. The one acceptance test of both
// tracers: Film::add on the CPU, the GPU's film_add_warp; a rejected sample is counted
// as discarded.
PB_HD bool sample_acceptable(Vec3f L, double limit) {
  return is_finite(L) && double(std::fabs(L.x)) < limit && double(std::fabs(L.y)) < limit &&
         double(std::fabs(L.z)) < limit;
}

class Film {
 public:
  Film() = default;
  Film(uint32_t width, uint32_t height, bool variance);

  // Picks the fixed-point scale for `spp` samples of a scene whose brightest
  // emission channel is `max_emission`, and zeroes the sums.
  void begin(uint64_t spp, float max_emission);
  static double choose_scale(uint64_t spp, float max_emission);

  // Sample value -> film; false (and nothing added) when any channel is NaN or
  // infinite, or so large it would overflow: the caller counts it as discarded.
  // (Inline, below: they run once per sample in the tracers' inner loops.)
  bool add(uint32_t pixel, Vec3f L);         // single writer per pixel
  bool add_atomic(uint32_t pixel, Vec3f L);  // many writers
  // Largest per-pixel sum (2^62); one sample may use at most a quarter of it.
  static constexpr double kMaxSum = 4611686018427387904.0;
  // Every channel of an accepted sample is finite and strictly below this: kMaxSum / 4 /
  // scale(). The GPU's film applies the same bound (sample_acceptable).
  double sample_limit() const { return limit_; }

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  size_t pixels() const { return size_t(width_) * height_; }
  bool has_variance() const { return !sum_sq_.empty(); }
  double scale() const { return scale_; }
  size_t bytes() const;

  // Mean radiance per pixel, RGB interleaved, row 0 at the top.
  std::vector<float> mean() const;
  // Variance of the per-pixel mean (sample variance / n), RGB; empty if not kept.
  std::vector<float> variance_of_mean() const;
  const std::vector<uint32_t>& counts() const { return count_; }
  const std::vector<int64_t>& raw_sums() const { return sum_; }
  std::vector<int64_t>& raw_sums() { return sum_; }
  std::vector<uint32_t>& counts() { return count_; }
  std::vector<double>& raw_sum_sq() { return sum_sq_; }
  const std::vector<double>& raw_sum_sq() const { return sum_sq_; }

 private:
  uint32_t width_ = 0, height_ = 0;
  double scale_ = 1;
  double limit_ = kMaxSum / 4;  // kMaxSum / 4 / scale_
  std::vector<int64_t> sum_;
  std::vector<uint32_t> count_;
  std::vector<double> sum_sq_;
};

// Host only (std::atomic_ref is C++20; nvcc may compile this header as C++17, and the
// GPU accumulates with atomicAdd of its own).
#if !defined(__CUDACC__)
inline bool Film::add(uint32_t pixel, Vec3f L) {
  if (!sample_acceptable(L, limit_)) return false;
  int64_t* s = &sum_[size_t(pixel) * 3];
  // Unrolled (g++ keeps these three-step loops as loops: ~12 more instructions a sample).
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) s[c] += quantize_radiance(L[c], scale_);
  ++count_[pixel];
  if (!sum_sq_.empty())
    for (int c = 0; c < 3; ++c) sum_sq_[size_t(pixel) * 3 + c] += double(L[c]) * double(L[c]);
  return true;
}

inline bool Film::add_atomic(uint32_t pixel, Vec3f L) {
  if (!sample_acceptable(L, limit_)) return false;
  int64_t* s = &sum_[size_t(pixel) * 3];
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c)
    std::atomic_ref<int64_t>(s[c]).fetch_add(quantize_radiance(L[c], scale_), std::memory_order_relaxed);
  std::atomic_ref<uint32_t>(count_[pixel]).fetch_add(1, std::memory_order_relaxed);
  if (!sum_sq_.empty())
    for (int c = 0; c < 3; ++c)
      std::atomic_ref<double>(sum_sq_[size_t(pixel) * 3 + c]).fetch_add(double(L[c]) * double(L[c]),
                                                                        std::memory_order_relaxed);
  return true;
}
#endif

}  // namespace pb
