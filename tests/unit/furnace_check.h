#pragma once
// What furnace-style tests compare: a film's mean over all pixel-channels with the
// standard error of that mean, and the white furnace's closed form. Shared by
// test_furnace, test_materials_render, test_stability and test_precision.
#include <cmath>

#include "pathbench/common/film.h"

namespace pb {

struct ImageMean {
  double mean = 0, sigma = 0;  // over all pixel-channels; sigma of that mean (pixels independent)
};

inline ImageMean image_mean(const Film& film) {
  const auto mean = film.mean();
  const auto var = film.variance_of_mean();  // empty without variance: sigma stays 0
  double sum = 0, var_sum = 0;
  for (size_t i = 0; i < mean.size(); ++i) sum += mean[i];
  for (float v : var) var_sum += v;
  const double n = double(mean.size());
  return {sum / n, std::sqrt(var_sum) / n};
}

// Radiance in a closed box whose walls all have albedo a and emission Le:
// Le (1 + a + ... + a^k) after k bounces, Le / (1 - a) unbounded (bounces < 0).
inline double furnace_radiance(double a, double Le, int bounces) {
  if (bounces < 0) return Le / (1 - a);
  double e = 0;
  for (int i = 0; i <= bounces; ++i) e += Le * std::pow(a, i);
  return e;
}

}  // namespace pb
