// Whole renders with mirrors, glass and rough metal:
//  - white furnace whose walls are a mix of mirrors and diffuse reflectors of one albedo
//    a: every path sees Le (1 + a + ... + a^k), Le / (1 - a) unbounded, whatever BSDF
//    each bounce meets -- this checks the delta-vertex bookkeeping of light sampling
//    (no light sample at a mirror, emission after it counted with weight 1);
//  - a glass sphere in a furnace leaves the radiance unchanged (lossless, and the
//    1/eta^2 radiance scaling in and out cancels);
//  - light sampling + MIS and pure BSDF sampling agree on every cornell-box variant
//    (the GGX pdf that MIS uses is the one its sampler draws from);
//  - pixel-parallel and wavefront renders of every variant are bit-identical;
//  - scene features pick the path step's instantiation, and scene files take the new
//    kinds (with clear errors).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "pathbench/common/errors.h"
#include "pathbench/common/features.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"
#include "furnace_check.h"

namespace pb {
namespace {

const std::string kScenes = std::string(PATHBENCH_SOURCE_DIR) + "/scenes/";

ImageMean render_mean(const Scene& scene, RenderSettings s, RunReport* report_out = nullptr) {
  s.variance = true;
  s.progress = false;
  Film film(s.width, s.height, true);
  RunReport report;
  run::render(scene, s, film, report);
  EXPECT_EQ(report.discarded_samples, 0u) << scene.name;
  if (report_out) *report_out = report;
  return image_mean(film);
}

RenderSettings settings(Sampling sampling, int bounces, uint32_t size, uint32_t spp) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.sampling = sampling;
  s.max_bounces = bounces;
  s.russian_roulette = bounces < 0;
  s.rr_start_depth = 1;
  s.seed = 5;
  return s;
}

#if PATHBENCH_EXTRA_MATERIALS
Material of_kind(MaterialKind kind, float a) {
  Material m{{a, a, a}, {0, 0, 0}, kind};
  return m;
}

// The furnace cube with walls of alternating kinds, all of albedo a and emission Le.
Scene mixed_furnace(float a, float Le, MaterialKind other) {
  Scene s = make_furnace(a, Le);
  s.name = std::string("furnace with diffuse and ") + to_string(other) + " walls";
  Material m = of_kind(other, a);
  m.emission = {Le, Le, Le};
  s.materials.push_back(m);
  s.material_names.push_back(to_string(other));
  for (size_t t = 0; t < s.triangles.size(); ++t)
    if ((t / 2) % 2 == 0) s.material_ids[t] = 1;  // faces 0, 2, 4: the other kind
  s.finalize();
  return s;
}

struct FurnaceCase {
  MaterialKind other;
  Sampling sampling;
  int bounces;
};

class MixedFurnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(MixedFurnace, MeanMatchesClosedForm) {
  const float a = 0.5f, Le = 1.0f;
  const FurnaceCase c = GetParam();
  const Scene scene = mixed_furnace(a, Le, c.other);
  ASSERT_EQ(scene.features.material_kinds, kind_bit(MaterialKind::Diffuse) | kind_bit(c.other));
  const ImageMean m = render_mean(scene, settings(c.sampling, c.bounces, 16, 256));
  const double expected = furnace_radiance(a, Le, c.bounces);
  EXPECT_NEAR(m.mean, expected, 5 * m.sigma + 1e-5 * expected) << scene.name << ", sigma " << m.sigma;
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, MixedFurnace,
    ::testing::Values(FurnaceCase{MaterialKind::Mirror, Sampling::Nee, 3},
                      FurnaceCase{MaterialKind::Mirror, Sampling::Nee, -1},
                      FurnaceCase{MaterialKind::Mirror, Sampling::Uniform, 3},
                      FurnaceCase{MaterialKind::Mirror, Sampling::Cosine, -1}),
    [](const auto& info) {
      return std::string(to_string(info.param.other)) + "_" + to_string(info.param.sampling) + "_" +
             (info.param.bounces < 0 ? std::string("unbounded") : std::to_string(info.param.bounces));
    });

// Every wall a mirror: each path's value is known exactly (no randomness left but RR).
TEST(MirrorFurnace, EveryWallAMirror) {
  Scene s = make_furnace(0.5f, 1.0f);
  s.materials[0].kind = MaterialKind::Mirror;
  s.finalize();
  const ImageMean m = render_mean(s, settings(Sampling::Nee, 4, 8, 4));
  EXPECT_NEAR(m.mean, 1 + 0.5 + 0.25 + 0.125 + 0.0625, 1e-5);
  EXPECT_LT(m.sigma, 1e-6);  // deterministic
}

// The icosphere of paper-cornell-ico:L, moved into the furnace in front of the camera
// (the furnace spans [-1, 1]^3, the camera sits at z = 0.5 looking down -z).
Scene furnace_with_sphere(float a, float Le, const Material& sphere) {
  Scene s = make_furnace(a, Le);
  const Scene ico = make_paper_cornell_ico(2);
  const Vec3f centre{0, -4, -4};
  const uint32_t base = uint32_t(s.positions.size());
  for (const Vec3f& p : ico.positions) s.positions.push_back((p - centre) * (0.45f / 5.0f) + Vec3f{0, 0, -0.4f});
  s.materials.push_back(sphere);
  s.material_names.push_back("sphere");
  for (size_t t = 14; t < ico.triangles.size(); ++t) {  // the box's 14 first
    const Triangle& tri = ico.triangles[t];
    s.triangles.push_back({{base + tri.v[0], base + tri.v[1], base + tri.v[2]}});
    s.material_ids.push_back(uint32_t(s.materials.size() - 1));
  }
  s.name = "furnace with a sphere";
  s.finalize();
  return s;
}

TEST(GlassFurnace, GlassSphereDoesNotChangeTheRadiance) {
  Material glass{{1, 1, 1}, {0, 0, 0}, MaterialKind::Dielectric};
  for (float ior : {1.5f, 2.4f, 1 / 1.5f}) {
    glass.ior = ior;
    const Scene scene = furnace_with_sphere(0.5f, 1.0f, glass);
    for (Sampling sampling : {Sampling::Nee, Sampling::Cosine}) {
      const ImageMean m = render_mean(scene, settings(sampling, -1, 16, 256));
      EXPECT_NEAR(m.mean, 2.0, 5 * m.sigma) << "ior " << ior << ", " << to_string(sampling) << ", sigma " << m.sigma;
    }
  }
}

// Negative control: a tinted sphere absorbs, and the test above would see it.
TEST(GlassFurnace, AbsorbingGlassIsDetected) {
  Material glass{{0.8f, 0.8f, 0.8f}, {0, 0, 0}, MaterialKind::Dielectric};
  const Scene scene = furnace_with_sphere(0.5f, 1.0f, glass);
  const ImageMean m = render_mean(scene, settings(Sampling::Nee, -1, 16, 256));
  EXPECT_LT(m.mean, 2.0 - 5 * m.sigma);
}

// Light sampling + MIS against BSDF sampling alone: two estimators of the same image.
// With a rough conductor this checks that the pdf MIS uses is the sampler's; with
// mirrors and glass that light found through a delta bounce is counted exactly once.
TEST(MaterialsRender, LightSamplingAgreesWithBsdfSampling) {
  for (const std::string& v : cornell_box_variants()) {
    const Scene scene = make_cornell_box(v);
    const ImageMean nee = render_mean(scene, settings(Sampling::Nee, 4, 24, 256));
    const ImageMean bsdf = render_mean(scene, settings(Sampling::Cosine, 4, 24, 256));
    const double sigma = std::sqrt(nee.sigma * nee.sigma + bsdf.sigma * bsdf.sigma);
    std::printf("[ means    ] %s: nee %.5f +- %.5f, cosine %.5f +- %.5f\n", scene.name.c_str(), nee.mean, nee.sigma,
                bsdf.mean, bsdf.sigma);
    EXPECT_NEAR(nee.mean, bsdf.mean, 5 * sigma) << scene.name;
  }
}

// Bit-identical films from both CPU strategies on scenes with every material kind.
TEST(MaterialsRender, PixelAndWavefrontBitIdentical) {
  std::vector<std::string> names;
  for (const std::string& v : cornell_box_variants()) names.push_back("cornell-box:" + v);
  names.push_back(kScenes + "materials-example.json");
  for (const std::string& name : names) {
    const Scene scene = load_scene(name);
    for (int bounces : {5, -1}) {
      RenderSettings s = settings(Sampling::Nee, bounces, 32, 8);
      s.progress = false;
      s.strategy = Strategy::Pixel;
      Film a(s.width, s.height, false);
      RunReport ra;
      run::render(scene, s, a, ra);
      s.strategy = Strategy::Wavefront;
      s.paths_in_flight = 1000;  // many refills
      Film b(s.width, s.height, false);
      RunReport rb;
      run::render(scene, s, b, rb);
      EXPECT_TRUE(a.raw_sums() == b.raw_sums()) << name << ", bounces " << bounces;
      EXPECT_TRUE(a.counts() == b.counts()) << name;
      EXPECT_EQ(ra.rays.total(), rb.rays.total()) << name;
      EXPECT_EQ(ra.discarded_samples, 0u) << name;
    }
  }
}

#endif  // PATHBENCH_EXTRA_MATERIALS

// ---- Features and dispatch -------------------------------------------------------------

uint32_t chosen_instantiation(const Scene& s) {
  return with_features(s.features.material_kinds, [](auto kinds) { return decltype(kinds)::value; });
}

TEST(MaterialFeatures, ScenesListTheKindsTheyUse) {
  EXPECT_EQ(make_paper_cornell().features.material_kinds, kDiffuseOnly);
  EXPECT_EQ(make_cornell_box().features.material_kinds, kDiffuseOnly);
  EXPECT_EQ(chosen_instantiation(make_paper_cornell()), kDiffuseOnly);
#if PATHBENCH_EXTRA_MATERIALS
  using K = MaterialKind;
  EXPECT_EQ(make_cornell_box("mirror").features.material_kinds, kind_bit(K::Diffuse) | kind_bit(K::Mirror));
  EXPECT_EQ(make_cornell_box("glass").features.material_kinds, kind_bit(K::Diffuse) | kind_bit(K::Dielectric));
  EXPECT_EQ(make_cornell_box("spheres").features.material_kinds,
            kind_bit(K::Diffuse) | kind_bit(K::Mirror) | kind_bit(K::Dielectric));
  EXPECT_EQ(make_cornell_box("ggx").features.material_kinds, kind_bit(K::Diffuse) | kind_bit(K::RoughConductor));
  EXPECT_EQ(load_scene(kScenes + "materials-example.json").features.material_kinds, kAllMaterialKinds);
  EXPECT_EQ(chosen_instantiation(make_cornell_box("spheres")), kAllMaterialKinds);
  // A material that no triangle uses does not count.
  Scene s = make_paper_cornell();
  s.materials.push_back({{0.5f, 0.5f, 0.5f}, {0, 0, 0}, K::Mirror});
  s.material_names.push_back("unused mirror");
  s.finalize();
  EXPECT_EQ(s.features.material_kinds, kDiffuseOnly);
#endif
}

#if !PATHBENCH_EXTRA_MATERIALS
// The diffuse-only build refuses scenes that need more, naming what is missing.
TEST(MaterialFeatures, DiffuseOnlyBuildRefusesOtherKinds) {
  for (const std::string& v : cornell_box_variants()) {
    try {
      make_cornell_box(v);
      ADD_FAILURE() << v << " loaded in a diffuse-only build";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("PATHBENCH_EXTRA_MATERIALS=OFF"), std::string::npos) << e.what();
    }
  }
}
#endif

