#include "render_command.h"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <utility>
#include <vector>

#include "cli_checks.h"
#include "pathbench/common/display_text.h"
#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/common/report.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/ranks_render.h"
#include "pathbench/run/run.h"
#include "version.h"

namespace pb::app {

void add_render_options(CLI::App& cmd, RenderOptions& o) {
  cmd.add_option("--scene", o.scene, "built-in scene name or a scene file: .json, .obj, .ply, .off, .gltf, .glb, Mitsuba 3 .xml")
      ->capture_default_str();
  cmd.add_flag("--strict", o.strict,
               "fail (exit 2) when the scene file holds what pathbench does not model (textures, other BSDFs or "
               "lights), instead of a warning");
  o.given.width = cmd.add_option("--width", o.settings.width, "image width in pixels")->check(non_negative())->capture_default_str();
  o.given.height = cmd.add_option("--height", o.settings.height, "image height in pixels")->check(non_negative())->capture_default_str();
  o.given.spp = cmd.add_option("--spp", o.settings.spp, "samples per pixel")->check(non_negative())->capture_default_str();
  auto* b = cmd.add_option("--bounces", o.settings.max_bounces, "diffuse bounces (the paper: 2)")->capture_default_str();
  o.given.bounces = b;
  o.given.converged =
      cmd.add_flag("--converged", o.choices.converged, "unbounded path length, ended by Russian roulette")->excludes(b);
  cmd.add_flag("--rr,!--no-rr", o.settings.russian_roulette, "Russian roulette (default: only with --converged)");
  cmd.add_flag("--watertight,!--no-watertight", o.settings.watertight,
               "watertight ray/triangle test (default on; off is faster on the CPU and can leak at edges)");
  cmd.add_option("--precision", o.choices.precision,
                 "scalar type of the path step: float or double (the hit triangle is found in float either way)")
      ->capture_default_str();
  cmd.add_option("--embree-layout", o.choices.embree_layout,
                 "CPU: triangles to Embree as they are, paired into quads, or auto (measured per scene)")
      ->capture_default_str();
  cmd.add_option("--instancing", o.choices.instancing,
                 "acceleration structure from the scene's instances (CPU: Embree instances, GPU: a two-level BVH): "
                 "auto (GPU: where the scene has instances; CPU: flat), on, or off (the flat triangles); the GPU's image "
                 "is the flat one bit for bit, the CPU's with 'on' but for rare rays meeting a copy's edge (docs/notes/cpu-log.md)")
      ->capture_default_str();
  cmd.add_option("--isa", o.choices.isa,
                 "CPU: instruction set of the batched path step: auto (widest the CPU has), avx512, avx2 or scalar; "
                 "same image with each")
      ->capture_default_str();
  cmd.add_option("--sampling", o.choices.sampling, "uniform (the paper), cosine, or nee (light sampling + MIS)")->capture_default_str();
  cmd.add_option("--device", o.choices.device,
                 "cpu, gpu, or hybrid (MPI ranks: GPU ranks on the visible GPUs, CPU ranks on the other cores)")
      ->capture_default_str();
  cmd.add_option("--balance", o.balance,
                 "MPI ranks: static (equal shares), dynamic (chunks from a shared counter), or auto (dynamic "
                 "when the ranks' devices differ)")
      ->check(CLI::IsMember({"auto", "static", "dynamic"}))
      ->capture_default_str();
  cmd.add_option("--strategy", o.choices.strategy, "pixel, wavefront, or paper-queue (GPU)")->capture_default_str();
  cmd.add_option("--paths-in-flight", o.settings.paths_in_flight,
                 "wavefront pool size (0: device default; at most the frame's samples)")
      ->check(non_negative());
  cmd.add_option("--threads", o.settings.threads, "CPU threads (0: all)")->capture_default_str();
  cmd.add_option("--seed", o.settings.seed, "random seed (0 to 2^64-1)")->check(non_negative())->capture_default_str();
  cmd.add_option("--out", o.out, "image file: .exr, .png or .pfm");
  cmd.add_option("--variance-out", o.variance_out, "variance-of-the-mean image (.exr or .pfm)");
  cmd.add_option("--report", o.report, "run report (.json)");
  cmd.add_flag("--profile", o.profile, "print a per-stage GPU profile");
  cmd.add_flag("--quiet", o.quiet, "no progress bar and no summary");
  cmd.footer("Exit status: 0 rendered and written, 2 bad input (a scene or option pathbench refuses, a size past "
             "its limit, an output path it cannot write; one message, nothing written), 3 an internal failure.");
}

void finish_render_options(RenderOptions& o) {
  o.settings.variance = !o.variance_out.empty();
  o.settings.progress = !o.quiet;
  o.choices.device = run::rank_device(o.choices.device);  // --device hybrid: this MPI rank's device
  apply_choices(o.choices, o.settings);
  for (const std::string* path : {&o.out, &o.variance_out}) {
    if (path->empty()) continue;
    const std::string ext = image_extension(*path);
    if (ext != ".exr" && ext != ".png" && ext != ".pfm")
      throw InputError(fmt::format("{}: unsupported image type '{}' (use .exr, .png or .pfm)", display_path(*path),
                                   std::filesystem::path(*path).extension().string()));
    if (ext != ".pfm" && !image_io_has_oiio())
      throw InputError(fmt::format("{}: this build has no OpenImageIO (PATHBENCH_OIIO=OFF); write .pfm instead",
                                   display_path(*path)));
  }
  if (!o.report.empty() && image_extension(o.report) != ".json")
    throw InputError(fmt::format("--report {}: the report is JSON; name it .json", display_path(o.report)));
  // Every output path is checked before the render, so that a bad one fails in
  // milliseconds and not after the render (and not after another output was written).
  const std::pair<const char*, const std::string*> outputs[] = {
      {"--out", &o.out}, {"--variance-out", &o.variance_out}, {"--report", &o.report}};
  for (size_t i = 0; i < std::size(outputs); ++i) {
    if (outputs[i].second->empty()) continue;
    check_output_path(*outputs[i].second, outputs[i].first);
    for (size_t j = 0; j < i; ++j)
      if (*outputs[j].second == *outputs[i].second)
        throw InputError(fmt::format("{} {}: the same file as {}", outputs[i].first, display_path(*outputs[i].second),
                                     outputs[j].first));
  }
}

void apply_scene_defaults(const Scene& scene, RenderOptions& o) {
  const SceneRenderDefaults& d = scene.render_defaults;
  auto absent = [](const CLI::Option* opt) { return !opt || opt->count() == 0; };
  std::string taken;
  auto take = [&](const std::string& what) { taken += (taken.empty() ? "" : ", ") + what; };
  if (d.width && absent(o.given.width)) o.settings.width = d.width, take(fmt::format("width {}", d.width));
  if (d.height && absent(o.given.height)) o.settings.height = d.height, take(fmt::format("height {}", d.height));
  if (d.spp && absent(o.given.spp)) o.settings.spp = d.spp, take(fmt::format("{} spp", d.spp));
  if (d.max_bounces != SceneRenderDefaults::kUnset && absent(o.given.bounces) && absent(o.given.converged)) {
    o.settings.max_bounces = d.max_bounces;
    // Unbounded paths end by Russian roulette, as --converged.
    if (d.max_bounces < 0) o.settings.russian_roulette = true;
    take(d.max_bounces < 0 ? std::string("unbounded path length") : fmt::format("{} bounces", d.max_bounces));
  }
  if (!taken.empty())
    fmt::print(stderr, "note: {}: {} from the scene file (options on the command line override them)\n",
               terminal_safe(scene.name), taken);
}

// What an image must say about where it came from (EXR attributes, PNG text).
ImageMetadata image_metadata(const RunReport& report) {
  const nlohmann::json j = report.to_json();
  nlohmann::json settings;
  for (const char* key : {"width", "height", "spp", "bounces", "russian_roulette", "sampling", "watertight", "precision",
                          "device", "strategy", "seed"})
    if (j.contains(key)) settings[key] = j[key];
  // Instanced or not: on the CPU it can change rare pixels (docs/notes/cpu-log.md).
  settings["instancing"] = to_string(report.settings.instancing);
  if (j.contains("instancing")) settings["instanced"] = j["instancing"].value("used", false);
  return {{"Software", fmt::format("pathbench {}", version_number())},
          {"pathbench:scene", report.scene},
          {"pathbench:spp", std::to_string(report.settings.spp)},
          {"pathbench:seed", std::to_string(report.settings.seed)},
          {"pathbench:settings", settings.dump()},
          {"pathbench:commit", git_revision()}};
}

int run_render(RenderOptions& o) {
  // Under mpirun every rank checks its options and loads the scene, and all stop when one fails.
  Scene scene;
  run::on_every_rank([&] {
    finish_render_options(o);
    scene = load_scene(o.scene, {.strict = o.strict});
    apply_scene_defaults(scene, o);
  });
  Film film;  // sized and begun by the run layer, after it has validated the settings
  RunReport report;
  const run::Balance balance = o.balance == "static"    ? run::Balance::Static
                               : o.balance == "dynamic" ? run::Balance::Dynamic
                                                        : run::Balance::Auto;
  // The options besides the settings that every MPI rank must share (MPMD lines).
  const std::string key = fmt::format("out={} variance_out={} report={} profile={} quiet={} balance={}", o.out,
                                      o.variance_out, o.report, o.profile, o.quiet, o.balance);
  // Rank 0 (or the only process) holds the frame; other ranks have given it their samples.
  if (!run::render_ranks(scene, o.settings, film, report, {.profile = o.profile, .balance = balance}, key)) return 0;

  // Each output goes to its own temporary file; only when all are complete are they
  // renamed into place, so a failure (a full disk) leaves none of them.
  std::vector<OutputFile> outputs;
  outputs.reserve(3);
  const ImageMetadata metadata = image_metadata(report);
  if (!o.out.empty()) write_image(outputs.emplace_back(o.out), film.mean(), film.width(), film.height(), metadata);
  if (!o.variance_out.empty())
    write_image(outputs.emplace_back(o.variance_out), film.variance_of_mean(), film.width(), film.height(), metadata);
  if (!o.report.empty()) {
    // The render's own peak, and the whole run's: the images above (the mean, its
    // 8-bit copy, the encoder's buffers) can raise the process's peak above the render's.
    report.extra["render_peak_host_bytes"] = report.peak_host_bytes;
    report.peak_host_bytes = std::max(report.peak_host_bytes, peak_resident_bytes());
    OutputFile& f = outputs.emplace_back(o.report);
    f.write(report.to_json().dump(2) + "\n");
    f.finish();
  }
  commit_all(outputs);
  if (!o.quiet) {
    fmt::print("{} {}x{} {} spp, {} bounces, {} sampling, {}, {}/{}: {:.3f} s, {:.2f} M rays/s ({} rays, {} paths",
               terminal_safe(scene.name), o.settings.width, o.settings.height, o.settings.spp,
               o.settings.max_bounces < 0 ? std::string("unbounded") : std::to_string(o.settings.max_bounces),
               to_string(o.settings.sampling), to_string(o.settings.precision), to_string(o.settings.device),
               to_string(o.settings.strategy),
               report.seconds, report.rays_per_second() / 1e6, report.rays.total(), report.paths);
    if (report.discarded_samples) fmt::print(", {} discarded", report.discarded_samples);
    fmt::print(")\n");
    if (report.extra.contains("ranks")) {  // MPI ranks (run/ranks_report.h)
      const nlohmann::json& x = report.extra["ranks"];
      std::string share;
      for (const auto& [device, part] : x["device_share"].items())
        share += fmt::format("{}{} {:.1f}%", share.empty() ? "" : ", ", device, 100 * part.get<double>());
      fmt::print("ranks: {} ({} balance; samples: {}), load balance {:.2f}, parallel efficiency {:.2f}, reduction "
                 "{:.3f} s\n",
                 x["count"].get<int>(), x["balance"].get<std::string>(), share, x["load_balance"].get<double>(),
                 x["parallel_efficiency"].get<double>(), x["reduce_seconds"].get<double>());
    }
    if (!o.out.empty()) fmt::print("image: {}\n", terminal_safe(o.out));
    if (!o.report.empty()) fmt::print("report: {}\n", terminal_safe(o.report));
  }
  return 0;
}

}  // namespace pb::app
