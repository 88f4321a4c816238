#include "pathbench/common/film.h"

#include "pathbench/common/settings.h"

#include <atomic>
#include <cmath>

namespace pb {

Film::Film(uint32_t width, uint32_t height, bool variance) : width_(width), height_(height) {
  if (width && height) check_image_size(width, height, variance);  // an impossible size is bad input, not bad_alloc
  sum_.assign(pixels() * 3, 0);
  count_.assign(pixels(), 0);
  if (variance) sum_sq_.assign(pixels() * 3, 0.0);
}

double Film::choose_scale(uint64_t spp, float max_emission) {
  // A sample is expected to stay under 1024 x the brightest emission (MIS keeps
  // light-sampled values bounded); the sum of spp of them must stay under 2^62.
  double bound = 1024.0 * (max_emission > 0 ? double(max_emission) : 1.0) * double(spp ? spp : 1);
  return std::exp2(std::floor(std::log2(kMaxSum / bound)));
}

void Film::begin(uint64_t spp, float max_emission) {
  scale_ = choose_scale(spp, max_emission);
  limit_ = kMaxSum / 4 / scale_;
  std::fill(sum_.begin(), sum_.end(), 0);
  std::fill(count_.begin(), count_.end(), 0);
  std::fill(sum_sq_.begin(), sum_sq_.end(), 0.0);
}

size_t Film::bytes() const {
  return sum_.size() * sizeof(int64_t) + count_.size() * sizeof(uint32_t) + sum_sq_.size() * sizeof(double);
}

std::vector<float> Film::mean() const {
  std::vector<float> out(pixels() * 3);
  for (size_t p = 0; p < pixels(); ++p) {
    const double n = count_[p];
    for (int c = 0; c < 3; ++c) out[p * 3 + c] = n > 0 ? float(double(sum_[p * 3 + c]) / scale_ / n) : 0.0f;
  }
  return out;
}

std::vector<float> Film::variance_of_mean() const {
  if (sum_sq_.empty()) return {};
  std::vector<float> out(pixels() * 3);
  for (size_t p = 0; p < pixels(); ++p) {
    const double n = count_[p];
    for (int c = 0; c < 3; ++c) {
      if (n < 2) { out[p * 3 + c] = 0; continue; }
      const double mean = double(sum_[p * 3 + c]) / scale_ / n;
      const double var = (sum_sq_[p * 3 + c] / n - mean * mean) * n / (n - 1);  // unbiased sample variance
      out[p * 3 + c] = float(std::max(var, 0.0) / n);
    }
  }
  return out;
}

}  // namespace pb
