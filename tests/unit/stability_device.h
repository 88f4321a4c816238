#pragma once
// The device the stability suites render on: one source, two devices. Built into the
// CPU unit tests, and with PB_STABILITY_ON_GPU into tests/gpu's
// pathbench_gpu_stability_tests (label gpu), where every render runs both GPU
// strategies, checks their films are identical, and every test reports SKIPPED
// without a GPU. Shared by test_stability.cpp and test_far_from_origin.cpp.
#include <gtest/gtest.h>

#include <string>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/run.h"
#ifdef PB_STABILITY_ON_GPU
#include "pathbench/gpu/render.h"
#endif

namespace pb {

// At the top of every test: on the GPU build, SKIPPED (with the reason) without a GPU.
#ifdef PB_STABILITY_ON_GPU
#define PB_REQUIRE_DEVICE()                                    \
  do {                                                         \
    std::string why;                                           \
    if (!gpu::device_available(&why)) GTEST_SKIP() << "no GPU: " << why; \
  } while (0)
#else
#define PB_REQUIRE_DEVICE() \
  do {                      \
  } while (0)
#endif

#ifdef PB_STABILITY_ON_GPU
constexpr Device kStabilityDevice = Device::Gpu;
#else
constexpr Device kStabilityDevice = Device::Cpu;
#endif

struct Rendered {
  Film film;
  RunReport report;
};

inline Rendered render(const Scene& scene, RenderSettings s) {
  s.progress = false;
  s.device = kStabilityDevice;
  Rendered r{Film(s.width, s.height, s.variance), {}};
#ifdef PB_STABILITY_ON_GPU
  s.strategy = Strategy::Pixel;
  run::render(scene, s, r.film, r.report);
  // The wavefront must agree bit for bit, extremes included (it has queues to overflow
  // and counters to wrap that the megakernel has not).
  RenderSettings w = s;
  w.strategy = Strategy::Wavefront;
  Film wf(s.width, s.height, s.variance);
  RunReport wr;
  run::render(scene, w, wf, wr);
  EXPECT_TRUE(wf.raw_sums() == r.film.raw_sums()) << "GPU wavefront film differs from pixel's";
  EXPECT_TRUE(wf.counts() == r.film.counts()) << "GPU wavefront sample counts differ from pixel's";
  EXPECT_EQ(wr.discarded_samples, r.report.discarded_samples);
#else
  run::render(scene, s, r.film, r.report);
#endif
  return r;
}

// A square image with light sampling: the settings every test here starts from.
inline RenderSettings nee_settings(uint32_t size, uint32_t spp, int bounces) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.max_bounces = bounces;
  s.sampling = Sampling::Nee;
  s.device = kStabilityDevice;
  return s;
}

}  // namespace pb