// ---- Scene files -------------------------------------------------------------------

#if PATHBENCH_EXTRA_MATERIALS
TEST(MaterialFiles, ExampleHasEveryKind) {
  const Scene s = load_scene(kScenes + "materials-example.json");
  auto named = [&](const char* n) {
    for (size_t i = 0; i < s.material_names.size(); ++i)
      if (s.material_names[i] == n) return s.materials[i];
    ADD_FAILURE() << "no material " << n;
    return Material{};
  };
  EXPECT_EQ(named("white").kind, MaterialKind::Diffuse);
  EXPECT_EQ(named("glass").kind, MaterialKind::Dielectric);
  EXPECT_EQ(named("glass").ior, 1.5f);
  EXPECT_EQ(named("glass").albedo.x, 1.0f);  // white by default
  EXPECT_EQ(named("mirror").kind, MaterialKind::Mirror);
  EXPECT_EQ(named("mirror").albedo.y, 0.95f);
  EXPECT_EQ(named("gold").kind, MaterialKind::RoughConductor);
  EXPECT_EQ(named("gold").alpha, 0.25f);
}
#endif

std::string error_for_material(const std::string& material_json) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("pathbench-material-" + std::to_string(::getpid()) + ".json")).string();
  {
    std::ofstream f(path);
    f << R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov_y_deg": 40},
             "materials": {"m": )"
      << material_json << R"(},
             "triangles": [{"material": "m", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]]}]})";
  }
  std::string what;
  try {
    load_scene(path);
  } catch (const InputError& e) {
    what = e.what();
  }
  std::filesystem::remove(path);
  return what;
}

