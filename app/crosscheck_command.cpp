#include "crosscheck_command.h"

#include <fmt/core.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <future>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "cli_checks.h"
#include "pathbench/scene_io/mitsuba_export.h"
#include "pathbench/common/display_text.h"
#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/output/output_file.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"
#include "python_tools.h"

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
  o.bounces_option =
      cmd.add_option("--bounces", o.bounces, "bounces (default: the scene file's max_depth, else 2; -1 unbounded)");
  cmd.add_option("--threads", o.threads, "CPU threads (0: all)")->check(non_negative())->capture_default_str();
  cmd.add_flag("--strict", o.strict, "what the scene file holds that pathbench does not model is an error");
  cmd.footer("Exit status: 0 same up to noise, 1 different (a device's image fails the test), 2 bad input (a "
             "message names it; nothing this run wrote is left in --out-dir), 3 an internal failure; stopped by a signal "
             "(Ctrl-C: 130, 128 + N), nothing this run wrote is left either.");
}

namespace {

// tools/crosscheck.py through the one Python launcher (needs numpy and Mitsuba 3); its exit status.
int run_tool(const std::vector<std::string>& args) {
  return run_python_tool({"crosscheck", "crosscheck.py", {"numpy", "mitsuba"}}, args);
}

// Mitsuba takes its sample count as a 32-bit unsigned integer.
constexpr uint64_t kMaxMitsubaSpp = 0xFFFFFFFFull;

// What one run writes under --out-dir, removed again unless the run ends with a verdict
// (exit 0 or 1): the folders it created (all of them, with what is in them), and in a
// folder that was there before, the files it wrote and any entry new since it started
// in the Mitsuba export folder. tools/crosscheck.py writes its own files only once it has
// a verdict, and removes them itself when it fails.
class OutDirRun {
 public:
  explicit OutDirRun(const fs::path& dir) : dir_(dir) {
    std::error_code ec;
    for (fs::path p = dir_; !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
      created_ = p;
      if (p == p.parent_path()) break;
    }
    fs::create_directories(dir_, ec);
    if (ec) throw InputError(fmt::format("--out-dir {}: {}", display_path(dir_.string()), ec.message()));
  }
  OutDirRun(const OutDirRun&) = delete;
  OutDirRun& operator=(const OutDirRun&) = delete;
  ~OutDirRun() { discard(); }
  // Removes what this run wrote (once; not after keep()).
  void discard() {
    if (kept_) return;
    kept_ = true;
    std::error_code ec;
    if (!created_.empty()) {
      fs::remove_all(created_, ec);
      return;
    }
    for (const fs::path& p : written_) fs::remove_all(p, ec);
    for (const auto& [folder, before] : folders_) {
      if (!before) {
        fs::remove_all(folder, ec);
        continue;
      }
      for (const fs::path& p : entries(folder))
        if (!before->count(p)) fs::remove_all(p, ec);
    }
  }
  const fs::path& dir() const { return dir_; }
  // A file this run writes: removed on failure.
  std::string file(const std::string& name) {
    written_.push_back(dir_ / name);
    return written_.back().string();
  }
  // A folder this run writes into: what is new in it is removed on failure (all of it
  // where the folder is new).
  std::string folder(const std::string& name) {
    const fs::path p = dir_ / name;
    std::error_code ec;
    folders_.emplace_back(p, fs::is_directory(p, ec) ? std::optional(entries(p)) : std::nullopt);
    return p.string();
  }
  void keep() { kept_ = true; }

 private:
  static std::set<fs::path> entries(const fs::path& folder) {
    std::set<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) out.insert(it->path());
    return out;
  }
  fs::path dir_, created_;
  std::vector<fs::path> written_;
  std::vector<std::pair<fs::path, std::optional<std::set<fs::path>>>> folders_;
  bool kept_ = false;
};

}  // namespace

