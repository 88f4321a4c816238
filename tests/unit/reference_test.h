#pragma once
// Renders compared with an independent (Mitsuba 3) reference, Mitsuba-style: the
// reference images and their metadata under tests/data, a CPU render with its variance
// image, and the per-pixel test of stat_test.h. Shared by test_statistical_render.cpp
// (paper-cornell) and test_materials_reference.cpp (cornell-box variants).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathbench/output/image_io.h"
#include "pathbench/run/run.h"
#include "stat_test.h"

namespace pb::reftest {

inline std::string data_path(const std::string& name) {
  return std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/" + name;
}

// A mean image, the variance of that mean, and the samples per pixel behind it.
struct Image {
  std::vector<float> mean, var;
  double spp = 0;      // the reference's from its .json ("spp_total"; 0: unknown)
  double seconds = 0;  // render time (our renders only)
};

// tests/data/<stem>.pfm, <stem>-var.pfm and <stem>.json; both images size x size.
inline Image load_reference(const std::string& stem, uint32_t size) {
  Image r;
  unsigned w = 0, h = 0, wv = 0, hv = 0;
  r.mean = read_image(data_path(stem + ".pfm"), w, h);
  r.var = read_image(data_path(stem + "-var.pfm"), wv, hv);
  if (w != size || h != size || wv != size || hv != size)
    throw std::runtime_error(stem + ": reference images are not " + std::to_string(size) + " x " +
                             std::to_string(size));
  std::ifstream meta(data_path(stem + ".json"));
  const std::string text((std::istreambuf_iterator<char>(meta)), std::istreambuf_iterator<char>());
  if (const auto pos = text.find("\"spp_total\":"); pos != std::string::npos) r.spp = std::atof(text.c_str() + pos + 12);
  return r;
}

// The reference at half its resolution: each pixel the mean of a 2 x 2 block (the box
// pixel filter makes that exactly the half-size image's pixel), its variance the sum of
// the four variances / 16. Lets fast tests render at 128 x 128 against a 256 x 256 one.
inline Image half_resolution(const Image& full, uint32_t full_size) {
  const uint32_t half = full_size / 2;
  Image r;
  r.spp = full.spp * 4;  // samples behind each half-size pixel
  r.mean.assign(size_t(half) * half * 3, 0.0f);
  r.var.assign(r.mean.size(), 0.0f);
  for (uint32_t y = 0; y < half; ++y)
    for (uint32_t x = 0; x < half; ++x)
      for (int c = 0; c < 3; ++c) {
        double m = 0, v = 0;
        for (uint32_t k = 0; k < 4; ++k) {
          const size_t i = ((size_t(2 * y + k / 2) * full_size) + 2 * x + k % 2) * 3 + c;
          m += full.mean[i];
          v += full.var[i];
        }
        const size_t o = (size_t(y) * half + x) * 3 + c;
        r.mean[o] = float(m / 4);
        r.var[o] = float(v / 16);
      }
  return r;
}

// A CPU render of `s` (variance on, no progress bar) that must discard no sample.
inline Image render_with_variance(const Scene& scene, RenderSettings s) {
  s.variance = true;
  s.progress = false;
  Film film(s.width, s.height, true);
  RunReport report;
  run::render(scene, s, film, report);
  EXPECT_EQ(report.discarded_samples, 0u);
  return {film.mean(), film.variance_of_mean(), double(s.spp), report.seconds};
}

// Per-pixel z-test at alpha 0.01, Sidak-corrected; the reference's variance scaled to
// our sample count.
inline stat::ImageTest compare(const Image& ours, const Image& ref) {
  return stat::compare_images(ours.mean, ours.var, ref.mean, ref.var, 0.01, 1e-4, ref.spp / ours.spp);
}

// The acceptance rule: enough pixel-channels pass and every channel's image mean is close.
inline bool accepts(const stat::ImageTest& t, double min_share, double max_mean_error) {
  bool means_ok = true;
  for (int c = 0; c < 3; ++c) means_ok &= std::fabs(t.mean_ratio(c) - 1) <= max_mean_error;
  return t.share_passed() >= min_share && means_ok;
}

}  // namespace pb::reftest
