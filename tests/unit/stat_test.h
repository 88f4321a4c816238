#pragma once
// Statistics for the tests: chi-square goodness of fit (as Mitsuba 3's and pbrt's
// sampler tests do it), p-values from the regularized incomplete gamma function,
// Sidak-corrected significance levels, 2D Simpson integration of densities, and the
// per-pixel z-test of an image against a reference with a variance image.
// Header-only, used by test_sampling.cpp and test_statistical_render.cpp.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace pb::stat {

// Regularized incomplete gamma functions (Numerical Recipes 6.2): the series for
// P(a, x) where x < a + 1, Lentz's continued fraction for Q(a, x) elsewhere, so
// neither loses digits to cancellation. Accurate to ~1e-14 relative.
inline double gamma_p_series(double a, double x) {
  double ap = a, sum = 1.0 / a, del = sum;
  for (int n = 0; n < 100000; ++n) {
    ap += 1;
    del *= x / ap;
    sum += del;
    if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
  }
  return std::min(1.0, sum * std::exp(-x + a * std::log(x) - std::lgamma(a)));
}

inline double gamma_q_continued_fraction(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Lower P(a, x) and upper Q(a, x) = 1 - P(a, x).
inline double regularized_gamma_p(double a, double x) {
  if (x <= 0) return 0.0;
  return x < a + 1 ? gamma_p_series(a, x) : 1.0 - gamma_q_continued_fraction(a, x);
}
inline double regularized_gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  return x < a + 1 ? 1.0 - gamma_p_series(a, x) : gamma_q_continued_fraction(a, x);
}

// P(X >= chi2) for X ~ chi-square with `dof` degrees of freedom.
inline double chi2_pvalue(double chi2, int dof) { return regularized_gamma_q(0.5 * dof, 0.5 * chi2); }

// Per-test significance level so that `tests` independent tests together reject a
// correct implementation with probability `alpha` (Sidak).
inline double sidak_alpha(double alpha, double tests) { return 1.0 - std::pow(1.0 - alpha, 1.0 / tests); }

// Two-sided p-value of a standard normal z.
inline double normal_two_sided_p(double z) { return std::erfc(std::fabs(z) / std::sqrt(2.0)); }

struct ChiSquare {
  double chi2 = 0;
  int dof = 0;
  double p = 0;
  int pooled_bins = 0;  // bins with expected count below the minimum, merged into one
  bool impossible = false;  // samples fell where the density is zero
  std::string message;
  bool passes(double alpha) const { return !impossible && dof > 0 && p >= alpha; }
};

// Pearson's chi-square of `observed` counts against `expected` counts. Bins whose
// expected count is below `min_expected` are pooled into one bin (and that pooled bin
// joins the test only if its expectation reaches the minimum too), as in Mitsuba 3's
// ChiSquareTest. A sample in a bin of zero expectation makes the test fail outright.
inline ChiSquare chi_square(const std::vector<double>& observed, const std::vector<double>& expected,
                            double min_expected = 5.0) {
  ChiSquare r;
  std::ostringstream msg;
  double pooled_obs = 0, pooled_exp = 0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] <= 0) {  // outside the support: must stay empty
      if (observed[i] > 0) {
        r.impossible = true;
        msg << "bin " << i << ": " << observed[i] << " samples where the density is zero; ";
      }
      continue;
    }
    if (expected[i] < min_expected) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      ++r.pooled_bins;
      continue;
    }
    const double d = observed[i] - expected[i];
    r.chi2 += d * d / expected[i];
    ++bins;
  }
  if (pooled_exp >= min_expected) {
    const double d = pooled_obs - pooled_exp;
    r.chi2 += d * d / pooled_exp;
    ++bins;
  }  // else: the pooled mass is below min_expected samples, too little to test: left out
  r.dof = bins - 1;
  r.p = r.dof > 0 ? chi2_pvalue(r.chi2, r.dof) : 0.0;
  msg << "chi2 " << r.chi2 << ", dof " << r.dof << ", p " << r.p << ", pooled bins " << r.pooled_bins;
  r.message = msg.str();
  return r;
}

