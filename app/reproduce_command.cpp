#include "reproduce_command.h"

#include <fmt/core.h>

#include <vector>

#include "pathbench/common/errors.h"
#include "pathbench/common/image_io.h"
#include "pathbench/common/scene_library.h"
#include "render_command.h"

namespace pb::app {

namespace {

// The paper's own figures (Tunnel 2015, Tesla K20m).
constexpr double kPaperSeconds = 27.0;
constexpr double kPaperTaskBytes = 48.0;

struct Row {
  RunReport report;
};

std::string fmt_bytes(double b) {
  if (b >= 1e9) return fmt::format("{:.2f} GB", b / 1e9);
  if (b >= 1e6) return fmt::format("{:.1f} MB", b / 1e6);
  return fmt::format("{:.0f} kB", b / 1e3);
}

}  // namespace

void add_reproduce_options(CLI::App& cmd, ReproduceOptions& o) {
  cmd.add_option("--device", o.device, "cpu, gpu, or all (cpu, plus gpu when there is one)")->capture_default_str();
  cmd.add_option("--out-dir", o.out_dir, "where to write images, reports and the table (default results/<machine>)");
  cmd.add_option("--spp", o.spp, "samples per pixel (the paper: 800)")->capture_default_str();
  cmd.add_option("--threads", o.threads, "CPU threads (0: all)")->capture_default_str();
  cmd.add_flag("--quiet", o.quiet, "no progress bars");
}

int run_reproduce(const ReproduceOptions& o) {
  if (o.device != "cpu" && o.device != "gpu" && o.device != "all")
    throw InputError(fmt::format("--device: unknown device '{}' (expected cpu, gpu or all)", o.device));
  if (o.spp == 0) throw InputError("--spp: must be at least 1");
  std::vector<Device> devices;
  std::string why_no_gpu;
  const bool have_gpu = gpu_available(&why_no_gpu);
  if (o.device != "gpu") devices.push_back(Device::Cpu);
  if (o.device == "gpu" && !have_gpu) throw InputError(fmt::format("--device gpu: {}", why_no_gpu));
  if (o.device != "cpu" && have_gpu) devices.push_back(Device::Gpu);

  const std::string dir = o.out_dir.empty() ? "results/" + machine_slug() : o.out_dir;
  const Scene scene = make_paper_cornell();
  std::vector<RunReport> rows;
  nlohmann::json all = nlohmann::json::array();
  for (Device dev : devices) {
    std::vector<Strategy> strategies = {Strategy::Pixel, Strategy::Wavefront};
    for (Sampling sampling : {Sampling::Uniform, Sampling::Nee}) {
      for (Strategy strategy : strategies) {
        RenderSettings s;
        s.width = s.height = 256;
        s.spp = o.spp;
        s.max_bounces = 2;
        s.sampling = sampling;
        s.strategy = strategy;
        s.device = dev;
        s.threads = o.threads;
        s.progress = !o.quiet;
        Film film(s.width, s.height, false);
        RunReport r;
        render_on_device(scene, s, film, r, false);
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
  write_text_file(dir + "/paper-cornell-report.json", all.dump(2) + "\n");

  std::string md;
  md += fmt::format("# The 2015 paper's experiment: paper-cornell, 256x256, {} spp, 2 bounces\n\n", o.spp);
  md += "| device | strategy | sampling | time (s) | vs paper's 27 s | M rays/s | M samples/s | path state / path | peak host |\n";
  md += "|---|---|---|---:|---:|---:|---:|---:|---:|\n";
  md += fmt::format("| Tesla K20m (paper) | global queue | uniform | {:.1f} | 1.0x | | {:.2f} | {:.0f} B | |\n", kPaperSeconds,
                    256.0 * 256 * 800 / kPaperSeconds / 1e6, kPaperTaskBytes);
  for (const RunReport& r : rows) {
    double secs = r.settings.device == Device::Gpu ? r.device_seconds : r.seconds;
    md += fmt::format("| {} | {} | {} | {:.3f} | {:.1f}x | {:.1f} | {:.2f} | {} B | {} |\n",
                      r.settings.device == Device::Cpu ? fmt::format("CPU ({} threads)", r.threads) : std::string("GPU"),
                      to_string(r.settings.strategy), to_string(r.settings.sampling), secs,
                      kPaperSeconds / secs * (800.0 / r.settings.spp), r.rays_per_second() / 1e6,
                      double(r.paths) / secs / 1e6, r.state_bytes_per_path, fmt_bytes(double(r.peak_host_bytes)));
  }
  md += fmt::format("\nCPU: {}. Paper's queue: 48 B/task; 512x512x300 needs {} (more than the K20m's 5 GB).\n",
                    cpu_model(), fmt_bytes(512.0 * 512 * 300 * kPaperTaskBytes));
  if (!have_gpu) md += fmt::format("GPU rows absent: {}.\n", why_no_gpu);
  write_text_file(dir + "/paper-cornell.md", md);
  fmt::print("\n{}\nwritten: {}/paper-cornell.md, paper-cornell-report.json, images\n", md, dir);
  return 0;
}

}  // namespace pb::app
