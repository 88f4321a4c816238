// Every sampler the path step uses, checked against the density it claims, in the
// style of Mitsuba 3's and pbrt's sampler tests: draw samples with the project's own
// random stream (RngStream), histogram them over the sphere in (cos theta, phi) or
// over the square, integrate the pdf over each bin (Simpson), and run a chi-square
// goodness-of-fit test with low-expectation bins pooled. A test fails at a
// Sidak-corrected 1 % over all the chi-square tests in this file. Also: the random
// stream itself, the shading frame, emitter selection and the light-sampling pdf.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "pathbench/common/math.h"
#include "pathbench/common/path.h"
#include "pathbench/common/rng.h"
#include "pathbench/common/sampling.h"
#include "pathbench/scene_io/scene_library.h"
#include "sphere_histogram.h"
#include "stat_test.h"

namespace pb {
namespace {

using stat::SphereHistogram;

// Number of chi-square tests below: the family-wise 1 % is split among them.
constexpr int kChiSquareTests = 10;
const double kAlpha = stat::sidak_alpha(0.01, kChiSquareTests);
constexpr uint32_t kSamples = 1000000;

// The i-th draw of four uniforms at path vertex 1 in dimension group `group` (by
// default the one the path step uses for the BSDF direction and the light sample).
std::array<float, 4> draw(uint32_t i, uint32_t pixel = 12345, uint32_t group = kRngVertex, uint64_t seed = 7) {
  const Uniform4 u = RngStream{pixel, seed}.draw(i, 1, group);
  return {u.v[0], u.v[1], u.v[2], u.v[3]};
}

Vec3d to_d(Vec3f v) { return Vec3d(v); }

// pick_emitter(s, u) chooses an emitter and rescales u to [0, 1) within the chosen
// emitter's CDF interval, so the same number can place the point (sample reuse).
uint32_t pick(const SceneView& s, float u) { return pick_emitter(s, u); }

// The emitter triangle and barycentrics that path_hit's light sampling derives from
// the vertex draw `u` (see path.h).
std::pair<uint32_t, Barycentrics<float>> light_sample(const SceneView& s, const Uniform4& u) {
  float u_pick = u.v[2];
  const uint32_t tri = s.emitters[pick_emitter(s, u_pick)];
  return {tri, sample_uniform_triangle(u_pick, u.v[3])};
}

void expect_chi_square_passes(const std::vector<double>& observed, const std::vector<double>& expected,
                              const char* what) {
  const stat::ChiSquare r = stat::chi_square(observed, expected);
  std::printf("[ chi2     ] %s: %s (reject below %.3g)\n", what, r.message.c_str(), kAlpha);
  EXPECT_TRUE(r.passes(kAlpha)) << what << ": " << r.message << ", alpha " << kAlpha;
}

// ---- The statistics themselves ----------------------------------------------------

TEST(ChiSquare, PValuesMatchTables) {
  EXPECT_NEAR(stat::chi2_pvalue(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(stat::chi2_pvalue(18.307038, 10), 0.05, 1e-6);
  EXPECT_NEAR(stat::chi2_pvalue(6.634897, 1), 0.01, 1e-6);
  EXPECT_NEAR(stat::chi2_pvalue(1000, 1000), 0.4940528, 1e-5);
  EXPECT_NEAR(stat::chi2_pvalue(2, 2), std::exp(-1.0), 1e-12);  // 2 dof: exp(-x/2)
  EXPECT_NEAR(stat::regularized_gamma_p(3, 2.5) + stat::regularized_gamma_q(3, 2.5), 1.0, 1e-14);
  EXPECT_NEAR(stat::sidak_alpha(0.01, 1), 0.01, 1e-15);
  EXPECT_NEAR(stat::normal_two_sided_p(1.959964), 0.05, 1e-6);
}

TEST(ChiSquare, RejectsAWrongPdf) {
  // The test has power: cosine-weighted samples against the uniform density fail.
  SphereHistogram h(32, 64);
  for (uint32_t i = 0; i < kSamples / 10; ++i) {
    const auto u = draw(i);
    h.add(to_d(sample_cosine_hemisphere(u[0], u[1])));
  }
  const auto e = h.expected([](double, double) { return double(uniform_hemisphere_pdf<float>()); },
                            [](double, double c1) { return c1 > 0; }, kSamples / 10);
  const stat::ChiSquare r = stat::chi_square(h.counts, e);
  EXPECT_FALSE(r.passes(kAlpha)) << r.message;
  EXPECT_LT(r.p, 1e-100) << r.message;
  // ... and samples where the density is zero fail outright.
  std::vector<double> obs = {5, 10, 1}, exp = {8, 8, 0};
  EXPECT_TRUE(stat::chi_square(obs, exp).impossible);
}

// ---- The random stream ---------------------------------------------------------

TEST(RngStream, IsDeterministic) {
  for (uint32_t i = 0; i < 1000; ++i) {
    const Uniform4 a = RngStream{i * 7919u, 42}.draw(i, i % 5, i % 3);
    const Uniform4 b = RngStream{i * 7919u, 42}.draw(i, i % 5, i % 3);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(a.v[k], b.v[k]);
  }
}

TEST(RngStream, EveryCounterAndKeyWordChangesTheNumbers) {
  // All 4-tuples over a grid of (seed, pixel, sample, bounce, group) are distinct: each
  // input reaches the output, and nothing aliases (e.g. pixel 1 sample 0 = pixel 0
  // sample 1). 96 random bits per tuple make a chance collision negligible.
  std::set<std::array<float, 4>> seen;
  size_t n = 0;
  for (uint64_t seed : {uint64_t(0), uint64_t(1), uint64_t(1) << 32, (uint64_t(1) << 32) + 1})
    for (uint32_t pixel = 0; pixel < 6; ++pixel)
      for (uint32_t sample = 0; sample < 6; ++sample)
        for (uint32_t bounce = 0; bounce < 4; ++bounce)
          for (uint32_t group = 0; group < 3; ++group) {
            const Uniform4 u = RngStream{pixel, seed}.draw(sample, bounce, group);
            seen.insert({u.v[0], u.v[1], u.v[2], u.v[3]});
            ++n;
          }
  EXPECT_EQ(seen.size(), n);
}

TEST(RngStream, UnitFloatRange) {
  EXPECT_EQ(u32_to_unit_float(0u), 0.0f);
  EXPECT_LT(u32_to_unit_float(0xFFFFFFFFu), 1.0f);
  EXPECT_EQ(u32_to_unit_float(0xFFFFFFFFu), 1.0f - 1.0f / 16777216.0f);
  EXPECT_EQ(u32_to_unit_float(0x80000000u), 0.5f);
  for (uint32_t i = 0; i < 100000; ++i) {
    const Uniform4 u = RngStream{i, 3}.draw(0, 0, 0);
    for (float v : u.v) {
      ASSERT_GE(v, 0.0f);
      ASSERT_LT(v, 1.0f);
      ASSERT_EQ(v * 16777216.0f, std::floor(v * 16777216.0f)) << "not a multiple of 2^-24";
    }
  }
}

TEST(RngStream, UniformChiSquare1D) {
  // Every one of the four outputs of a draw, over 1000 bins.
  const int bins = 1000;
  std::vector<double> obs(bins, 0.0);
  for (uint32_t i = 0; i < kSamples / 4; ++i)
    for (float v : draw(i)) obs[size_t(v * bins)] += 1;
  expect_chi_square_passes(obs, std::vector<double>(bins, double(kSamples) / bins), "u32_to_unit_float, 1D");
}

TEST(RngStream, UniformChiSquare2DAcrossPixels) {
  // Pairs (value in pixel p, value in pixel p + 1) for the same sample: neighbouring
  // keys must not be correlated.
  const int n = 64;
  std::vector<double> obs(n * n, 0.0);
  for (uint32_t i = 0; i < kSamples; ++i) {
    const uint32_t pixel = i % 65536, sample = i / 65536;
    const float a = RngStream{pixel, 9}.draw(sample, 0, kRngCamera).v[0];
    const float b = RngStream{pixel + 1, 9}.draw(sample, 0, kRngCamera).v[0];
    obs[size_t(a * n) * n + size_t(b * n)] += 1;
  }
  expect_chi_square_passes(obs, std::vector<double>(n * n, double(kSamples) / (n * n)),
                           "RngStream, neighbouring pixels");
}

// ---- Hemisphere samplers -------------------------------------------------------

// Draws kSamples directions with sample(u0, u1) from the project's random stream,
// checks each is a unit vector, and tests their histogram against pdf(cos theta, phi)
// (zero in bins where support(c0, c1) is false). `simpson_n` intervals per bin axis.
template <class Sample, class Pdf, class Support>
void check_direction_sampler(const char* what, Sample&& sample, Pdf&& pdf, Support&& support, int simpson_n = 16,
                             uint32_t pixel = 12345) {
  SphereHistogram h(32, 64);
  for (uint32_t i = 0; i < kSamples; ++i) {
    const auto u = draw(i, pixel);
    const Vec3d w = to_d(sample(u[0], u[1]));
    ASSERT_NEAR(length(w), 1.0, 1e-5) << what;
    h.add(w);
  }
  const auto e = h.expected(pdf, support, kSamples, simpson_n);
  double total = 0;
  for (double x : e) total += x;
  EXPECT_NEAR(total, kSamples, 1e-3 * kSamples) << what << ": the pdf does not integrate to 1";
  expect_chi_square_passes(h.counts, e, what);
}

const auto kWholeSphere = [](double, double) { return true; };

TEST(Sampling, UniformHemisphereMatchesPdf) {
  // The density is uniform_hemisphere_pdf() on the upper hemisphere, zero below.
  check_direction_sampler(
      "sample_uniform_hemisphere", [](float u0, float u1) { return sample_uniform_hemisphere(u0, u1); },
      [](double, double) { return double(uniform_hemisphere_pdf<float>()); },
      [](double, double c1) { return c1 > 0; });
}

TEST(Sampling, CosineHemisphereMatchesPdf) {
  check_direction_sampler(
      "sample_cosine_hemisphere", [](float u0, float u1) { return sample_cosine_hemisphere(u0, u1); },
      [](double c, double) { return double(cosine_hemisphere_pdf(float(c))); }, kWholeSphere);
}

TEST(Sampling, CosineHemisphereThroughFrameMatchesPdf) {
  // The path step samples in the local frame and maps with Frame::to_world: the world
  // direction must have density cos(n, w) / pi about the shading normal n.
  const Vec3f n = normalize(Vec3f{1, 2, -3});
  const Frame<float> f = Frame<float>::from_normal(n);
  const Vec3d nd = Vec3d(n);
  const auto pdf = [&](double c, double phi) {
    const double s = std::sqrt(std::max(0.0, 1 - c * c));
    return std::max(0.0, dot(nd, Vec3d{s * std::cos(phi), s * std::sin(phi), c})) / kPi<double>;
  };
  // The density has a kink along the great circle dot(n, w) = 0: finer Simpson there.
  check_direction_sampler(
      "cosine hemisphere through Frame",
      [&](float u0, float u1) { return f.to_world(sample_cosine_hemisphere(u0, u1)); }, pdf, kWholeSphere, 64, 777);
}

// ---- Triangle ------------------------------------------------------------------

TEST(Sampling, UniformTriangleMatchesArea) {
  // Barycentrics (b1, b2) uniform over {b1, b2 >= 0, b1 + b2 <= 1}: an n x n grid on
  // the unit square puts the diagonal through cell corners, so cells are wholly
  // inside (expected 2 / n^2 of the samples), halved (1 / n^2) or outside (0).
  const int n = 40;
  std::vector<double> obs(n * n, 0.0), e(n * n, 0.0);
  for (uint32_t i = 0; i < kSamples; ++i) {
    const auto u = draw(i, 4242, 3);  // a dimension group of its own
    const Barycentrics<float> b = sample_uniform_triangle(u[0], u[1]);
    ASSERT_GE(b.b1, 0.0f);
    ASSERT_GE(b.b2, 0.0f);
    ASSERT_LE(b.b1 + b.b2, 1.0f + 1e-6f);
    const int x = std::min(n - 1, int(b.b1 * n)), y = std::min(n - 1, int(b.b2 * n));
    obs[size_t(x) * n + y] += 1;
  }
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      e[size_t(x) * n + y] = kSamples * (x + y < n - 1 ? 2.0 : (x + y == n - 1 ? 1.0 : 0.0)) / (n * n);
  expect_chi_square_passes(obs, e, "sample_uniform_triangle");
}

TEST(Sampling, LightPointsUniformOverPaperLight) {
  // The light-sampling point as path_hit computes it (pick an emitter triangle, then
  // barycentrics) is uniform over the paper's 10 x 6 light, across both triangles.
  const Scene scene = make_paper_cornell();
  const SceneView s = scene.view();
  ASSERT_EQ(s.num_emitters, 2u);
  const int nx = 30, nz = 18;
  std::vector<double> obs(nx * nz, 0.0);
  for (uint32_t i = 0; i < kSamples; ++i) {
    const uint32_t pixel = i % 4096, sample = i / 4096;
    const auto [tri_id, b] = light_sample(s, RngStream{pixel, 5}.draw(sample, 1, kRngVertex));
    const Triangle tri = s.triangles[tri_id];
    const Vec3f v0 = s.positions[tri.v[0]];
    const Vec3f y = v0 + (s.positions[tri.v[1]] - v0) * b.b1 + (s.positions[tri.v[2]] - v0) * b.b2;
    ASSERT_NEAR(y.y, 9.9f, 1e-5f);
    const int ix = std::clamp(int((y.x + 5) / 10 * nx), 0, nx - 1);
    const int iz = std::clamp(int((y.z + 8) / 6 * nz), 0, nz - 1);
    obs[size_t(ix) * nz + iz] += 1;
  }
  expect_chi_square_passes(obs, std::vector<double>(nx * nz, double(kSamples) / (nx * nz)),
                           "light points on paper-cornell's light");
}

// ---- Frame ---------------------------------------------------------------------

TEST(Frame, OrthonormalRightHandedAndMapsZToNormal) {
  std::vector<Vec3f> normals = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},         {-1, 0, 0},
                                {0, 1, 0},  {0, -1, 0}, normalize(Vec3f{0, 1e-4f, -1}),
                                normalize(Vec3f{1e-7f, 0, -1}), normalize(Vec3f{0, 0, 1}) * -1.0f};
  for (uint32_t i = 0; i < 20000; ++i) {  // uniform over the sphere
    const auto u = draw(i, 99);
    const float z = 1 - 2 * u[0], r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * kPi<float> * u[1];
    normals.push_back({r * std::cos(phi), r * std::sin(phi), z});
  }
  for (const Vec3f& n : normals) {
    const Frame<float> f = Frame<float>::from_normal(n);
    const float tol = 2e-6f;
    ASSERT_NEAR(length(f.s), 1.0f, tol) << n.x << " " << n.y << " " << n.z;
    ASSERT_NEAR(length(f.t), 1.0f, tol);
    ASSERT_NEAR(dot(f.s, f.t), 0.0f, tol);
    ASSERT_NEAR(dot(f.s, f.n), 0.0f, tol);
    ASSERT_NEAR(dot(f.t, f.n), 0.0f, tol);
    const Vec3f z = f.to_world({0, 0, 1});
    ASSERT_NEAR(z.x, n.x, tol);
    ASSERT_NEAR(z.y, n.y, tol);
    ASSERT_NEAR(z.z, n.z, tol);
    const Vec3f c = cross(f.s, f.t);  // right-handed: s x t = n
    ASSERT_NEAR(dot(c, n), 1.0f, 4 * tol);
    // to_world preserves lengths and the cosine to n.
    const Vec3f w = f.to_world(normalize(Vec3f{0.3f, -0.4f, 0.5f}));
    ASSERT_NEAR(length(w), 1.0f, 4 * tol);
    ASSERT_NEAR(dot(w, n), 0.5f / length(Vec3f{0.3f, -0.4f, 0.5f}), 4 * tol);
  }
}

TEST(Frame, DoublePrecisionToo) {
  const Frame<double> f = Frame<double>::from_normal(normalize(Vec3d{-0.2, 0.7, 0.1}));
  EXPECT_NEAR(dot(f.s, f.t), 0.0, 1e-14);
  EXPECT_NEAR(dot(cross(f.s, f.t), f.n), 1.0, 1e-14);
}

// ---- Emitter selection ---------------------------------------------------------

// A closed-off scene with three emitters of different area and emission, so the
// selection probabilities (proportional to area x mean emission) are all different.
Scene three_emitter_scene() {
  Scene s;
  s.name = "three-emitters";
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0},      // area 0.5
                 {0, 0, 1}, {2, 0, 1}, {0, 1, 1},      // area 1
                 {0, 0, 2}, {1, 0, 2}, {0, 3, 2},      // area 1.5
                 {-5, -5, -1}, {5, -5, -1}, {0, 5, -1}};
  s.triangles = {{{0, 1, 2}}, {{9, 10, 11}}, {{3, 4, 5}}, {{6, 7, 8}}};
  s.materials = {{{0, 0, 0}, {1, 2, 3}},        // mean 2
                 {{0.5f, 0.5f, 0.5f}, {0, 0, 0}},
                 {{0, 0, 0}, {1, 1, 1}},        // mean 1
                 {{0, 0, 0}, {0.5f, 0.5f, 0.5f}}};  // mean 0.5
  s.material_ids = {0, 1, 2, 3};
  s.camera = Camera::look_at({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 40);
  s.finalize();
  return s;
}

TEST(PickEmitter, FrequenciesFollowTheCdf) {
  const Scene scene = three_emitter_scene();
  const SceneView s = scene.view();
  ASSERT_EQ(s.num_emitters, 3u);
  // Powers: 0.5 x 2 = 1, 1 x 1 = 1, 1.5 x 0.5 = 0.75.
  const double power[3] = {1.0, 1.0, 0.75};
  EXPECT_NEAR(s.emitter_power_total, 2.75, 1e-5);
  double acc = 0;
  for (int i = 0; i < 3; ++i) {
    acc += power[i];
    EXPECT_NEAR(s.emitter_cdf[i], acc / 2.75, 1e-6) << "emitter " << i;
  }
  // Histogram over (emitter, u after the pick): the emitter frequencies follow the CDF
  // and the rescaled u is uniform on [0, 1) for each emitter.
  const int nu = 50;
  std::vector<double> obs(3 * nu, 0.0), e(3 * nu);
  for (uint32_t i = 0; i < kSamples; ++i) {
    float u = draw(i, 31337)[2];
    const uint32_t k = pick_emitter(s, u);
    ASSERT_LT(k, 3u);
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    obs[k * nu + std::min(nu - 1, int(u * nu))] += 1;
  }
  for (int i = 0; i < 3 * nu; ++i) e[i] = kSamples * power[i / nu] / 2.75 / nu;
  expect_chi_square_passes(obs, e, "pick_emitter (choice and rescaled u)");
}

TEST(PickEmitter, EdgesOfTheCdf) {
  const Scene scene = three_emitter_scene();
  const SceneView s = scene.view();
  EXPECT_EQ(pick(s, 0.0f), 0u);
  EXPECT_EQ(pick(s, std::nextafter(s.emitter_cdf[0], 0.0f)), 0u);
  EXPECT_EQ(pick(s, s.emitter_cdf[0]), 1u);  // intervals are [cdf[i-1], cdf[i])
  EXPECT_EQ(pick(s, 1.0f - 1.0f / 16777216.0f), 2u);
  float u = 1.0f - 1.0f / 16777216.0f;
  pick_emitter(s, u);
  EXPECT_LT(u, 1.0f) << "the rescaled u must stay below 1";
  u = s.emitter_cdf[0];
  pick_emitter(s, u);
  EXPECT_EQ(u, 0.0f);
  // One emitter: always it.
  const Scene cornell = make_paper_cornell();
  Scene one = cornell;
  one.materials[3].emission = {0, 0, 0};
  one.triangles.push_back(cornell.triangles[12]);
  one.material_ids.push_back(3);
  one.materials.push_back({{0, 0, 0}, {5, 5, 5}});
  one.material_ids.back() = uint32_t(one.materials.size() - 1);
  one.finalize();
  ASSERT_EQ(one.emitters.size(), 1u);
  EXPECT_EQ(pick(one.view(), 0.999f), 0u);
}

// ---- The light-sampling pdf ----------------------------------------------------

// Moeller-Trumbore in double; t along the unit direction d, or -1 on a miss.
double intersect(Vec3d o, Vec3d d, Vec3d v0, Vec3d v1, Vec3d v2) {
  const Vec3d e1 = v1 - v0, e2 = v2 - v0, p = cross(d, e2);
  const double det = dot(e1, p);
  if (std::fabs(det) < 1e-14) return -1;
  const Vec3d tv = o - v0;
  const double b1 = dot(tv, p) / det;
  if (b1 < 0 || b1 > 1) return -1;
  const Vec3d q = cross(tv, e1);
  const double b2 = dot(d, q) / det;
  if (b2 < 0 || b1 + b2 > 1) return -1;
  const double t = dot(e2, q) / det;
  return t > 0 ? t : -1;
}

// Integral over all directions from x of path_hit's light-sampling density
// emitter_area_pdf * dist^2 / cos_l (zero where no emitter's front side is seen), by
// the midpoint rule in (cos theta, phi) over a cone about the emitters' centroid.
double light_pdf_solid_angle_integral(const Scene& scene, Vec3d x, int n = 1500) {
  const SceneView s = scene.view();
  Vec3d centre{0, 0, 0};
  std::vector<Vec3d> corners;
  for (uint32_t e = 0; e < s.num_emitters; ++e)
    for (uint32_t k : s.triangles[s.emitters[e]].v) {
      corners.push_back(Vec3d(s.positions[k]));
      centre += Vec3d(s.positions[k]);
    }
  centre = centre / double(corners.size());
  const Vec3d axis = normalize(centre - x);
  // The widest angle to the axis lies on an emitter's boundary (not always at a corner:
  // seen at a grazing angle the cone cuts the plane in a hyperbola): walk the edges.
  double cos_max = 1;
  for (size_t k = 0; k < corners.size(); k += 3)
    for (int e = 0; e < 3; ++e)
      for (int i = 0; i <= 1000; ++i) {
        const Vec3d a = corners[k + e], b = corners[k + (e + 1) % 3];
        cos_max = std::min(cos_max, dot(axis, normalize(a + (b - a) * (i / 1000.0) - x)));
      }
  cos_max = std::max(-1.0, cos_max - 0.02);
  const Frame<double> f = Frame<double>::from_normal(axis);
  const double dc = (1 - cos_max) / n, dphi = 2 * kPi<double> / n;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double c = cos_max + (i + 0.5) * dc, r = std::sqrt(std::max(0.0, 1 - c * c));
    for (int j = 0; j < n; ++j) {
      const double phi = (j + 0.5) * dphi;
      const Vec3d w = f.to_world({r * std::cos(phi), r * std::sin(phi), c});
      for (uint32_t e = 0; e < s.num_emitters; ++e) {
        const uint32_t tri_id = s.emitters[e];
        const Triangle tri = s.triangles[tri_id];
        const Vec3d v0 = Vec3d(s.positions[tri.v[0]]), v1 = Vec3d(s.positions[tri.v[1]]),
                    v2 = Vec3d(s.positions[tri.v[2]]);
        const double t = intersect(x, w, v0, v1, v2);
        if (t <= 0) continue;
        const Vec3d nl = normalize(cross(v1 - v0, v2 - v0));
        const double cos_l = -dot(nl, w);
        if (cos_l <= 0) continue;  // the back of a one-sided emitter: never sampled
        sum += emitter_area_pdf<double>(s, s.material_of(tri_id).emission) * t * t / cos_l * dc * dphi;
      }
    }
  }
  return sum;
}

