#pragma once
// One random stream for every tracer: counter-based Philox4x32-10 (Random123).
// Key = (pixel, seed low word); counter = (sample, bounce, dimension group, seed high
// word). A number depends only on those, never on the thread, the strategy or the
// device, so pixel-parallel and ray-parallel renders draw identical numbers.
#include <Random123/philox.h>

#include <cstdint>

#include "pathbench/common/hd.h"

namespace pb {

// Dimension groups; each draw yields four uniforms. One draw per path vertex covers
// the common case (a Philox call is the largest single cost of a vertex).
enum RngGroup : uint32_t {
  kRngCamera = 0,     // u0,u1: pixel jitter
  kRngVertex = 1,     // u0,u1: BSDF direction; u2: emitter choice, reused for the point; u3: point
  kRngRoulette = 2,   // u0: Russian roulette (drawn only when roulette applies)
};

struct Uniform4 {
  float v[4];
};

// 24 random bits -> float in [0, 1), never 1.
PB_HD float u32_to_unit_float(uint32_t x) { return float(x >> 8) * (1.0f / 16777216.0f); }

struct RngStream {
  uint32_t pixel;
  uint64_t seed;

  PB_HD Uniform4 draw(uint32_t sample, uint32_t bounce, uint32_t group) const {
    r123::Philox4x32 philox;
    r123::Philox4x32::ctr_type ctr = {{sample, bounce, group, uint32_t(seed >> 32)}};
    r123::Philox4x32::key_type key = {{pixel, uint32_t(seed)}};
    r123::Philox4x32::ctr_type r = philox(ctr, key);
    return {{u32_to_unit_float(r.v[0]), u32_to_unit_float(r.v[1]), u32_to_unit_float(r.v[2]),
             u32_to_unit_float(r.v[3])}};
  }
};

}  // namespace pb
