// The CPU wavefront's batched (AVX2) shading and final-vertex screen, cpu/src/shade_x8.h,
// against the scalar path step they stand in for: the same image bit for bit on scenes
// beyond the paper's box (many triangles, several emitters, an icosphere), and a screen
// that never drops a ray the scalar watertight test says hits an emitter, including rays
// aimed exactly at the emitters' vertices and edges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "pathbench/common/path.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/run/run.h"

#pragma GCC push_options
#pragma GCC target("avx2")
#define PB_SIMD_NS avx2
#include "../../cpu/src/shade_x8.h"
#undef PB_SIMD_NS
namespace {
// Eight lanes of sincos_turns; vectors stay inside AVX2 code (passing them by value
// between AVX2 and baseline functions would not agree on the calling convention).
void sincos_turns_x8(const float* u, float* s, float* c) {
  pb::cpu::avx2::F8 u8, s8, c8;
  std::memcpy(&u8, u, sizeof u8);
  pb::cpu::avx2::sincos_turns(u8, s8, c8);
  std::memcpy(s, &s8, sizeof s8);
  std::memcpy(c, &c8, sizeof c8);
}
}  // namespace
#pragma GCC pop_options

namespace pb {
namespace {

Film render(const Scene& scene, Strategy strategy, int threads, Sampling sampling, int bounces) {
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 8;
  s.sampling = sampling;
  s.max_bounces = bounces;
  s.russian_roulette = bounces < 0;
  s.strategy = strategy;
  s.threads = threads;
  s.seed = 7;
  s.progress = false;
  Film film(s.width, s.height, false);
  RunReport report;
  run::render(scene, s, film, report);
  return film;
}

TEST(WavefrontBatch, SameImageAsPixelOnOtherScenes) {
  // cornell-box: 38 triangles; ico:2: 332; furnace: every surface both emits and reflects.
  for (const char* name : {"cornell-box", "paper-cornell-ico:2", "furnace"}) {
    const Scene scene = std::string(name) == "furnace" ? make_furnace(0.5f, 1.0f) : load_scene(name);
    for (auto [sampling, bounces] : {std::pair{Sampling::Nee, 2}, std::pair{Sampling::Uniform, 3},
                                     std::pair{Sampling::Nee, -1}}) {
      SCOPED_TRACE(std::string(name) + ", " + to_string(sampling) + ", bounces " + std::to_string(bounces));
      const Film pixel = render(scene, Strategy::Pixel, 1, sampling, bounces);
      const Film wavefront = render(scene, Strategy::Wavefront, 2, sampling, bounces);
      EXPECT_TRUE(pixel.raw_sums() == wavefront.raw_sums());
      EXPECT_TRUE(pixel.counts() == wavefront.counts());
    }
  }
}

// The scalar answer: does path_final_query's loop find an emitter along the ray?
bool scalar_finds_emitter(const SceneView& s, const Ray<float>& ray) {
  const WatertightRay wr = make_watertight_ray(ray.o, ray.d);
  for (uint32_t k = 0; k < s.num_emitters; ++k) {
    const Triangle t = s.triangles[s.emitters[k]];
    float th;
    if (intersect_watertight(wr, s.positions[t.v[0]], s.positions[t.v[1]], s.positions[t.v[2]], 3.402823466e38f, th))
      return true;
  }
  return false;
}

TEST(WavefrontBatch, FinalVertexScreenKeepsEveryHit) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2: the wavefront shades one path at a time";
  const Scene scene = make_cornell_box();
  const SceneView s = scene.view();
  ASSERT_GT(s.num_emitters, 0u);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Vec3f lo = scene.bounds_min, hi = scene.bounds_max;
  auto inside = [&] {
    return Vec3f{lo.x + (hi.x - lo.x) * (0.5f + 0.49f * u(rng)), lo.y + (hi.y - lo.y) * (0.5f + 0.49f * u(rng)),
                 lo.z + (hi.z - lo.z) * (0.5f + 0.49f * u(rng))};
  };
  std::vector<PathState<float>> states(8);
  PathState<float>* lanes[8];
  for (int i = 0; i < 8; ++i) lanes[i] = &states[i];
  size_t hits = 0, screened_out = 0;
  for (int round = 0; round < 4000; ++round) {
    for (int i = 0; i < 8; ++i) {
      const Vec3f o = inside();
      Vec3f d{u(rng), u(rng), u(rng)};
      // Every other ray aims exactly at an emitter vertex or an edge midpoint.
      if ((round + i) % 2 == 0) {
        const Triangle t = s.triangles[s.emitters[rng() % s.num_emitters]];
        const Vec3f a = s.positions[t.v[rng() % 3]], b = s.positions[t.v[rng() % 3]];
        d = (a + b) * 0.5f - o;
      }
      states[i].ray = {o, d};
    }
    bool candidate[8];
    cpu::avx2::final_vertex_candidates_x8(s, lanes, candidate);
    for (int i = 0; i < 8; ++i) {
      const bool hit = scalar_finds_emitter(s, states[i].ray);
      hits += hit;
      screened_out += !candidate[i];
      if (hit) ASSERT_TRUE(candidate[i]) << "round " << round << " lane " << i;
    }
  }
  EXPECT_GT(hits, 1000u);               // the aimed rays do hit
  EXPECT_GT(screened_out, 4000u * 2);   // and the screen does drop most of the others
}

// sincos_turns<float> (sampling.h) over every float turn fraction the random stream can
// give (k / 2^24): within 3e-7 of sin and cos of 2 pi u, and the AVX2 lanes give the
// same bits as the scalar function.
TEST(WavefrontBatch, SinCosOfTurns) {
  double worst = 0;
  for (uint32_t k = 0; k < (1u << 24); k += 7) {
    const float u = float(k) * (1.0f / 16777216.0f);
    float s, c;
    sincos_turns(u, s, c);
    const double phi = 2.0 * 3.14159265358979323846 * double(u);
    worst = std::max({worst, std::fabs(double(s) - std::sin(phi)), std::fabs(double(c) - std::cos(phi))});
  }
  EXPECT_LT(worst, 3e-7);
  if (!__builtin_cpu_supports("avx2")) return;
  float u[8], s8[8], c8[8];
  for (uint32_t k = 0; k < (1u << 24); k += 8 * 11) {
    for (int i = 0; i < 8; ++i) u[i] = float(k + uint32_t(i)) * (1.0f / 16777216.0f);
    sincos_turns_x8(u, s8, c8);
    for (int i = 0; i < 8; ++i) {
      float s, c;
      sincos_turns(u[i], s, c);
      ASSERT_EQ(s, s8[i]) << u[i];
      ASSERT_EQ(c, c8[i]) << u[i];
    }
  }
}

}  // namespace
}  // namespace pb