TEST(LightPdf, IntegratesToOneOverTheEmittersSolidAngle) {
  const Scene scene = make_paper_cornell();
  const Vec3d points[] = {{0, -10, -5}, {9, -10, 21}, {-3, 2, -10}, {-10, 0, 0}, {1, 9.5, -4}, {-9, -9, 20}};

  for (const Vec3d& x : points) {
    const double integral = light_pdf_solid_angle_integral(scene, x);
    std::printf("[ light pdf] from (%g, %g, %g): integral %.6f\n", x.x, x.y, x.z, integral);
    EXPECT_NEAR(integral, 1.0, 2e-3) << "from (" << x.x << ", " << x.y << ", " << x.z << ")";
  }
  // Above the light only its back is seen: the density is zero everywhere.
  EXPECT_NEAR(light_pdf_solid_angle_integral(scene, {0, 9.95, -5}, 400), 0.0, 1e-12);
}

TEST(LightPdf, IntegratesToOneWithSeveralEmitters) {
  // Unequal emitters: the per-emitter densities must add up to 1 seen from a point
  // that sees every emitter's front side (all three face +z; look from above).
  const Scene scene = three_emitter_scene();
  const double integral = light_pdf_solid_angle_integral(scene, {0.3, 0.3, 4}, 2000);
  std::printf("[ light pdf] three emitters: integral %.6f\n", integral);
  EXPECT_NEAR(integral, 1.0, 2e-3);
}

}  // namespace
}  // namespace pb

// pb::fmadd (math.h) rounds once, on every path it may take (builtin, inline FMA behind
// the CPU check, libm): a * b + c with a = 1 + 2^-12 keeps the 2^-24 term that rounding
// a * a first would drop (a tie, to even), and likewise in double.
TEST(Fmadd, RoundsOnce) {
  const float a = 1.0f + 0x1p-12f;
  EXPECT_EQ(pb::fmadd(a, a, -1.0f), 0x1p-11f + 0x1p-24f);
  EXPECT_EQ(a * a - 1.0f, 0x1p-11f);  // the unfused value, for contrast
  const double b = 1.0 + 0x1p-27;
  EXPECT_EQ(pb::fmadd(b, b, -1.0), 0x1p-26 + 0x1p-54);
  EXPECT_EQ(pb::fmadd(pb::Vec3f{a, 2.0f, a}, a, pb::Vec3f{-1.0f, 0.0f, 0.0f}).x, 0x1p-11f + 0x1p-24f);
}
