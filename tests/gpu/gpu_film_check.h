#pragma once
// What the GPU tests (label gpu) share: the skip without a device, small render settings,
// a render to a film, and the two verdicts on films (bit for bit) and on refused settings.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/common/film.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/gpu/render.h"

namespace pb::gpu {

#define PB_REQUIRE_GPU()                                        \
  do {                                                          \
    std::string why;                                            \
    if (!device_available(&why)) GTEST_SKIP() << "no GPU: " << why; \
  } while (0)

inline RenderSettings small_settings(Strategy strategy, uint32_t size = 64, uint32_t spp = 32) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.max_bounces = 2;
  s.sampling = Sampling::Nee;
  s.strategy = strategy;
  s.device = Device::Gpu;
  s.seed = 1234;
  s.progress = false;
  return s;
}

inline Film render_gpu(const Scene& scene, const GpuScene& gs, RenderSettings s, RunReport* out = nullptr) {
  Film film(s.width, s.height, s.variance);
  RunReport r;
  film.begin(s.spp, scene.max_emission());  // as the run layer does before it calls the tracer
  render(scene, gs, s, film, r, false);
  EXPECT_EQ(r.paths, s.total_samples());
  EXPECT_EQ(r.discarded_samples, 0u);
  if (out) *out = r;
  return film;
}

// The render refuses the settings (an environment variable's value) with an InputError
// naming `variable`.
inline void expect_refused_naming(const Scene& scene, const GpuScene& gs, const RenderSettings& s, const char* variable) {
  Film f(s.width, s.height, false);
  RunReport r;
  f.begin(s.spp, scene.max_emission());
  try {
    render(scene, gs, s, f, r, false);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(variable), std::string::npos) << e.what();
  }
}

inline void expect_identical(const Film& a, const Film& b, const char* what) {
  ASSERT_EQ(a.raw_sums().size(), b.raw_sums().size());
  size_t differ = 0;
  for (size_t i = 0; i < a.raw_sums().size(); ++i) differ += a.raw_sums()[i] != b.raw_sums()[i];
  EXPECT_EQ(differ, 0u) << what << ": film sums differ in " << differ << " values";
  EXPECT_EQ(a.counts(), b.counts()) << what;
}

}  // namespace pb::gpu
