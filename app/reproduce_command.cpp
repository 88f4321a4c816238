#include "reproduce_command.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "cli_checks.h"
#include "output_dirs.h"
#include "pathbench/output/output_file.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/output/image_io.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/ranks_render.h"
#include "pathbench/run/run.h"
#include "pathbench/run/world.h"

namespace pb::app {

namespace {

// The paper's own figures (Tunnel 2015, Tesla K20m): 256x256, 800 spp, 2 bounces,
// uniform hemisphere sampling, one global queue of 48-byte tasks.
constexpr double kPaperSeconds = 27.0;
constexpr double kPaperTaskBytes = 48.0;
constexpr uint32_t kPaperSpp = 800;
constexpr uint32_t kSide = 256;

std::string fmt_bytes(double b) {
  if (b <= 0) return "0";
  if (b >= 1e9) return fmt::format("{:.2f} GB", b / 1e9);
  if (b >= 1e6) return fmt::format("{:.1f} MB", b / 1e6);
  return fmt::format("{:.0f} kB", b / 1e3);
}

uint64_t queue_bytes(const RunReport& r) {
  for (const char* key : {"queue_bytes", "pool_bytes", "pool_device_bytes"})
    if (r.extra.contains(key) && r.extra[key].is_number()) return r.extra[key].get<uint64_t>();
  return 0;
}

std::string device_label(const RunReport& r) {
  if (r.settings.device == Device::Cpu) return fmt::format("CPU, {} threads", r.threads);
  if (r.extra.contains("gpu") && r.extra["gpu"].contains("name") && r.extra["gpu"]["name"].is_string())
    return fmt::format("GPU ({})", r.extra["gpu"]["name"].get<std::string>());
  return "GPU";
}

RenderSettings paper_settings(Device dev, Strategy strategy, Sampling sampling, uint32_t spp, int threads) {
  RenderSettings s;
  s.width = s.height = kSide;
  s.spp = spp;
  s.max_bounces = 2;
  s.sampling = sampling;
  s.strategy = strategy;
  s.device = dev;
  s.threads = threads;
  return s;
}

// Seconds per sample per pixel of a CPU pixel-parallel render with `sampling`,
// measured on a short render.
double cpu_seconds_per_spp(const Scene& scene, Sampling sampling, int threads) {
  constexpr uint32_t kProbeSpp = 8;
  RenderSettings s = paper_settings(Device::Cpu, Strategy::Pixel, sampling, kProbeSpp, threads);
  s.progress = false;
  Film film(s.width, s.height, false);
  RunReport r;
  run::render(scene, s, film, r);
  return r.seconds / kProbeSpp;
}

// Samples per pixel for the CPU rows other than pixel/nee (which makes the image
// and always runs at `spp`): `spp`, unless the four CPU rows would overrun
// `budget_s`; then as many as fit in what the image row leaves (a multiple of 16, at
// least 16). Their times are scaled to `spp` in the table.
uint32_t reduced_spp_for_budget(const Scene& scene, uint32_t spp, double budget_s, int threads) {
  if (budget_s <= 0) return spp;
  const double uni = cpu_seconds_per_spp(scene, Sampling::Uniform, threads);
  const double nee = cpu_seconds_per_spp(scene, Sampling::Nee, threads);
  const double full = 2 * spp * (uni + nee);
  if (full <= budget_s) return spp;
  const double left = budget_s - spp * nee;  // after the image row
  uint32_t r = left > 0 ? uint32_t(left / (2 * uni + nee)) / 16 * 16 : 0;
  r = std::clamp<uint32_t>(r, 16, spp);
  fmt::print("reproduce: all CPU rows at {} spp would take about {:.0f} s here (budget {:.0f} s); the image row "
             "(pixel, nee) runs at {} spp, the other CPU rows at {} spp with times scaled to {} spp "
             "(--budget 0 for full spp everywhere)\n",
             spp, full, budget_s, spp, r, spp);
  return r;
}

}  // namespace

void add_reproduce_options(CLI::App& cmd, ReproduceOptions& o) {
  cmd.add_option("--device", o.device, "cpu, gpu, or all (cpu, plus gpu when there is one)")->capture_default_str();
  cmd.add_option("--out-dir", o.out_dir, "where to write images, reports and the table (default pathbench-out/<machine>)");
  cmd.add_flag("--update-committed", o.update_committed,
               "maintainers: write into the committed results/<machine>/ instead of pathbench-out/<machine>/");
  cmd.add_option("--spp", o.spp, "samples per pixel (the paper: 800)")->check(non_negative())->capture_default_str();
  cmd.add_option("--uniform-spp", o.uniform_spp,
                 "samples per pixel for the CPU uniform rows (0: --spp, or fewer if --budget needs it); times are scaled to --spp in the table")
      ->check(non_negative());
  cmd.add_option("--budget", o.budget_s,
                 "seconds the CPU rows may take: if the full run would not fit, every CPU row but the image row "
                 "(pixel, nee) runs at fewer spp and its time is scaled; 0: no budget")
      ->capture_default_str();
  cmd.add_option("--threads", o.threads, "CPU threads (0: all)")->capture_default_str();
  cmd.add_flag("--quiet", o.quiet, "no progress bars");
}

int run_reproduce(const ReproduceOptions& o) {
  if (o.device != "cpu" && o.device != "gpu" && o.device != "all")
    throw InputError(fmt::format("--device: unknown device '{}' (expected cpu, gpu or all)", o.device));
  if (o.spp == 0) throw InputError("--spp: must be at least 1");
  std::vector<Device> devices;
  std::string why_no_gpu;
  // Under mpirun every rank renders a share of every row (run::render_ranks): the rows,
  // the GPU's presence and the budget's spp are rank 0's, and rank 0 alone writes.
  run::World& world = run::World::get();
  const bool have_gpu = world.all(run::gpu_available(&why_no_gpu) ? "gpu" : "")[0] == "gpu";
  if (o.device != "gpu") devices.push_back(Device::Cpu);
  if (o.device == "gpu" && !have_gpu) throw InputError(fmt::format("--device gpu: {}", why_no_gpu));
  if (o.device != "cpu" && have_gpu) devices.push_back(Device::Gpu);

  const std::string dir = output_dir(o.out_dir, o.update_committed, machine_slug());
  check_output_path(dir + "/paper-cornell.md", "--out-dir");  // before minutes of rendering
  const Scene scene = make_paper_cornell();
  const auto t_start = std::chrono::steady_clock::now();
  const bool cpu_rows = devices.front() == Device::Cpu;
  // CPU rows other than the image row (pixel, nee) may run at fewer spp.
  const uint32_t reduced_spp = uint32_t(std::stoul(world.all(std::to_string(
      cpu_rows && world.root() ? reduced_spp_for_budget(scene, o.spp, o.budget_s, o.threads) : o.spp))[0]));
  const uint32_t uniform_spp = o.uniform_spp ? o.uniform_spp : reduced_spp;
  std::vector<RunReport> rows;
  nlohmann::json all = nlohmann::json::array();
  for (Device dev : devices) {
    std::vector<Strategy> strategies = {Strategy::Pixel, Strategy::Wavefront};
    if (dev == Device::Gpu) strategies.push_back(Strategy::PaperQueue);
    for (Sampling sampling : {Sampling::Uniform, Sampling::Nee}) {
      for (Strategy strategy : strategies) {
        uint32_t spp = o.spp;
        if (dev == Device::Cpu && sampling == Sampling::Uniform) spp = uniform_spp;
        if (dev == Device::Cpu && sampling == Sampling::Nee && strategy != Strategy::Pixel) spp = reduced_spp;
        RenderSettings s = paper_settings(dev, strategy, sampling, spp, o.threads);
        s.progress = !o.quiet;
        Film film(s.width, s.height, false);
        RunReport r;
        try {
          if (!run::render_ranks(scene, s, film, r)) continue;  // not rank 0: its share is given
        } catch (const std::exception& e) {
          // The paper's queue may not fit: a row saying so, not a failed run.
          if (strategy != Strategy::PaperQueue) throw;
          if (!world.root()) continue;  // PeerFailure: rank 0 has the message
          fmt::print(stderr, "reproduce: {} {} {}: {}\n", to_string(dev), to_string(strategy), to_string(sampling),
                     e.what());
          r.settings = s;
          r.scene = scene.name;
          r.extra["error"] = e.what();
          all.push_back(r.to_json());
          rows.push_back(r);
          continue;
        }
        // The paper's own image (uniform sampling) and ours with light sampling.
        if (strategy == Strategy::Pixel) {
          const std::string stem = fmt::format("{}/paper-cornell-{}-{}", dir, to_string(dev), to_string(sampling));
          if (image_io_has_oiio()) {
            write_image(stem + ".png", film.mean(), s.width, s.height);
            write_image(stem + ".exr", film.mean(), s.width, s.height);
          } else {
            write_image(stem + ".pfm", film.mean(), s.width, s.height);
          }
          if (dev == Device::Cpu && sampling == Sampling::Nee && image_io_has_oiio()) {
            write_image(dir + "/paper-cornell.png", film.mean(), s.width, s.height);
            write_image(dir + "/paper-cornell.exr", film.mean(), s.width, s.height);
          }
        }
        all.push_back(r.to_json());
        rows.push_back(r);
      }
    }
  }
  if (!world.root()) return 0;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  write_text_file(dir + "/paper-cornell-report.json", all.dump(2) + "\n");

  std::string md;
  md += fmt::format("# The 2015 paper's experiment: paper-cornell, {}x{}, {} spp, 2 bounces\n\n", kSide, kSide, o.spp);
  md += "| device | strategy | sampling | spp run | time (s) | time at " + std::to_string(o.spp) +
        " spp (s) | vs paper's 27 s | M rays/s | M paths/s | path state / path | queue or pool | peak host | peak device |\n";
  md += "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  md += fmt::format("| Tesla K20m (paper, 2015) | global queue | uniform | {} | {:.1f} | {:.1f} | 1.0x | | {:.2f} | {:.0f} B | "
                    "{} (256x256x800 tasks x 48 B, computed) | | |\n",
                    kPaperSpp, kPaperSeconds, kPaperSeconds * o.spp / kPaperSpp,
                    double(kSide) * kSide * kPaperSpp / kPaperSeconds / 1e6, kPaperTaskBytes,
                    fmt_bytes(double(kSide) * kSide * kPaperSpp * kPaperTaskBytes));
  bool scaled = false;
  for (const RunReport& r : rows) {
    if (r.extra.contains("error")) {
      md += fmt::format("| {} | {} | {} | {} | failed: {} | | | | | | | | |\n", device_label(r), to_string(r.settings.strategy),
                        to_string(r.settings.sampling), r.settings.spp, r.extra["error"].get<std::string>());
      continue;
    }
    const double secs = run::render_seconds(r);
    const double at_spp = secs * double(o.spp) / double(r.settings.spp);
    const bool row_scaled = r.settings.spp != o.spp;
    scaled |= row_scaled;
    const double vs_paper = kPaperSeconds / (secs * double(kPaperSpp) / double(r.settings.spp));
    md += fmt::format("| {} | {} | {} | {} | {:.2f} | {:.2f}{} | {:.1f}x | {:.1f} | {:.2f} | {} B | {} | {} | {} |\n",
                      device_label(r), to_string(r.settings.strategy), to_string(r.settings.sampling), r.settings.spp,
                      secs, at_spp, row_scaled ? " (scaled)" : "", vs_paper, r.rays_per_second() / 1e6,
                      double(r.paths) / secs / 1e6, r.state_bytes_per_path,
                      r.settings.strategy == Strategy::Pixel ? std::string("none") : fmt_bytes(double(queue_bytes(r))),
                      fmt_bytes(double(r.peak_host_bytes)),
                      r.settings.device == Device::Gpu ? fmt_bytes(double(r.peak_device_bytes)) : std::string("-"));
  }
  md += "\n";
  md += "- Paper (Tunnel 2015): about 27 s on a Tesla K20m for 256x256 at 800 spp with two diffuse bounces and uniform "
        "hemisphere sampling; every ray of the frame in one global queue of 48-byte tasks: 512x512x300 needed " +
        fmt_bytes(512.0 * 512 * 300 * kPaperTaskBytes) + ".\n";
  md += "- \"vs paper\" is the paper's 27 s divided by our time at 800 spp (higher is faster). Different hardware: a "
        "comparison of the experiment, not of the chips.\n";
  md += "- Times are render times: CPU wall clock around the render (after the Embree build); GPU time from CUDA "
        "events. M paths/s = samples per second.\n";
  md += "- \"queue or pool\": bytes of path state held at once (CPU/GPU wavefront: the bounded pool of paths in flight; "
        "paper-queue: the whole frame's queue); pixel-parallel keeps one path per thread.\n";
  if (scaled)
    md += fmt::format("- Rows marked (scaled) ran at fewer spp to keep `pathbench reproduce` within its time budget "
                      "(--budget); their time at {} spp is the measured time x {} / spp run (render time is linear "
                      "in spp).\n",
                      o.spp, o.spp);
  md += fmt::format("- CPU: {} ({} hardware threads; machine_id {}, the fingerprint is in the report JSON). Git "
                    "revision {}. Whole run: {:.1f} s wall.\n",
                    cpu_model(), hardware_threads(), machine_fingerprint()["machine_id"].get<std::string>(),
                    git_revision(), wall);
  if (!have_gpu) md += fmt::format("- GPU rows absent: {}.\n", why_no_gpu);
  write_text_file(dir + "/paper-cornell.md", md);
  fmt::print("\n{}\nwritten: {}/paper-cornell.md, paper-cornell-report.json, images\n", md, dir);
  return 0;
}

}  // namespace pb::app