// Composite Simpson's rule on [x0, x1] x [y0, y1] with n (even) intervals per axis.
template <class F> double simpson_2d(F&& f, double x0, double x1, double y0, double y1, int n = 16) {
  const double hx = (x1 - x0) / n, hy = (y1 - y0) / n;
  auto w = [n](int i) { return (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0); };
  double sum = 0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) sum += w(i) * w(j) * f(x0 + i * hx, y0 + j * hy);
  return sum * hx * hy / 9.0;
}

// ---- Image against a reference -----------------------------------------------------

struct ImageTest {
  size_t values = 0;          // pixel-channels compared
  size_t passed = 0;
  size_t zero_variance = 0;   // compared exactly (both variances ~0)
  size_t zero_variance_failed = 0;
  double alpha = 0;           // per-value (Sidak-corrected) significance level
  double min_p = 1;
  // Failures where our own sample variance is far below what the reference's
  // per-sample variance predicts for our sample count: a rare, bright contribution
  // (e.g. a sliver of the light in the pixel) that our few samples missed, so both
  // our mean and our variance estimate are low. Reported to explain such failures.
  size_t failed_undersampled = 0;
  double mean_ours[3] = {0, 0, 0};
  double mean_ref[3] = {0, 0, 0};
  double share_passed() const { return values ? double(passed) / double(values) : 0.0; }
  double mean_ratio(int c) const { return mean_ref[c] != 0 ? mean_ours[c] / mean_ref[c] : 0.0; }
  std::string summary() const {
    std::ostringstream s;
    s << passed << " of " << values << " pixel-channels pass (" << 100.0 * share_passed()
      << " %) at Sidak-corrected alpha " << alpha << "; smallest p " << min_p << "; " << zero_variance
      << " zero-variance values (" << zero_variance_failed << " differ); " << failed_undersampled
      << " failures look under-sampled (our variance < 1/4 of the reference's, scaled to our spp); mean ratio R " << mean_ratio(0) << " G "
      << mean_ratio(1) << " B " << mean_ratio(2);
    return s.str();
  }
};

// Per pixel-channel z = (ours - ref) / sqrt(var_ours + var_ref), two-sided p, compared
// with the Sidak-corrected level for `family_alpha` over all values. Where both
// variances are (almost) zero -- a directly seen emitter, the same constant in every
// sample -- the values must agree within `exact_tol` relative instead. Images are RGB
// interleaved, variances are variances of the per-pixel mean. `ref_over_ours_spp`
// (reference samples / ours), when given, only sorts failures for the report.
inline ImageTest compare_images(const std::vector<float>& ours, const std::vector<float>& var_ours,
                                const std::vector<float>& ref, const std::vector<float>& var_ref,
                                double family_alpha = 0.01, double exact_tol = 1e-4,
                                double ref_over_ours_spp = 0) {
  ImageTest r;
  r.values = ours.size();
  r.alpha = sidak_alpha(family_alpha, double(r.values));
  double sum_o[3] = {0, 0, 0}, sum_r[3] = {0, 0, 0};
  for (size_t i = 0; i < ours.size(); ++i) {
    const double o = ours[i], f = ref[i];
    sum_o[i % 3] += o;
    sum_r[i % 3] += f;
    const double v = double(var_ours[i]) + double(var_ref[i]);
    const double scale = std::max({std::fabs(o), std::fabs(f), 1e-3});
    // Variances below float rounding of the mean itself count as zero.
    if (!(v > (1e-6 * scale) * (1e-6 * scale))) {
      ++r.zero_variance;
      if (std::fabs(o - f) <= exact_tol * scale) ++r.passed;
      else ++r.zero_variance_failed;
      continue;
    }
    const double p = normal_two_sided_p((o - f) / std::sqrt(v));
    r.min_p = std::min(r.min_p, p);
    if (std::isfinite(o) && p >= r.alpha) ++r.passed;
    else if (ref_over_ours_spp > 0 && var_ours[i] < 0.25 * var_ref[i] * ref_over_ours_spp) ++r.failed_undersampled;
  }
  const double n = double(ours.size() / 3);
  for (int c = 0; c < 3; ++c) {
    r.mean_ours[c] = sum_o[c] / n;
    r.mean_ref[c] = sum_r[c] / n;
  }
  return r;
}

}  // namespace pb::stat
