#pragma once
// PB_REQUIRE_GPU(): skips the calling test (GTEST_SKIP, which CTest reports as SKIPPED) on a host
// without a usable CUDA device, naming why; shared by the GPU tracer's test files.
#include <gtest/gtest.h>

#include <string>

#include "pathbench/gpu/render.h"

#define PB_REQUIRE_GPU()                                                        \
  do {                                                                          \
    std::string pb_why_no_gpu;                                                  \
    if (!::pb::gpu::device_available(&pb_why_no_gpu)) GTEST_SKIP() << "no GPU: " << pb_why_no_gpu; \
  } while (0)