TEST(MaterialFiles, BadValuesAreClearErrors) {
  struct Case {
    const char* json;
    std::vector<const char*> expect;
  };
  const Case cases[] = {
      {R"({"kind": "plastic"})", {"materials.m.kind", "unknown material kind 'plastic'", "roughconductor"}},
      {R"({"kind": 2})", {"materials.m.kind", "expected a string"}},
      {R"({"kind": "dielectric", "ior": 0})", {"materials.m.ior", "must be above 0"}},
      {R"({"kind": "dielectric", "ior": -1.5})", {"materials.m.ior", "must be above 0"}},
      {R"({"kind": "dielectric", "ior": "glass"})", {"materials.m.ior", "expected a number"}},
      {R"({"kind": "roughconductor", "alpha": 0})", {"materials.m.alpha", "out of range", "mirror"}},
      {R"({"kind": "roughconductor", "alpha": 1.5})", {"materials.m.alpha", "out of range"}},
      {R"({"kind": "mirror", "ior": 1.5})", {"materials.m.ior", "only to materials of kind \"dielectric\""}},
      {R"({"albedo": [0.5, 0.5, 0.5], "alpha": 0.3})", {"materials.m.alpha", "roughconductor"}},
      {R"({"kind": "mirror", "albedo": [1.5, 1, 1]})", {"albedo above 1"}},
  };
  for (const Case& c : cases) {
    const std::string what = error_for_material(c.json);
    ASSERT_FALSE(what.empty()) << c.json << " was accepted";
    for (const char* e : c.expect) EXPECT_NE(what.find(e), std::string::npos) << c.json << ": " << what;
  }
  // And good ones load (in a diffuse-only build, only the diffuse one).
  EXPECT_EQ(error_for_material(R"({"kind": "diffuse", "albedo": [0.5, 0.5, 0.5]})"), "");
#if PATHBENCH_EXTRA_MATERIALS
  EXPECT_EQ(error_for_material(R"({"kind": "dielectric", "ior": 1.33})"), "");
  EXPECT_EQ(error_for_material(R"({"kind": "roughconductor", "alpha": 1})"), "");
#else
  EXPECT_NE(error_for_material(R"({"kind": "mirror"})").find("PATHBENCH_EXTRA_MATERIALS=OFF"), std::string::npos);
#endif
}

}  // namespace
}  // namespace pb
