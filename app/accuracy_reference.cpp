#include "accuracy_reference.h"

#include <fmt/core.h>

#include <filesystem>
#include <fstream>

#include "pathbench/output/output_file.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/film.h"
#include "pathbench/output/image_io.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/common/report.h"
#include "pathbench/run/ranks_render.h"
#include "pathbench/run/run.h"
#include "pathbench/run/world.h"

namespace pb::app {

namespace fs = std::filesystem;

namespace {
// A seed no sweep render uses, so the reference's noise is independent of theirs.
constexpr uint64_t kReferenceSeed = 0x7265666572656e63ull;  // "referenc"

std::string stem_of(const Scene& scene, const RenderSettings& s) {
  return fmt::format("reference-{}-{}x{}-{}-{}spp-v{}", slugify(scene.name, "scene"), s.width, s.height, to_string(s.device),
                     s.spp, kReferenceVersion);
}

bool try_load(const std::string& dir, const std::string& stem, const RenderSettings& s, Reference& ref) {
  const fs::path json = fs::path(dir) / (stem + ".json");
  if (!fs::exists(json) || !fs::exists(fs::path(dir) / (stem + ".pfm")) || !fs::exists(fs::path(dir) / (stem + "-var.pfm")))
    return false;
  std::ifstream in(json);
  nlohmann::json info = nlohmann::json::parse(in, nullptr, false);
  if (info.is_discarded() || info.value("version", -1) != kReferenceVersion) return false;
  unsigned w = 0, h = 0, vw = 0, vh = 0;
  ref.mean = read_image((fs::path(dir) / (stem + ".pfm")).string(), w, h);
  ref.var = read_image((fs::path(dir) / (stem + "-var.pfm")).string(), vw, vh);
  if (w != s.width || h != s.height || vw != w || vh != h) return false;
  ref.info = info;
  ref.info["cached"] = true;
  return true;
}
}  // namespace

bool render_unless_gpu_refuses(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report,
                               std::string& refusal, bool all_ranks) {
  try {
    if (all_ranks) run::render_ranks(scene, s, film, report);
    else run::render(scene, s, film, report);
    return true;
  } catch (const InputError& e) {
    if (s.device != Device::Gpu) throw;
    refusal = e.what();
    return false;
  } catch (const run::PeerFailure& e) {  // another rank's GPU refused (rank 0 has the message)
    if (s.device != Device::Gpu || e.code != kExitBadInput) throw;
    refusal = e.what();
    return false;
  }
}

RenderSettings reference_settings(const RenderSettings& base, uint32_t spp) {
  RenderSettings s = base;
  s.spp = spp;
  s.max_bounces = -1;
  s.russian_roulette = true;
  s.sampling = Sampling::Nee;
  s.watertight = true;
  s.precision = Precision::Double;
  s.seed = kReferenceSeed;
  s.variance = true;
  return s;
}

Reference load_or_render_reference(const Scene& scene, const RenderSettings& base, uint32_t spp,
                                   const std::string& dir, bool regenerate, bool progress) {
  RenderSettings s = reference_settings(base, spp);
  s.progress = progress;
  const std::string stem = stem_of(scene, s);
  Reference ref;
  run::World& world = run::World::get();
  bool cached = !regenerate && try_load(dir, stem, s, ref);
  if (world.size() > 1) cached = world.all(cached ? "cached" : "")[0] == "cached";  // rank 0's cache decides
  if (cached) return ref;

  Film film(s.width, s.height, true);
  RunReport report;
  std::string refusal;
  if (!render_unless_gpu_refuses(scene, s, film, report, refusal, true)) {
    // A GPU tracer without double precision: the best it has.
    if (world.root())
      fmt::print(stderr, "accuracy: reference in double refused by the GPU ({}); rendering it in float\n", refusal);
    s.precision = Precision::Float;
    film = Film(s.width, s.height, true);
    run::render_ranks(scene, s, film, report);
  }
  if (!world.root()) return ref;  // rank 0 holds the reference
  ref.mean = film.mean();
  ref.var = film.variance_of_mean();
  fs::create_directories(dir);
  write_image((fs::path(dir) / (stem + ".pfm")).string(), ref.mean, s.width, s.height);
  write_image((fs::path(dir) / (stem + "-var.pfm")).string(), ref.var, s.width, s.height);
  ref.info = {{"version", kReferenceVersion},
              {"file", stem + ".pfm"},
              {"variance_file", stem + "-var.pfm"},
              {"seconds", run::render_seconds(report)},
              {"report", report.to_json()}};
  write_text_file((fs::path(dir) / (stem + ".json")).string(), ref.info.dump(2) + "\n");
  ref.info["cached"] = false;
  return ref;
}

}  // namespace pb::app
