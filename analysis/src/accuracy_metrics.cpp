#include "pathbench/analysis/accuracy_metrics.h"

#include <fmt/core.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace pb::analysis {

namespace {
void check_sizes(const std::vector<float>& a, const std::vector<float>& ref, const char* what) {
  if (a.size() != ref.size() || ref.empty() || ref.size() % 3 != 0)
    throw std::invalid_argument(fmt::format("{}: {} values against a reference of {} (RGB, same size, not empty)", what,
                                            a.size(), ref.size()));
}
}  // namespace

ImageError image_error(const std::vector<float>& x, const std::vector<float>& ref, double eps) {
  check_sizes(x, ref, "image");
  double se = 0, rel = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    const double d = double(x[i]) - double(ref[i]);
    se += d * d;
    rel += d * d / (double(ref[i]) * double(ref[i]) + eps);
  }
  const double n = double(ref.size());
  return {std::sqrt(se / n), rel / n};
}

double rel_mse_floor(const std::vector<float>& ref, const std::vector<float>& ref_var, double eps) {
  check_sizes(ref_var, ref, "reference variance");
  double sum = 0;
  for (size_t i = 0; i < ref.size(); ++i) sum += double(ref_var[i]) / (double(ref[i]) * double(ref[i]) + eps);
  return sum / double(ref.size());
}

namespace {
// Sum and an upper bound of the variance of the sum of all pixel-channels: per pixel
// the channels are taken as fully correlated, Var(r + g + b) <= (sd_r + sd_g + sd_b)^2.
struct SumAndVariance {
  double sum = 0, var = 0;
};
SumAndVariance sum_and_variance(const std::vector<float>& img, const std::vector<float>& var) {
  SumAndVariance s;
  for (size_t p = 0; p < img.size(); p += 3) {
    double sd = 0;
    for (int c = 0; c < 3; ++c) {
      s.sum += img[p + c];
      if (!var.empty()) sd += std::sqrt(std::max(0.0, double(var[p + c])));
    }
    s.var += sd * sd;
  }
  return s;
}
}  // namespace

Bias relative_bias(const std::vector<float>& x, const std::vector<float>& x_var, const std::vector<float>& ref,
                   const std::vector<float>& ref_var) {
  check_sizes(x, ref, "image");
  if (!x_var.empty()) check_sizes(x_var, ref, "image variance");
  if (!ref_var.empty()) check_sizes(ref_var, ref, "reference variance");
  const SumAndVariance a = sum_and_variance(x, x_var), r = sum_and_variance(ref, ref_var);
  if (!(r.sum > 0)) throw std::invalid_argument("reference: the image mean must be positive for a relative bias");
  // Ratio of the sums (the pixel count cancels); its standard error by the delta method.
  const double ratio = a.sum / r.sum;
  Bias b;
  b.relative = ratio - 1.0;
  b.std_error = std::sqrt(a.var + ratio * ratio * r.var) / r.sum;
  return b;
}

double Bias::z() const {
  if (std_error > 0) return relative / std_error;
  if (relative == 0) return 0;
  return std::copysign(std::numeric_limits<double>::infinity(), relative);
}

double efficiency(double rel_mse, double seconds) {
  const double d = rel_mse * seconds;
  return d > 0 ? 1.0 / d : std::numeric_limits<double>::infinity();
}

}  // namespace pb::analysis
