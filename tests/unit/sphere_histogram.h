#pragma once
// Histogram of unit directions over the sphere in (cos theta, phi) about +z, with the
// expected counts of a density integrated over each bin: the direction samplers' and
// the BSDFs' chi-square tests (test_sampling.cpp, test_materials_bsdf.cpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "pathbench/common/math.h"
#include "stat_test.h"

namespace pb::stat {

// Histogram of directions over the whole sphere, binned in (cos theta, phi) about +z.
struct SphereHistogram {
  int n_cos, n_phi;
  std::vector<double> counts;
  SphereHistogram(int nc, int np) : n_cos(nc), n_phi(np), counts(size_t(nc) * np, 0.0) {}
  void add(Vec3d w) {
    const double c = std::clamp(w.z, -1.0, 1.0);
    double phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi<double>;
    const int i = std::min(n_cos - 1, int((c + 1) * 0.5 * n_cos));
    const int j = std::min(n_phi - 1, int(phi / (2 * kPi<double>) * n_phi));
    counts[size_t(i) * n_phi + j] += 1;
  }
  // Expected counts for `n` samples of a density pdf(cos theta, phi) (per steradian;
  // d omega = d cos d phi). Bins where `support(c0, c1)` is false get zero.
  template <class Pdf, class Support>
  std::vector<double> expected(Pdf&& pdf, Support&& support, double n, int simpson_n = 16) const {
    std::vector<double> e(counts.size());
    for (int i = 0; i < n_cos; ++i) {
      const double c0 = -1 + 2.0 * i / n_cos, c1 = -1 + 2.0 * (i + 1) / n_cos;
      for (int j = 0; j < n_phi; ++j) {
        const double p0 = 2 * kPi<double> * j / n_phi, p1 = 2 * kPi<double> * (j + 1) / n_phi;
        e[size_t(i) * n_phi + j] = support(c0, c1) ? n * stat::simpson_2d(pdf, c0, c1, p0, p1, simpson_n) : 0.0;
      }
    }
    return e;
  }
};

}  // namespace pb::stat
