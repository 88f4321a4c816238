#include "accuracy_command.h"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "accuracy_reference.h"
#include "pathbench/run/world.h"
#include "cli_checks.h"
#include "output_dirs.h"
#include "python_tools.h"
#include "pathbench/analysis/accuracy_metrics.h"
#include "pathbench/output/output_file.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/output/image_io.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"
#include "pathbench/run/run_context.h"


namespace pb::app {

using namespace pb::analysis;  // the error metrics this command reports

namespace fs = std::filesystem;

namespace {

// One point of the sweep. `groups` names the comparisons it belongs to (a plot panel
// and a table section each); the baseline, the converged estimator, is in all of them.
struct Config {
  std::string name, label;
  std::vector<std::string> groups;
  int32_t bounces;  // -1: unbounded
  Sampling sampling;
  bool russian_roulette;
  Precision precision;
  bool watertight;  // CPU: Embree's robust mode (Pluecker test) vs its fast mode (Moeller-Trumbore);
                    // GPU: Woop et al.'s watertight test vs Moeller-Trumbore
};

std::vector<Config> sweep_configs() {
  const auto F = Precision::Float, D = Precision::Double;
  const auto nee = Sampling::Nee;
  return {
      {"baseline", "nee, unbounded + RR, float, watertight",
       {"bounces", "sampling", "roulette", "precision", "intersection"}, -1, nee, true, F, true},
      {"bounces-1", "nee, 1 bounce", {"bounces"}, 1, nee, false, F, true},
      {"bounces-2", "nee, 2 bounces", {"bounces"}, 2, nee, false, F, true},
      {"bounces-4", "nee, 4 bounces", {"bounces"}, 4, nee, false, F, true},
      {"bounces-8", "nee, 8 bounces, no RR", {"bounces", "roulette"}, 8, nee, false, F, true},
      {"bounces-8-rr", "nee, 8 bounces + RR", {"roulette"}, 8, nee, true, F, true},
      {"uniform", "uniform hemisphere (the paper's), unbounded + RR", {"sampling"}, -1, Sampling::Uniform, true, F, true},
      {"cosine", "cosine hemisphere, unbounded + RR", {"sampling"}, -1, Sampling::Cosine, true, F, true},
      {"double", "double precision path step", {"precision"}, -1, nee, true, D, true},
      {"moller-trumbore", "Moeller-Trumbore, the paper's test (CPU: Embree's fast mode)", {"intersection"}, -1, nee, true, F, false},
      {"paper", "the paper's: uniform, 2 bounces, Moeller-Trumbore", {"paper"}, 2, Sampling::Uniform, false, F, false},
  };
}

std::vector<Config> selected_configs(const std::string& list) {
  std::vector<Config> all = sweep_configs();
  if (list.empty()) return all;
  std::vector<Config> out;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    bool found = false;
    for (const Config& c : all)
      if (c.name == name) {
        out.push_back(c);
        found = true;
      }
    if (!found) {
      std::string names;
      for (const Config& c : all) names += (names.empty() ? "" : ", ") + c.name;
      throw InputError(fmt::format("--configs: unknown configuration '{}' (expected some of: {})", name, names));
    }
  }
  return out;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json config_json(const Config& c) {
  return {{"name", c.name},
          {"label", c.label},
          {"groups", c.groups},
          {"bounces", c.bounces < 0 ? nlohmann::json("unbounded") : nlohmann::json(c.bounces)},
          {"sampling", to_string(c.sampling)},
          {"russian_roulette", c.russian_roulette},
          {"precision", to_string(c.precision)},
          {"intersection", c.watertight ? "watertight" : "moller-trumbore"}};
}

// Quick mode shrinks whatever the user left at its default.
void apply_quick(AccuracyOptions& o) {
  const AccuracyOptions d;
  if (o.width == d.width) o.width = 32;
  if (o.height == d.height) o.height = 32;
  if (o.reference_spp == d.reference_spp) o.reference_spp = 256;
  if (o.max_spp == d.max_spp) o.max_spp = 16;
  if (o.max_seconds == d.max_seconds) o.max_seconds = 5;
}

void validate(const AccuracyOptions& o) {
  check_image_size(o.width, o.height, true);  // >= 1x1, the pixel limit, the film in memory
  if (o.max_spp == 0) throw InputError("--max-spp: must be at least 1");
  if (o.reference_spp < 2) throw InputError("--reference-spp: must be at least 2 (the reference needs a variance)");
  if (o.reference_spp <= o.max_spp)
    throw InputError(fmt::format("--reference-spp {}: must be more than --max-spp {} (the reference must be less noisy "
                                 "than every image judged against it)",
                                 o.reference_spp, o.max_spp));
  if (!(o.max_seconds > 0) || !std::isfinite(o.max_seconds))
    throw InputError(fmt::format("--max-seconds: must be a positive number of seconds (got {})", o.max_seconds));
  if (o.threads < 0) throw InputError("--threads: must be >= 0 (0 = all)");
}

// tools/accuracy_report.py through the one Python launcher.
enum class ToolRun { Done, Failed, Unavailable };
ToolRun run_report_tool(const std::string& json_path, std::string& command) {
  command = fmt::format("{} {}/accuracy_report.py '{}'", find_python(), find_python_tools(), json_path);
  if (find_python_tools().empty()) return ToolRun::Unavailable;
  const int status = run_python_tool({"accuracy", "accuracy_report.py", {"numpy", "matplotlib"}}, {json_path}, true);
  return status == 0 ? ToolRun::Done : status == kPythonToolMissing ? ToolRun::Unavailable : ToolRun::Failed;
}

}  // namespace

void add_accuracy_options(CLI::App& cmd, AccuracyOptions& o) {
  cmd.add_option("--scene", o.scene, "built-in scene name or a .json / .obj file")->capture_default_str();
  cmd.add_option("--device", o.device, "cpu or gpu")->capture_default_str();
  cmd.add_option("--strategy", o.strategy, "pixel or wavefront (GPU also paper-queue)")->capture_default_str();
  cmd.add_option("--width", o.width, "image width")->check(non_negative())->capture_default_str();
  cmd.add_option("--height", o.height, "image height")->check(non_negative())->capture_default_str();
  cmd.add_option("--reference-spp", o.reference_spp, "samples per pixel of the converged reference")->check(non_negative())->capture_default_str();
  cmd.add_option("--max-spp", o.max_spp, "last rung of each configuration's spp ladder (1, 4, 16, ...) at most")
      ->check(non_negative())->capture_default_str();
  cmd.add_option("--max-seconds", o.max_seconds,
                 "a configuration's ladder stops before a render expected to take longer than this")
      ->capture_default_str();
  cmd.add_option("--configs", o.configs, "comma-separated configuration names (default: all)");
  cmd.add_option("--out-dir", o.out_dir, "output folder (default pathbench-out/<machine>/accuracy; the reference is cached there)");
  cmd.add_flag("--update-committed", o.update_committed,
               "maintainers: write into the committed results/<machine>/accuracy/ instead of pathbench-out/");
  cmd.add_option("--seed", o.seed, "random seed of the sweep renders")->check(non_negative())->capture_default_str();
  cmd.add_option("--threads", o.threads, "CPU threads (0: all)")->capture_default_str();
  cmd.add_flag("--quick", o.quick, "smoke test: 32x32, reference 256 spp, ladder up to 16 spp (unless given)");
  cmd.add_flag("--regenerate-reference", o.regenerate_reference, "render the reference even if it is cached");
  cmd.add_flag("--no-report-tool", o.no_report_tool, "skip tools/accuracy_report.py (FLIP, table, plots)");
}

int run_accuracy(AccuracyOptions& o) {
  if (o.quick) apply_quick(o);
  validate(o);
  RenderSettings base;
  base.device = parse_device(o.device);
  base.strategy = parse_strategy(o.strategy);
  base.width = o.width;
  base.height = o.height;
  base.threads = o.threads;
  base.seed = o.seed;
  base.variance = true;  // for the bias's standard error
  base.progress = false;
  const std::vector<Config> configs = selected_configs(o.configs);
  if (base.device == Device::Gpu) {
    std::string why;
    if (!run::gpu_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
  }
  const Scene scene = load_scene(o.scene);
  const std::string dir = output_dir(o.out_dir, o.update_committed, run::machine_folder(base.device), "accuracy");
  const std::string stem = fmt::format("{}-{}x{}-{}", slugify(scene.name, "scene"), o.width, o.height, to_string(base.device));
  const std::string image_dir = "images/" + stem;
  check_output_path((fs::path(dir) / (stem + ".json")).string(), "--out-dir");  // before the sweep
  fs::create_directories(fs::path(dir) / image_dir);
  // Per-render images are for the report tool (FLIP), not for the repository.
  write_text_file((fs::path(dir) / "images" / ".gitignore").string(), "*\n");

  nlohmann::json out;
  out["scene"] = scene.name;
  out["triangles"] = scene.triangles.size();
  out["width"] = o.width;
  out["height"] = o.height;
  out["device"] = to_string(base.device);
  out["strategy"] = to_string(base.strategy);
  out["seed"] = o.seed;
  out["date"] = utc_now();
  out["git_revision"] = git_revision();
  out["compiler"] = compiler_id();
  out["machine"] = {{"slug", run::machine_folder(base.device)}, {"cpu", cpu_model()}, {"hardware_threads", hardware_threads()}};
  out["load_average_at_start"] = load_average();
  out["fingerprint"] = run::run_fingerprint(base.device == Device::Gpu);
  out["ladder"] = {{"max_spp", o.max_spp}, {"max_seconds", o.max_seconds}, {"factor", 4}};
  out["metrics"] = {
      {"rmse", "sqrt(mean over pixel-channels of (x - ref)^2)"},
      {"rel_mse", fmt::format("mean over pixel-channels of (x - ref)^2 / (ref^2 + eps), eps = {}", kRelMseEpsilon)},
      {"rel_mse_eps", kRelMseEpsilon},
      {"bias", "(mean(x) - mean(ref)) / mean(ref) over all pixel-channels; bias_stderr from both variance images "
               "(channels of a pixel taken as fully correlated: an upper bound); none at 1 spp (no variance)"},
      {"bias_z_threshold", kBiasZThreshold},
      {"efficiency", "1 / (rel_mse x seconds)"},
      {"seconds", base.device == Device::Gpu ? "CUDA-event render time" : "host wall clock of the render (after the Embree build)"}};

  fmt::print(stderr, "accuracy: {} {}x{} on {}, {} configurations; output {}\n", scene.name, o.width, o.height,
             to_string(base.device), configs.size(), dir);
  const auto t_ref = std::chrono::steady_clock::now();
  const Reference ref = load_or_render_reference(scene, base, o.reference_spp, dir, o.regenerate_reference, true);
  if (!run::World::get().root()) return 0;  // MPI: the ranks rendered the reference; the sweep is rank 0's
  const double floor = rel_mse_floor(ref.mean, ref.var);
  out["reference"] = ref.info;
  out["reference"]["spp"] = o.reference_spp;
  out["reference"]["rel_mse_floor"] = floor;
  out["reference"]["precision"] = ref.info["report"].value("precision", "double");
  out["reference"].erase("report");
  fmt::print(stderr, "accuracy: reference {} spp {} ({:.1f} s); its own relMSE floor {:.3g}\n", o.reference_spp,
             ref.info.value("cached", false) ? "from the cache" : "rendered",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ref).count(), floor);

  nlohmann::json rows = nlohmann::json::array(), cfg_json = nlohmann::json::array(), skipped = nlohmann::json::array();
  for (const Config& c : configs) cfg_json.push_back(config_json(c));
  // Rungs outermost, configurations inside: on a shared machine the load changes during
  // the run, and this way a change touches one rung of every configuration alike rather
  // than the whole ladder of a few.
  std::vector<bool> climbing(configs.size(), true);
  for (uint64_t spp = 1; spp <= o.max_spp; spp *= 4) {
    for (size_t k = 0; k < configs.size(); ++k) {
      if (!climbing[k]) continue;
      const Config& c = configs[k];
      RenderSettings s = base;
      s.max_bounces = c.bounces;
      s.sampling = c.sampling;
      s.russian_roulette = c.russian_roulette;
      s.precision = c.precision;
      s.watertight = c.watertight;
      s.spp = uint32_t(spp);
      Film film(s.width, s.height, true);
      RunReport report;
      std::string refusal;
      if (!render_unless_gpu_refuses(scene, s, film, report, refusal)) {
        // The GPU may not run every configuration (e.g. double precision): a note, not a failure.
        fmt::print(stderr, "accuracy: [{}/{}] {}: skipped, the GPU refuses it: {}\n", k + 1, configs.size(), c.name,
                   refusal);
        skipped.push_back({{"config", c.name}, {"reason", refusal}});
        climbing[k] = false;
        continue;
      }
      if (!out["machine"].contains("threads")) {  // what ran the sweep: CPU threads, or the GPU
        out["machine"]["threads"] = report.threads;
        if (report.extra.contains("gpu")) out["machine"]["gpu"] = report.extra["gpu"];
      }
      const std::vector<float> img = film.mean(), var = film.variance_of_mean();
      const double secs = run::render_seconds(report);
      const ImageError err = image_error(img, ref.mean);
      // At 1 spp the film has no variance estimate, so no standard error either.
      const Bias bias = relative_bias(img, spp >= 2 ? var : std::vector<float>{}, ref.mean, ref.var);
      const std::string image = fmt::format("{}/{}-{}spp.pfm", image_dir, c.name, spp);
      write_image((fs::path(dir) / image).string(), img, s.width, s.height);
      const bool has_var = spp >= 2;
      rows.push_back({{"config", c.name},
                      {"spp", spp},
                      {"seconds", secs},
                      {"rays", report.rays.total()},
                      {"rays_per_second", secs > 0 ? double(report.rays.total()) / secs : 0.0},
                      {"rmse", err.rmse},
                      {"rel_mse", err.rel_mse},
                      {"bias", bias.relative},
                      {"bias_stderr", has_var ? nlohmann::json(bias.std_error) : nlohmann::json(nullptr)},
                      {"bias_z", has_var ? finite_or_null(bias.z()) : nlohmann::json(nullptr)},
                      {"biased", has_var ? nlohmann::json(std::fabs(bias.z()) > kBiasZThreshold) : nlohmann::json(nullptr)},
                      {"efficiency", finite_or_null(efficiency(err.rel_mse, secs))},
                      {"discarded_samples", report.discarded_samples},
                      {"state_bytes_per_path", report.state_bytes_per_path},
                      {"image", image}});
      fmt::print(stderr, "accuracy: [{}/{}] {:<16} {:>5} spp {:8.3f} s  relMSE {:.3e}  bias {:+.3f}%{}\n", k + 1,
                 configs.size(), c.name, spp, secs, err.rel_mse, 100 * bias.relative,
                 has_var ? fmt::format(" +- {:.3f}%", 100 * bias.std_error) : std::string());
      if (secs * 4 > o.max_seconds) climbing[k] = false;  // its next rung would take about 4x as long
    }
  }
  out["configurations"] = cfg_json;
  out["rows"] = rows;
  out["skipped"] = skipped;
  out["load_average_at_end"] = load_average();
  const std::string json_path = (fs::path(dir) / (stem + ".json")).string();
  write_text_file(json_path, out.dump(2) + "\n");
  fmt::print("accuracy: {} rows written to {}\n", rows.size(), json_path);

  if (o.no_report_tool) return 0;
  std::string command;
  switch (run_report_tool(json_path, command)) {
    case ToolRun::Done: return 0;
    case ToolRun::Failed: fmt::print(stderr, "accuracy: the report tool failed: {}\n", command); return kExitFailed;
    case ToolRun::Unavailable: break;
  }
  fmt::print(stderr,
             "accuracy: FLIP, the table and the plots were not made (no Python with numpy and matplotlib, or no "
             "pathbench tools: set PATHBENCH_PYTHON; scripts/install-deps.sh makes the tree's .venv); then run: {}\n",
             command);
  return 0;
}

}  // namespace pb::app
