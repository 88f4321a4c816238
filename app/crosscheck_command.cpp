#include "crosscheck_command.h"

#include <fmt/core.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "cli_checks.h"
#include "mitsuba_export.h"
#include "python_tools.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/image_io.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/run/run.h"

namespace pb::app {

namespace fs = std::filesystem;

void add_crosscheck_options(CLI::App& cmd, CrosscheckOptions& o) {
  cmd.add_option("scene", o.scene, "built-in scene name or scene file")->required();
  cmd.add_option("--mitsuba-xml", o.mitsuba_xml,
                 "Mitsuba 3 scene to compare with (default: SCENE itself if it is .xml, else SCENE exported)");
  cmd.add_option("--out-dir", o.out_dir, "images, difference images and verdict (JSON)")->capture_default_str();
  cmd.add_option("--device", o.device, "cpu, gpu or all (the GPU where present)")->capture_default_str();
  cmd.add_option("--variant", o.variant, "Mitsuba variant")->capture_default_str();
  cmd.add_option("--width", o.width, "image width (default: the scene file's film, else 64)")->check(non_negative());
  cmd.add_option("--height", o.height, "image height (default: the scene file's film, else 48)")->check(non_negative());
  cmd.add_option("--spp", o.spp, "pathbench samples per pixel")->check(non_negative())->capture_default_str();
  cmd.add_option("--mitsuba-spp-factor", o.mitsuba_spp_factor, "Mitsuba renders this many times pathbench's samples")
      ->check(non_negative())->capture_default_str();
  cmd.add_option("--bounces", o.bounces, "bounces (default: the scene file's max_depth, else 2; -1 unbounded)");
  cmd.add_option("--threads", o.threads, "CPU threads (0: all)")->capture_default_str();
  cmd.add_flag("--strict", o.strict, "what the scene file holds that pathbench does not model is an error");
}

namespace {

// tools/crosscheck.py through the one Python launcher (needs numpy and Mitsuba 3); its exit status.
int run_tool(const std::vector<std::string>& args) {
  return run_python_tool({"crosscheck", "crosscheck.py", {"numpy", "mitsuba"}}, args);
}

}  // namespace

int run_crosscheck(CrosscheckOptions& o) {
  if (o.device != "cpu" && o.device != "gpu" && o.device != "all")
    throw InputError(fmt::format("--device: unknown device '{}' (cpu, gpu or all)", o.device));
  if (o.spp == 0 || o.mitsuba_spp_factor == 0) throw InputError("--spp, --mitsuba-spp-factor: must be at least 1");
  // Python and Mitsuba first: a missing one is one line and exit 2 before any rendering.
  if (const int s = run_python_tool({"crosscheck", "", {"numpy", "mitsuba"}}, {}); s != 0) return s;
  const Scene scene = load_scene(o.scene, {.strict = o.strict});
  const SceneRenderDefaults& d = scene.render_defaults;
  const bool own_xml = o.mitsuba_xml.empty() && image_extension(o.scene) == ".xml";
  RenderSettings s;
  s.width = o.width ? o.width : d.width ? d.width : 64;
  s.height = o.height ? o.height : d.height ? d.height : 48;
  if (own_xml && ((o.width && o.width != d.width) || (o.height && o.height != d.height)))
    throw InputError(fmt::format("--width/--height: Mitsuba renders {} at its film's {}x{}; leave them out", o.scene,
                                 d.width, d.height));
  s.max_bounces = o.bounces != -2 ? o.bounces : d.max_bounces != SceneRenderDefaults::kUnset ? d.max_bounces : 2;
  s.russian_roulette = s.max_bounces < 0;
  s.spp = o.spp;
  s.sampling = Sampling::Nee;
  s.threads = o.threads;
  s.variance = true;
  s.progress = false;
  std::vector<Device> devices;
  if (o.device != "gpu") devices.push_back(Device::Cpu);
  std::string why;
  if (o.device != "cpu") {
    if (run::gpu_available(&why)) devices.push_back(Device::Gpu);
    else if (o.device == "gpu") throw InputError("--device gpu: " + why);
    else fmt::print(stderr, "note: crosscheck: CPU only ({})\n", why);
  }
  fs::create_directories(o.out_dir);
  const std::string reference = !o.mitsuba_xml.empty() ? o.mitsuba_xml
                                : own_xml             ? o.scene
                                                      : write_mitsuba_scene(scene, s, (fs::path(o.out_dir) / "mitsuba").string());
  std::vector<std::string> args{"--xml", reference, "--out-dir", o.out_dir, "--spp", std::to_string(o.spp * o.mitsuba_spp_factor),
                                "--pathbench-spp", std::to_string(o.spp), "--variant", o.variant, "--scene", o.scene};
  for (Device dev : devices) {
    s.device = dev;
    const run::Rendered r = run::render(scene, s);
    const std::string base = (fs::path(o.out_dir) / fmt::format("pathbench-{}", to_string(dev))).string();
    write_image(base + ".pfm", r.film.mean(), r.film.width(), r.film.height());
    write_image(base + "-var.pfm", r.film.variance_of_mean(), r.film.width(), r.film.height());
    args.insert(args.end(), {"--image", fmt::format("{}={}.pfm", to_string(dev), base)});
  }
  fmt::print("crosscheck: {} ({}x{}, {} spp, {} bounces) against Mitsuba 3 ({}, {} spp)\n", o.scene, s.width, s.height,
             s.spp, s.max_bounces < 0 ? std::string("unbounded") : std::to_string(s.max_bounces), reference,
             o.spp * o.mitsuba_spp_factor);
  std::fflush(stdout);
  return run_tool(args);
}

}  // namespace pb::app
