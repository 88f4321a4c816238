#pragma once
// Error of a rendered image against a converged reference, for `pathbench accuracy`.
// Images are RGB float, interleaved, the same size; variances are per pixel-channel
// variances of the mean (Film::variance_of_mean). Throws std::invalid_argument when
// sizes do not match.
#include <vector>

namespace pb::analysis {

// Relative MSE's epsilon: (x - ref)^2 / (ref^2 + eps) per pixel-channel. 0.01 keeps
// black pixels from dominating (as in Rousselle et al. 2011 and most denoising papers).
inline constexpr double kRelMseEpsilon = 1e-2;

struct ImageError {
  double rmse = 0;     // sqrt of the mean over pixel-channels of (x - ref)^2
  double rel_mse = 0;  // mean over pixel-channels of (x - ref)^2 / (ref^2 + eps)
};
ImageError image_error(const std::vector<float>& x, const std::vector<float>& ref, double eps = kRelMseEpsilon);

// What the reference's own noise adds to the expected relative MSE of any image
// against it: the mean of ref_var / (ref^2 + eps). Errors near this floor are not
// resolved by the reference.
double rel_mse_floor(const std::vector<float>& ref, const std::vector<float>& ref_var, double eps = kRelMseEpsilon);

// Bias of an image against the reference: the relative difference of the image means
// (over all pixel-channels), (mean(x) - mean(ref)) / mean(ref), with its standard
// error from both variance images. Pixels are independent (one random stream per
// pixel), but the three channels of a pixel come from the same paths: their
// covariance is unknown, so the standard error takes them as fully correlated (an
// upper bound). An empty variance image counts as zero variance.
struct Bias {
  double relative = 0;
  double std_error = 0;
  // relative / std_error; 0 when both are 0, +-infinity when only std_error is.
  double z() const;
};
Bias relative_bias(const std::vector<float>& x, const std::vector<float>& x_var, const std::vector<float>& ref,
                   const std::vector<float>& ref_var);

// More than this many standard errors from zero: a bias, not noise.
inline constexpr double kBiasZThreshold = 4.0;

// 1 / (relMSE x seconds): work-normalised accuracy; higher is better.
double efficiency(double rel_mse, double seconds);

}  // namespace pb::analysis
