#include "bench_ranks.h"

#include <fmt/core.h>

#include <map>
#include <memory>
#include <stdexcept>

#include "pathbench/run/ranks_render.h"
#include "pathbench/run/world.h"
#include "scene_cache.h"

namespace pb::bench {

namespace {
constexpr const char* kStop = "stop";  // no benchmark name is this short
std::map<std::string, RenderCase>& render_cases() {
  static std::map<std::string, RenderCase> cases;
  return cases;
}
bool g_released = false;
}  // namespace

int bench_ranks() { return run::World::get().size(); }
bool bench_follower() { return !run::World::get().root(); }

void remember_render_case(const std::string& name, const RenderCase& c) { render_cases()[name] = c; }

void render_frame_over_ranks(const std::string& name, const Scene& scene, const RenderSettings& s, Film& film,
                             RunReport& report) {
  run::World::get().announce(name);
  run::on_every_rank([] {});  // the followers load the scene meanwhile
  run::render_ranks(scene, s, film, report);
}

int follow_rank0() {
  run::World& w = run::World::get();
  for (;;) {
    const std::string name = w.announce("");
    if (name == kStop) return 0;
    try {
      std::shared_ptr<const Scene> scene;
      const RenderCase* frame = nullptr;
      run::on_every_rank([&] {
        const auto it = render_cases().find(name);
        if (it == render_cases().end())
          throw std::runtime_error(fmt::format("no render benchmark '{}' here (the ranks' command lines differ?)", name));
        frame = &it->second;
        scene = cached_scene(frame->scene);
      });
      Film film;
      RunReport report;
      run::render_ranks(*scene, frame->settings, film, report);
    } catch (const run::PeerFailure&) {
      // Agreed by every rank: rank 0 skips that benchmark and goes on; so does this rank.
    } catch (const std::exception& e) {
      fmt::print(stderr, "pathbench-bench: rank {}: {}\n", w.rank(), e.what());
      return 1;  // World::end aborts the run: rank 0 would wait for this rank forever
    }
  }
}

void release_followers() {
  if (g_released) return;
  g_released = true;
  run::World::get().announce(kStop);
}

}  // namespace pb::bench
