#pragma once
// A GPU render that must refuse its settings (an environment variable's value): an InputError
// naming the variable, for the GPU test files that check such refusals.
#include <gtest/gtest.h>

#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/common/film.h"
#include "pathbench/gpu/render.h"

namespace pb::test {

inline void expect_refused_naming(const Scene& scene, const gpu::GpuScene& gs, const RenderSettings& s,
                                  const char* variable) {
  Film f(s.width, s.height, false);
  RunReport r;
  f.begin(s.spp, scene.max_emission());
  try {
    gpu::render(scene, gs, s, f, r, false);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(variable), std::string::npos) << e.what();
  }
}

}  // namespace pb::test
