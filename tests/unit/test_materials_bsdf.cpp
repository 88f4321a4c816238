// The BSDFs of bsdf/ one by one: Fresnel against the textbook, the dielectric's
// reflect/refract choice and directions, the GGX sampler against its pdf (chi-square,
// as test_sampling.cpp does for the hemisphere samplers), the GGX sample weights
// against f cos / pdf, GGX reciprocity and energy bounds, and the mirror.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "pathbench/common/bsdf/bsdf.h"
#include "pathbench/common/rng.h"
#include "sphere_histogram.h"
#include "stat_test.h"

namespace pb {
namespace {

// Chi-square tests in this file (the family-wise 1 % is split among them).
constexpr int kChiSquareTests = 9 + 6;
const double kAlpha = stat::sidak_alpha(0.01, kChiSquareTests);

Uniform4 draw(uint32_t i, uint32_t pixel) { return RngStream{pixel, 11}.draw(i, 1, kRngVertex); }

Vec3d direction(double theta_deg, double phi_deg = 0) {
  const double t = theta_deg * kPi<double> / 180, p = phi_deg * kPi<double> / 180;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// The local frame as the world frame: BSDF results come back in local coordinates.
template <class T> Frame<T> identity_frame() { return {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}; }

// ---- Fresnel ------------------------------------------------------------------------

// Fresnel's equations in their angle form (Hecht, Optics, 4.42-4.43), independent of
// the cosine form the renderer uses.
double fresnel_from_angles(double theta_i, double eta) {
  const double s = std::sin(theta_i) / eta;
  if (s >= 1) return 1;
  if (theta_i == 0) return std::pow((eta - 1) / (eta + 1), 2);
  const double theta_t = std::asin(s);
  const double rs = std::pow(std::sin(theta_i - theta_t) / std::sin(theta_i + theta_t), 2);
  const double rp = std::pow(std::tan(theta_i - theta_t) / std::tan(theta_i + theta_t), 2);
  return 0.5 * (rs + rp);
}

TEST(Fresnel, KnownValues) {
  EXPECT_NEAR(fresnel_dielectric(1.0, 1.5).reflectance, 0.04, 1e-12);               // ((n - 1) / (n + 1))^2
  EXPECT_NEAR(fresnel_dielectric(std::cos(kPi<double> / 4), 1.5).reflectance, 0.0502, 1e-4);  // Hecht: Rs .092, Rp .0085
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.5f).reflectance, 0.04f, 1e-6f);
  // Brewster's angle: the p-polarised part vanishes.
  const double brewster = std::atan(1.5);
  const double rs = std::pow(std::sin(brewster - (kPi<double> / 2 - brewster)), 2);  // theta_i + theta_t = 90 deg
  EXPECT_NEAR(fresnel_dielectric(std::cos(brewster), 1.5).reflectance, 0.5 * rs, 1e-12);
  // Total internal reflection from inside beyond the critical angle asin(1 / 1.5).
  const double critical = std::asin(1 / 1.5);
  EXPECT_EQ(fresnel_dielectric(std::cos(critical + 0.01), 1 / 1.5).reflectance, 1.0);
  EXPECT_LT(fresnel_dielectric(std::cos(critical - 0.01), 1 / 1.5).reflectance, 1.0);
  // Grazing incidence reflects everything; an index-matched interface nothing.
  EXPECT_EQ(fresnel_dielectric(0.0, 1.5).reflectance, 1.0);
  EXPECT_EQ(fresnel_dielectric(0.7, 1.0).reflectance, 0.0);
}

TEST(Fresnel, MatchesTheAngleFormEverywhere) {
  for (double eta : {1.5, 1 / 1.5, 1.33, 2.4, 1 / 2.4})
    for (double deg = 0; deg < 90; deg += 0.5) {
      const double ti = deg * kPi<double> / 180;
      const Fresnel<double> f = fresnel_dielectric(std::cos(ti), eta);
      EXPECT_NEAR(f.reflectance, fresnel_from_angles(ti, eta), 1e-12) << "eta " << eta << ", " << deg << " deg";
      if (f.reflectance < 1) EXPECT_NEAR(std::sqrt(1 - f.cos_t * f.cos_t), std::sin(ti) / eta, 1e-12);  // Snell
    }
}

// ---- Smooth dielectric ------------------------------------------------------------------

struct DielectricCase {
  double theta_deg;
  bool entering;
};

TEST(Dielectric, ChoosesReflectionWithFresnelProbability) {
  // For each angle, side and index: counts of reflect / refract against F, 1 - F.
  const float ior = 1.5f;
  for (const DielectricCase c : {DielectricCase{10, true}, DielectricCase{60, true}, DielectricCase{85, true},
                                 DielectricCase{20, false}, DielectricCase{35, false}, DielectricCase{41, false}}) {
    const Vec3f wo = Vec3f(direction(c.theta_deg, 30));
    const Vec3f d = -wo, n{0, 0, 1};
    const float eta = c.entering ? ior : 1 / ior;
    const double F = fresnel_from_angles(c.theta_deg * kPi<double> / 180, eta);
    const uint32_t N = 200000;
    std::vector<double> counts(2, 0.0);
    for (uint32_t i = 0; i < N; ++i) {
      const BsdfSample<float> s = dielectric_sample(Vec3f{1, 1, 1}, ior, c.entering, d, n, draw(i, 77).v[0]);
      ASSERT_EQ(s.pdf, 0.0f);  // a delta lobe
      ASSERT_NEAR(length(s.wi), 1.0f, 1e-5f);
      if (s.wi.z > 0) {
        counts[0] += 1;
        // Reflection: the mirror direction, weight 1.
        ASSERT_NEAR(s.wi.x, -wo.x, 1e-6f);
        ASSERT_NEAR(s.wi.y, -wo.y, 1e-6f);
        ASSERT_NEAR(s.wi.z, wo.z, 1e-6f);
        ASSERT_EQ(s.weight.x, 1.0f);
      } else {
        counts[1] += 1;
        // Refraction: Snell's law, in the plane of incidence, radiance scaled by 1/eta^2.
        const double sin_t = std::sqrt(double(s.wi.x) * s.wi.x + double(s.wi.y) * s.wi.y);
        ASSERT_NEAR(sin_t, std::sin(c.theta_deg * kPi<double> / 180) / eta, 1e-5);
        ASSERT_NEAR(s.wi.x * wo.y - s.wi.y * wo.x, 0.0f, 1e-5f);  // same plane
        ASSERT_LT(s.wi.x * wo.x, 1e-7f);                          // the other side of the normal
        ASSERT_NEAR(s.weight.y, 1 / (eta * eta), 1e-6f);
      }
    }
    const std::vector<double> expected = {N * F, N * (1 - F)};
    const stat::ChiSquare r = stat::chi_square(counts, expected);
    std::printf("[ chi2     ] dielectric %g deg %s: %s\n", c.theta_deg, c.entering ? "entering" : "leaving",
                r.message.c_str());
    EXPECT_TRUE(r.passes(kAlpha)) << c.theta_deg << " deg: " << r.message;
  }
}

TEST(Dielectric, TotalInternalReflectionAlwaysReflects) {
  const Vec3f d = -Vec3f(direction(50)), n{0, 0, 1};  // 50 deg > the critical 41.8 deg
  for (uint32_t i = 0; i < 1000; ++i) {
    const BsdfSample<float> s = dielectric_sample(Vec3f{1, 1, 1}, 1.5f, false, d, n, draw(i, 5).v[0]);
    ASSERT_GT(s.wi.z, 0);
    ASSERT_EQ(s.weight.x, 1.0f);
  }
}

TEST(Mirror, ReflectsWithItsAlbedo) {
  const Vec3d wo = direction(35, 110);
  const BsdfSample<double> s = mirror_sample(Vec3f{0.9f, 0.5f, 0.25f}, -wo, Vec3d{0, 0, 1});
  EXPECT_NEAR(s.wi.x, -wo.x, 1e-15);
  EXPECT_NEAR(s.wi.y, -wo.y, 1e-15);
  EXPECT_NEAR(s.wi.z, wo.z, 1e-15);
  EXPECT_EQ(s.pdf, 0.0);
  EXPECT_EQ(s.weight.x, double(0.9f));
  EXPECT_EQ(s.weight.z, 0.25);
}

// ---- GGX rough conductor --------------------------------------------------------------

struct GgxCase {
  float alpha;
  double theta_deg;
};
const GgxCase kGgxCases[] = {{0.2f, 0}, {0.2f, 45}, {0.2f, 80}, {0.5f, 30}, {0.5f, 75}, {1.0f, 0},
                             {1.0f, 60}, {0.05f, 20}, {0.05f, 70}};

// The sampled directions' histogram against the pdf the sampler claims (the pdf MIS uses).
TEST(RoughConductor, SamplerMatchesItsPdf) {
  uint32_t pixel = 100;
  for (const GgxCase c : kGgxCases) {
    const Vec3f wo = Vec3f(direction(c.theta_deg, 20));
    stat::SphereHistogram h(32, 64);
    const uint32_t N = 1000000;
    for (uint32_t i = 0; i < N; ++i) {
      const Uniform4 u = draw(i, pixel);
      BsdfSample<float> s;
      if (!roughconductor_sample(Vec3f{1, 1, 1}, c.alpha, identity_frame<float>(), wo, u.v[0], u.v[1], s)) continue;
      ASSERT_GT(s.wi.z, 0);
      h.add(Vec3d(s.wi));
    }
    const Vec3d wod = Vec3d(wo);
    auto pdf = [&](double ct, double phi) {
      const double st = std::sqrt(std::max(0.0, 1 - ct * ct));
      const Vec3d wi{st * std::cos(phi), st * std::sin(phi), ct};
      return roughconductor_eval(Vec3f{1, 1, 1}, double(c.alpha), wod, wi).pdf;
    };
    // Narrow lobes need finer integration within the bins.
    const auto e = h.expected(pdf, [](double, double c1) { return c1 > 0; }, N, c.alpha < 0.1f ? 64 : 16);
    const stat::ChiSquare r = stat::chi_square(h.counts, e);
    std::printf("[ chi2     ] GGX alpha %g, %g deg: %s\n", c.alpha, c.theta_deg, r.message.c_str());
    EXPECT_TRUE(r.passes(kAlpha)) << "alpha " << c.alpha << ", " << c.theta_deg << " deg: " << r.message;
    ++pixel;
  }
}

// What the path step multiplies by after BSDF sampling equals f cos / pdf from
// roughconductor_eval (what light sampling uses): the two strategies agree on f.
TEST(RoughConductor, SampleWeightIsFCosOverPdf) {
  const Vec3f albedo{0.9f, 0.6f, 0.3f};
  for (const GgxCase c : kGgxCases) {
    const Vec3d wo = direction(c.theta_deg, 200);
    for (uint32_t i = 0; i < 2000; ++i) {
      const Uniform4 u = draw(i, 3);
      BsdfSample<double> s;
      if (!roughconductor_sample(albedo, double(c.alpha), identity_frame<double>(), wo, double(u.v[0]), double(u.v[1]), s))
        continue;
      const BsdfEval<double> e = roughconductor_eval(albedo, double(c.alpha), wo, s.wi);
      ASSERT_NEAR(e.pdf, s.pdf, 1e-9 * s.pdf);
      ASSERT_NEAR(e.f.x * s.wi.z / e.pdf, s.weight.x, 1e-9 * s.weight.x + 1e-12) << "alpha " << c.alpha;
      ASSERT_NEAR(e.f.z * s.wi.z / e.pdf, s.weight.z, 1e-9 * s.weight.z + 1e-12);
    }
  }
}

TEST(RoughConductor, IsReciprocal) {
  for (float alpha : {0.05f, 0.2f, 0.7f, 1.0f})
    for (uint32_t i = 0; i < 5000; ++i) {
      const Uniform4 u = draw(i, 9);
      const Vec3d a = direction(89.0 * u.v[0], 360.0 * u.v[1]), b = direction(89.0 * u.v[2], 360.0 * u.v[3]);
      const double fab = roughconductor_eval(Vec3f{1, 1, 1}, double(alpha), a, b).f.x;
      const double fba = roughconductor_eval(Vec3f{1, 1, 1}, double(alpha), b, a).f.x;
      ASSERT_GE(fab, 0);
      ASSERT_NEAR(fab, fba, 1e-12 * fab) << "alpha " << alpha;
    }
  // Nothing below the surface, from either side.
  EXPECT_EQ(roughconductor_eval(Vec3f{1, 1, 1}, 0.5, direction(30), direction(120)).f.x, 0.0);
  EXPECT_EQ(roughconductor_eval(Vec3f{1, 1, 1}, 0.5, direction(100), direction(30)).f.x, 0.0);
}

// The directional albedo, integral of f cos over the hemisphere, estimated twice: by the
// mean sample weight of the GGX sampler and by uniform hemisphere sampling of eval. Both
// agree, never exceed the albedo (single-scattering GGX loses energy, it never gains),
// approach it for smooth surfaces, and match the closed form at alpha = 1 head-on.
TEST(RoughConductor, DirectionalAlbedoIsBoundedAndConsistent) {
  for (const GgxCase c : kGgxCases) {
    const Vec3d wo = direction(c.theta_deg);
    const uint32_t N = 400000;
    double by_sampling = 0, by_sampling2 = 0, uniform = 0, uniform2 = 0;
    for (uint32_t i = 0; i < N; ++i) {
      const Uniform4 u = draw(i, 21);
      BsdfSample<double> s;
      double w = 0;
      if (roughconductor_sample(Vec3f{1, 1, 1}, double(c.alpha), identity_frame<double>(), wo, double(u.v[0]),
                                double(u.v[1]), s))
        w = s.weight.x;
      ASSERT_LE(w, 1.0 + 1e-12);  // weight = G1 <= 1
      by_sampling += w;
      by_sampling2 += w * w;
      const Vec3d wi = sample_uniform_hemisphere(double(u.v[2]), double(u.v[3]));
      const double f = roughconductor_eval(Vec3f{1, 1, 1}, double(c.alpha), wo, wi).f.x * wi.z / uniform_hemisphere_pdf<double>();
      uniform += f;
      uniform2 += f * f;
    }
    const double m1 = by_sampling / N, m2 = uniform / N;
    const double s1 = std::sqrt((by_sampling2 / N - m1 * m1) / N), s2 = std::sqrt((uniform2 / N - m2 * m2) / N);
    EXPECT_LE(m1, 1.0) << "alpha " << c.alpha << ", " << c.theta_deg << " deg";
    EXPECT_NEAR(m1, m2, 5 * std::sqrt(s1 * s1 + s2 * s2)) << "alpha " << c.alpha << ", " << c.theta_deg << " deg";
    if (c.alpha <= 0.05f) EXPECT_GT(m1, 0.98) << "a nearly smooth surface keeps nearly all its energy";
    // alpha = 1 makes D = 1/pi; seen head-on, f cos_i = (1/(4 pi)) 2 cos_i / (1 + cos_i),
    // whose integral over the hemisphere is 1 - ln 2.
    if (c.alpha == 1.0f && c.theta_deg == 0) EXPECT_NEAR(m1, 1 - std::log(2.0), 5 * s1);
  }
}

}  // namespace
}  // namespace pb
