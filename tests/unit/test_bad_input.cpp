// Bad input: every case is one InputError whose message names the file (or option)
// and what is wrong. Fixtures: tests/data/scenes/ (one problem per file).
// tests/cli runs the same cases through the `pathbench` binary (exit status 2).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <ostream>
#include <vector>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/run.h"

namespace pb {
namespace {

const std::string kData = std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/scenes/";

// Runs `f`, expects an InputError whose message contains every one of `parts`.
void expect_input_error(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
    return;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return;
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
}
void expect_scene_error(const std::string& spec, const std::vector<std::string>& parts) {
  expect_input_error([&] { load_scene(spec); }, parts);
}

// Scene files (fixtures named after their one problem) and built-in names: load_scene
// must throw an InputError whose message has every one of `parts`.
struct BadScene {
  const char* test;
  std::string spec;  // a file under tests/data/scenes/ (kData + name), or a built-in spec
  std::vector<std::string> parts;
};
std::ostream& operator<<(std::ostream& os, const BadScene& c) { return os << c.spec; }

class BadSceneSpec : public ::testing::TestWithParam<BadScene> {};

TEST_P(BadSceneSpec, IsOneInputErrorSayingWhatIsWrong) {
  const BadScene& c = GetParam();
  testing::internal::CaptureStderr();  // e.g. the zero-area warning before the error
  expect_scene_error(c.spec, c.parts);
  testing::internal::GetCapturedStderr();
}

INSTANTIATE_TEST_SUITE_P(
    Files, BadSceneSpec,
    ::testing::Values(
        BadScene{"MissingFile", kData + "no-such-scene.json", {"no-such-scene.json", "no such file"}},
        BadScene{"MissingObjFile", kData + "no-such-mesh.obj", {"no-such-mesh.obj", "no such file"}},
        BadScene{"TruncatedJson", kData + "truncated.json", {"truncated.json", "malformed JSON", "unexpected end of input"}},
        BadScene{"MalformedJson", kData + "malformed.json", {"malformed.json", "malformed JSON", "line 1"}},
        BadScene{"MalformedObj", kData + "malformed.obj", {"malformed.obj:3:", "'one' is not a number"}},
        BadScene{"JsonWrongType", kData + "wrong-type.json", {"wrong-type.json", "camera.position", "expected an array of 3 numbers"}},
        BadScene{"JsonMissingField", kData + "missing-field.json", {"missing-field.json", "camera.look_at", "missing"}},
        BadScene{"JsonUnknownKey", kData + "unknown-key.json", {"unknown-key.json", "camera.fov", "unknown key", "fov_y_deg"}},
        BadScene{"JsonFractionalIndex", kData + "float-index.json",
                 {"float-index.json", "triangles[0].indices[0][2]", "whole number", "got number 2.5"}},
        BadScene{"JsonInfiniteCoordinate", kData + "nan.json", {"nan.json", "triangles[0].vertices[1][0]", "not a finite number"}},
        BadScene{"JsonNumberOverflow", kData + "overflow.json", {"overflow.json", "malformed JSON", "number overflow parsing '1e999'"}},
        BadScene{"ObjNanCoordinate", kData + "nan.obj", {"nan.obj:2:", "NaN or infinite"}},
        BadScene{"JsonVertexIndexOutOfRange", kData + "bad-index.json",
                 {"bad-index.json", "triangles[0].indices[1][2]", "vertex index 5 is out of range"}},
        BadScene{"ObjVertexIndexOutOfRange", kData + "bad-index.obj", {"bad-index.obj:4:", "vertex 7", "only 3 vertices"}},
        BadScene{"JsonUnknownMaterial", kData + "unknown-material.json",
                 {"unknown-material.json", "triangles[0].material", "unknown material 'blue'"}},
        BadScene{"ObjUnknownMaterial", kData + "unknown-material.obj", {"unknown-material.obj:5:", "usemtl 'nosuch'"}},
        BadScene{"ObjMissingMaterialLibrary", kData + "missing-mtl.obj", {"missing-mtl.obj:1:", "no-such.mtl", "not found"}},
        BadScene{"JsonMissingMeshFile", kData + "missing-mesh.json",
                 {"missing-mesh.json", "meshes[0].file", "no-such-mesh.obj", "no such file"}},
        BadScene{"OnlyZeroAreaTriangles", kData + "all-zero-area.json", {"all-zero-area.json", "every triangle has zero area"}},
        BadScene{"UnknownFileType", kData + "README.md", {"README.md", "unknown scene file type"}}),
    [](const auto& info) { return std::string(info.param.test); });

INSTANTIATE_TEST_SUITE_P(
    BuiltinNames, BadSceneSpec,
    ::testing::Values(
        BadScene{"UnknownName", "cornell-bx", {"unknown scene 'cornell-bx'", "cornell-box"}},
        BadScene{"IcoLevelNotANumber", "paper-cornell-ico:x", {"paper-cornell-ico:x", "'x' is not a number"}},
        BadScene{"IcoLevelOutOfRange", "paper-cornell-ico:99", {"paper-cornell-ico:99", "out of range", "0 to 10"}},
        BadScene{"IcoLevelNegative", "paper-cornell-ico:-1", {"out of range"}},
        BadScene{"IcoLevelNotWhole", "paper-cornell-ico:1.5", {"whole number"}},
        BadScene{"IcoTooManyParameters", "paper-cornell-ico:1,2", {"at most 1 parameter"}},
        BadScene{"IcoLevelMissing", "paper-cornell-ico", {"needs a parameter", "level"}},
        BadScene{"ScalingTooFew", "scaling:5", {"scaling:5", "out of range", "10 to 10000000"}},
        BadScene{"ScalingTooMany", "scaling:2e7", {"out of range"}},
        BadScene{"ScalingNotANumber", "scaling:many", {"'many' is not a number"}},
        BadScene{"ParameterToAFixedScene", "paper-cornell:2", {"paper-cornell", "takes no parameters"}},
        BadScene{"CornellBoxUnknownVariant", "cornell-box:2", {"cornell-box:2", "unknown variant", "mirror, glass"}},
        BadScene{"CornellBoxEmptyVariant", "cornell-box:", {"give a variant"}}),
    [](const auto& info) { return std::string(info.param.test); });

// Scenes built in code: finalize() checks what the loaders cannot express.
Scene one_triangle() {
  Scene s;
  s.name = "test-scene";
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.triangles = {{{0, 1, 2}}};
  s.material_ids = {0};
  s.materials = {{{0.5f, 0.5f, 0.5f}, {1, 1, 1}}};
  s.material_names = {"grey"};
  s.camera = Camera::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 40);
  return s;
}
TEST(BadScene, MaterialIndexOutOfRange) {
  Scene s = one_triangle();
  s.material_ids[0] = 3;
  expect_input_error([&] { s.finalize(); }, {"test-scene", "triangle 0 refers to material 3"});
}
TEST(BadScene, VertexIndexOutOfRange) {
  Scene s = one_triangle();
  s.triangles[0].v[2] = 9;
  expect_input_error([&] { s.finalize(); }, {"test-scene", "refers to vertex 9"});
}
TEST(BadScene, NanVertex) {
  Scene s = one_triangle();
  s.positions[1].y = std::numeric_limits<float>::quiet_NaN();
  expect_input_error([&] { s.finalize(); }, {"test-scene", "vertex 1", "NaN"});
}

// Impossible settings (the CLI turns these strings and numbers into RenderSettings).
TEST(BadSettings, ZeroSpp) {
  RenderSettings s;
  s.spp = 0;
  expect_input_error([&] { s.validate(); }, {"--spp"});
}
TEST(BadSettings, ZeroWidth) {
  RenderSettings s;
  s.width = 0;
  expect_input_error([&] { s.validate(); }, {"--width"});
}
TEST(BadSettings, UnknownStrategy) { expect_input_error([] { parse_strategy("fastest"); }, {"--strategy", "'fastest'"}); }
TEST(BadSettings, UnknownSampling) { expect_input_error([] { parse_sampling("importance"); }, {"--sampling", "'importance'"}); }
TEST(BadSettings, UnknownDevice) { expect_input_error([] { parse_device("tpu"); }, {"--device", "'tpu'"}); }
TEST(BadSettings, UnknownEmbreeLayout) {
  expect_input_error([] { parse_embree_layout("octagons"); }, {"--embree-layout", "'octagons'"});
}

// apply_choices: the one path from named options to settings, for the CLI and the Python module.
TEST(Settings, ApplyChoicesParsesEveryNameAndConverged) {
  RenderSettings s;
  RenderChoices c{"cosine", "wavefront", "cpu", "double", "quads", "avx2", true};
  apply_choices(c, s);
  EXPECT_EQ(s.sampling, Sampling::Cosine);
  EXPECT_EQ(s.strategy, Strategy::Wavefront);
  EXPECT_EQ(s.precision, Precision::Double);
  EXPECT_EQ(s.embree_layout, EmbreeLayout::Quads);
  EXPECT_EQ(s.isa, Isa::Avx2);
  EXPECT_EQ(s.max_bounces, -1);
  EXPECT_TRUE(s.russian_roulette);
}
TEST(BadSettings, ApplyChoicesRefusesUnknownNames) {
  RenderSettings s;
  RenderChoices c;
  c.precision = "half";
  expect_input_error([&] { apply_choices(c, s); }, {"--precision", "'half'"});
}
// Settings are validated once, by the run layer, before any film is sized.
TEST(BadSettings, RunRenderValidatesOnce) {
  RenderSettings s;
  s.spp = 0;
  const Scene scene = load_scene("paper-cornell");
  Film film(1, 1, false);
  RunReport report;
  expect_input_error([&] { run::render(scene, s, film, report); }, {"--spp"});
  EXPECT_EQ(film.width(), 1u);  // untouched: refused before the film was sized
}

// What each device's tracer runs: validate_for_tracer, the one place of these checks (they
// were in cpu/src/render.cpp and gpu/src/render.cu), with the messages they had there.
TEST(BadSettings, TracerLimitsPaperQueueIsGpuOnly) {
  RenderSettings s;
  s.strategy = Strategy::PaperQueue;
  expect_input_error([&] { validate_for_tracer(s, Device::Cpu); },
                     {"--strategy paper-queue", "a GPU strategy; the CPU runs pixel or wavefront"});
  EXPECT_NO_THROW(validate_for_tracer(s, Device::Gpu));
}
// The GPU's wavefront state is float4 arrays, traced with the watertight test: double
// precision and Moeller-Trumbore run there with --strategy pixel only (on the CPU with any).
TEST(BadSettings, TracerLimitsGpuVariantsWithPixelOnly) {
  struct Variant {
    void (*ask)(RenderSettings&);
    std::vector<std::string> message;
  };
  const Variant variants[] = {
      {[](RenderSettings& s) { s.precision = Precision::Double; },
       {"--precision double", "the GPU runs double precision with --strategy pixel only"}},
      {[](RenderSettings& s) { s.watertight = false; },
       {"--no-watertight", "Moeller-Trumbore triangle test with --strategy pixel only"}}};
  for (const Variant& v : variants) {
    RenderSettings s;
    v.ask(s);
    for (Strategy st : {Strategy::Wavefront, Strategy::PaperQueue}) {
      s.strategy = st;
      expect_input_error([&] { validate_for_tracer(s, Device::Gpu); }, v.message);
    }
    s.strategy = Strategy::Wavefront;
    EXPECT_NO_THROW(validate_for_tracer(s, Device::Cpu));
    s.strategy = Strategy::Pixel;
    EXPECT_NO_THROW(validate_for_tracer(s, Device::Gpu));
  }
}
// The run layer applies them before the tracer builds anything or the film is sized.
TEST(BadSettings, RunRenderRefusesPaperQueueOnCpuBeforeTheFilm) {
  RenderSettings s;
  s.strategy = Strategy::PaperQueue;
  s.width = s.height = 4;
  const Scene scene = load_scene("paper-cornell");
  Film film(1, 1, false);
  RunReport report;
  expect_input_error([&] { run::render(scene, s, film, report); }, {"--strategy paper-queue", "GPU strategy"});
  EXPECT_EQ(film.width(), 1u);  // untouched: refused before the film was sized
}

}  // namespace
}  // namespace pb
