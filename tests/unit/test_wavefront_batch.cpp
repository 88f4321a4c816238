// The CPU's batched shading and final-vertex screen (cpu/src/shade_x8.h, for AVX2 and
// AVX-512 through BatchKernels) against the scalar path step they stand in for: the same
// image bit for bit on scenes beyond the paper's box (many triangles, several emitters,
// an icosphere) with every ISA (--isa) and strategy, and a screen that never drops a ray
// the scalar watertight test says hits an emitter, including rays aimed exactly at the
// emitters' vertices and edges. ISAs this CPU lacks are skipped, saying so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "pathbench/common/errors.h"
#include "pathbench/common/path.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/cpu/isa.h"
#include "pathbench/run/run.h"
#include "shade_batch.h"

namespace pb {
namespace {

Film render(const Scene& scene, Strategy strategy, int threads, Sampling sampling, int bounces, Isa isa = Isa::Auto) {
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 8;
  s.sampling = sampling;
  s.max_bounces = bounces;
  s.russian_roulette = bounces < 0;
  s.strategy = strategy;
  s.threads = threads;
  s.seed = 7;
  s.isa = isa;
  s.progress = false;
  Film film(s.width, s.height, false);
  RunReport report;
  run::render(scene, s, film, report);
  EXPECT_EQ(report.extra["isa"], isa == Isa::Auto ? to_string(cpu::resolve_isa(isa)) : to_string(isa));
  return film;
}

// The vector ISAs, each with its kernels (tests skip where this CPU lacks the ISA).
class BatchIsa : public ::testing::TestWithParam<Isa> {
 protected:
  const cpu::BatchKernels& kernels() const { return *cpu::batch_kernels(GetParam()); }
};
std::string cpu_flags_text() {
  std::string f;
  for (const std::string& x : cpu::cpu_vector_flags()) f += (f.empty() ? "" : " ") + x;
  return f;
}
#define PB_SKIP_WITHOUT_ISA()                                                                         \
  if (!cpu::cpu_supports(GetParam()))                                                                \
  GTEST_SKIP() << "this CPU lacks " << to_string(GetParam()) << " (it has: " << cpu_flags_text() \
               << "); that batched path step cannot run here"

INSTANTIATE_TEST_SUITE_P(Isas, BatchIsa, ::testing::Values(Isa::Avx2, Isa::Avx512),
                         [](const auto& info) { return std::string(to_string(info.param)); });

// cornell-box with every material emitting, each its own brightness: 38 emitters of
// unequal power, more than a register of lanes holds (the kernels' emitter pick then
// reads its CDF lane by lane, not from a register).
Scene glowing_cornell_box() {
  Scene s = make_cornell_box();
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const float e = 0.3f + 0.7f * float(i);
    s.materials[i].emission = {e, 0.5f * e, 0.25f + e};
  }
  s.finalize();
  return s;
}

Scene test_scene(const std::string& name) {
  if (name == "furnace") return make_furnace(0.5f, 1.0f);
  if (name == "glowing-cornell-box") return glowing_cornell_box();
  return load_scene(name);
}

// Every strategy with this ISA against the scalar pixel strategy (the reference path
// step, one path at a time): same sums and counts, bit for bit.
TEST_P(BatchIsa, SameImageAsScalar) {
  PB_SKIP_WITHOUT_ISA();
  for (const char* name : {"paper-cornell", "cornell-box", "paper-cornell-ico:2", "furnace", "glowing-cornell-box"}) {
    const Scene scene = test_scene(name);
    if (std::string(name) == "glowing-cornell-box") ASSERT_GT(scene.emitters.size(), 16u);
    for (auto [sampling, bounces] : {std::pair{Sampling::Nee, 2}, std::pair{Sampling::Uniform, 3},
                                     std::pair{Sampling::Nee, -1}}) {
      SCOPED_TRACE(std::string(name) + ", " + to_string(sampling) + ", bounces " + std::to_string(bounces));
      const Film reference = render(scene, Strategy::Pixel, 1, sampling, bounces, Isa::Scalar);
      for (Strategy strategy : {Strategy::Pixel, Strategy::Wavefront}) {
        SCOPED_TRACE(to_string(strategy));
        const Film f = render(scene, strategy, 2, sampling, bounces, GetParam());
        EXPECT_TRUE(reference.raw_sums() == f.raw_sums());
        EXPECT_TRUE(reference.counts() == f.counts());
      }
    }
  }
}

TEST(Isa, NamesAndRefusals) {
  for (Isa i : {Isa::Auto, Isa::Avx512, Isa::Avx2, Isa::Scalar}) EXPECT_EQ(parse_isa(to_string(i)), i);
  EXPECT_THROW(parse_isa("sse2"), InputError);
  EXPECT_EQ(cpu::resolve_isa(Isa::Scalar), Isa::Scalar);
  const Isa best = cpu::resolve_isa(Isa::Auto);
  EXPECT_NE(best, Isa::Auto);
  EXPECT_TRUE(cpu::cpu_supports(best));
  for (Isa i : {Isa::Avx512, Isa::Avx2}) {
    if (cpu::cpu_supports(i)) EXPECT_EQ(cpu::resolve_isa(i), i);
    else EXPECT_THROW(cpu::resolve_isa(i), InputError);
  }
  EXPECT_EQ(cpu::isa_lanes(Isa::Avx512), 16);
  EXPECT_EQ(cpu::isa_lanes(Isa::Avx2), 8);
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

TEST_P(BatchIsa, FinalVertexScreenKeepsEveryHit) {
  PB_SKIP_WITHOUT_ISA();
  const cpu::BatchKernels& k = kernels();
  const int N = k.lanes;
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
  std::vector<PathState<float>> states(static_cast<size_t>(N));
  PathState<float>* lanes[cpu::kMaxShadeLanes];
  for (int i = 0; i < N; ++i) lanes[i] = &states[size_t(i)];
  size_t hits = 0, screened_out = 0;
  const int rounds = 32000 / N;
  for (int round = 0; round < rounds; ++round) {
    for (int i = 0; i < N; ++i) {
      const Vec3f o = inside();
      Vec3f d{u(rng), u(rng), u(rng)};
      // Every other ray aims exactly at an emitter vertex or an edge midpoint.
      if ((round + i) % 2 == 0) {
        const Triangle t = s.triangles[s.emitters[rng() % s.num_emitters]];
        const Vec3f a = s.positions[t.v[rng() % 3]], b = s.positions[t.v[rng() % 3]];
        d = (a + b) * 0.5f - o;
      }
      states[size_t(i)].ray = {o, d};
    }
    bool candidate[cpu::kMaxShadeLanes];
    k.final_vertex_candidates(s, lanes, candidate);
    for (int i = 0; i < N; ++i) {
      const bool hit = scalar_finds_emitter(s, states[size_t(i)].ray);
      hits += hit;
      screened_out += !candidate[i];
      if (hit) ASSERT_TRUE(candidate[i]) << "round " << round << " lane " << i;
    }
  }
  EXPECT_GT(hits, 1000u);               // the aimed rays do hit
  EXPECT_GT(screened_out, 4000u * 2);   // and the screen does drop most of the others
}

// sincos_turns<float> (sampling.h) over every float turn fraction the random stream can
// give (k / 2^24): within 3e-7 of sin and cos of 2 pi u.
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
}

// The vector lanes of sincos_turns give the scalar function's bits.
TEST_P(BatchIsa, SinCosOfTurnsLanes) {
  PB_SKIP_WITHOUT_ISA();
  const cpu::BatchKernels& k = kernels();
  const uint32_t N = uint32_t(k.lanes);
  float u[cpu::kMaxShadeLanes], sv[cpu::kMaxShadeLanes], cv[cpu::kMaxShadeLanes];
  for (uint32_t base = 0; base < (1u << 24); base += N * 11) {
    for (uint32_t i = 0; i < N; ++i) u[i] = float(base + i) * (1.0f / 16777216.0f);
    k.sincos_turns(u, sv, cv);
    for (uint32_t i = 0; i < N; ++i) {
      float s, c;
      sincos_turns(u[i], s, c);
      ASSERT_EQ(s, sv[i]) << u[i];
      ASSERT_EQ(c, cv[i]) << u[i];
    }
  }
}

}  // namespace
}  // namespace pb