int run_crosscheck(CrosscheckOptions& o) {
  // Every option, size and path is checked before anything is rendered or written.
  if (o.device != "cpu" && o.device != "gpu" && o.device != "all")
    throw InputError(fmt::format("--device: unknown device '{}' (cpu, gpu or all)", o.device));
  if (o.spp == 0 || o.mitsuba_spp_factor == 0) throw InputError("--spp, --mitsuba-spp-factor: must be at least 1");
  const uint64_t mitsuba_spp = uint64_t(o.spp) * o.mitsuba_spp_factor;  // 32 x 32 bits: no wrap in 64
  if (mitsuba_spp > kMaxMitsubaSpp)
    throw InputError(fmt::format("--spp x --mitsuba-spp-factor: {} x {} = {} samples per pixel for Mitsuba, more than "
                                 "the {} it takes",
                                 o.spp, o.mitsuba_spp_factor, mitsuba_spp, kMaxMitsubaSpp));
  if (o.out_dir.empty()) throw InputError("--out-dir: empty");
  check_output_path((fs::path(o.out_dir) / "verdict.json").string(), "--out-dir");
  if (!o.mitsuba_xml.empty()) {
    std::error_code ec;
    if (!fs::is_regular_file(o.mitsuba_xml, ec))
      throw InputError(fmt::format("--mitsuba-xml {}: {}", display_path(o.mitsuba_xml),
                                   fs::exists(o.mitsuba_xml, ec) ? "not a regular file" : "no such file"));
  }
  // Python and Mitsuba first: a missing one is one line and exit 2 before any rendering.
  if (const int s = run_python_tool({"crosscheck", "", {"numpy", "mitsuba"}}, {}); s != 0) return s;
  const Scene scene = load_scene(o.scene, {.strict = o.strict});
  const SceneRenderDefaults& d = scene.render_defaults;
  const bool own_xml = o.mitsuba_xml.empty() && image_extension(o.scene) == ".xml";
  RenderSettings s;
  s.width = o.width ? o.width : d.width ? d.width : 64;
  s.height = o.height ? o.height : d.height ? d.height : 48;
  if (own_xml && ((o.width && o.width != d.width) || (o.height && o.height != d.height)))
    throw InputError(fmt::format("--width/--height: Mitsuba renders {} at its film's {}x{}; leave them out",
                                 display_path(o.scene), d.width, d.height));
  const bool bounces_given = o.bounces_option && o.bounces_option->count() > 0;
  s.max_bounces = bounces_given ? o.bounces : d.max_bounces != SceneRenderDefaults::kUnset ? d.max_bounces : 2;
  s.russian_roulette = s.max_bounces < 0;
  s.spp = o.spp;
  s.sampling = Sampling::Nee;
  s.threads = o.threads;
  s.variance = true;
  s.progress = false;
  s.validate();
  std::vector<Device> devices;
  if (o.device != "gpu") devices.push_back(Device::Cpu);
  std::string why;
  if (o.device != "cpu") {
    if (run::gpu_available(&why)) devices.push_back(Device::Gpu);
    else if (o.device == "gpu") throw InputError("--device gpu: " + why);
    else fmt::print(stderr, "note: crosscheck: CPU only ({})\n", why);
  }
  // From here a signal (Ctrl-C) must not end the process before what it wrote is removed
  // (before, the images and the exported scene stayed): it is acted on at the checks below.
  DeferredSignals signals;
  OutDirRun out(o.out_dir);
  const auto stop_if_signalled = [&] {
    if (!signals.signal()) return;
    out.discard();
    signals.stop();
  };
  const std::string reference = !o.mitsuba_xml.empty() ? o.mitsuba_xml
                                : own_xml             ? o.scene
                                                      : write_mitsuba_scene(scene, s, out.folder("mitsuba"));
  stop_if_signalled();
  std::vector<std::string> args{"--xml", reference, "--out-dir", o.out_dir, "--spp", std::to_string(mitsuba_spp),
                                "--pathbench-spp", std::to_string(o.spp), "--variant", o.variant, "--scene", o.scene,
                                "--bounces", std::to_string(s.max_bounces)};
  for (Device dev : devices) {
    s.device = dev;
    // The render cannot be cancelled: it runs on another thread while this one watches.
    auto rendering = std::async(std::launch::async, [&] { return run::render(scene, s); });
    while (rendering.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready) stop_if_signalled();
    const run::Rendered r = rendering.get();
    const std::string base = fmt::format("pathbench-{}", to_string(dev));
    write_image(out.file(base + ".pfm"), r.film.mean(), r.film.width(), r.film.height());
    write_image(out.file(base + "-var.pfm"), r.film.variance_of_mean(), r.film.width(), r.film.height());
    stop_if_signalled();
    args.insert(args.end(), {"--image", fmt::format("{}={}", to_string(dev), (out.dir() / (base + ".pfm")).string())});
  }
  fmt::print("crosscheck: {} ({}x{}, {} spp, {} bounces) against Mitsuba 3 ({}, {} spp)\n", terminal_safe(o.scene),
             s.width, s.height, s.spp, s.max_bounces < 0 ? std::string("unbounded") : std::to_string(s.max_bounces),
             terminal_safe(reference), mitsuba_spp);
  std::fflush(stdout);
  const int status = run_tool(args);
  if (signals.signal()) {
    // Even with a verdict: Mitsuba takes SIGINT itself, ends its render early ("winding
    // down") and returns the partial image, which crosscheck.py then judged. Its files go too.
    for (const Device dev : devices) {
      out.file(fmt::format("diff-{}.pfm", to_string(dev)));
      out.file(fmt::format("z-{}.pfm", to_string(dev)));
    }
    out.file("mitsuba.pfm");
    out.file("verdict.json");
    stop_if_signalled();
  }
  if (status == 0 || status == 1) {  // a verdict: same or different
    out.keep();
    return status;
  }
  if (status == kExitBadInput || status == kExitFailed) return status;  // its message is on stderr
  fmt::print(stderr, "pathbench: failed: crosscheck: tools/crosscheck.py ended with status {}\n", status);
  return kExitFailed;
}

}  // namespace pb::app
