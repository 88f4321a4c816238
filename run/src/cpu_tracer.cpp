// The Embree + TBB tracer of cpu/ behind run/'s tracer interface (pathbench/run/tracer.h).
#include <cstdlib>
#include <sstream>

#include <fmt/core.h>

#include "pathbench/cpu/embree_layout.h"
#include "pathbench/cpu/render.h"
#include "pathbench/run/tracer.h"

namespace pb::run {

namespace {

class EmbreePreparedScene final : public PreparedScene {
 public:
  EmbreePreparedScene(const Scene& scene, const RenderSettings& s)
      : scene_(scene), embree_(cpu::make_embree_scene(scene, s.watertight, s.embree_layout, s.instancing)) {}
  void render(const RenderSettings& s, Film& film, RunReport& report, bool, DeviceFilm*) const override {
    cpu::render(scene_, *embree_, s, film, report);  // Film::add accumulates into `film`
  }

 private:
  const Scene& scene_;
  std::unique_ptr<cpu::EmbreeScene> embree_;
};

class EmbreeTracer final : public Tracer {
 public:
  bool available(std::string*) const override { return true; }
  void render(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, bool) const override {
    cpu::render(scene, s, film, report);
  }
  std::unique_ptr<PreparedScene> prepare(const Scene& scene, const RenderSettings& s) const override {
    return std::make_unique<EmbreePreparedScene>(scene, s);
  }
  // "<layout> <triangles ns> <quads ns> <reason>" (hexadecimal floats: the same bits on every rank).
  std::string measured(const Scene& scene, const RenderSettings& s) const override {
    if (s.embree_layout != EmbreeLayout::Auto || s.instancing == Instancing::On) return {};  // nothing probed
    const cpu::LayoutChoice c = cpu::choose_embree_layout(scene, s.watertight);
    return fmt::format("{} {:a} {:a} {}", to_string(c.layout), c.triangles_ns, c.quads_ns, c.reason);
  }
  bool adopt_measured(const Scene& scene, const RenderSettings& s, const std::string& line) const override {
    if (s.embree_layout != EmbreeLayout::Auto || line.empty()) return true;
    std::istringstream in(line);
    std::string layout, tri, quads, reason;
    if (!(in >> layout >> tri >> quads) || !std::getline(in >> std::ws, reason)) return false;
    EmbreeLayout l;
    try {
      l = parse_embree_layout(layout);
    } catch (const std::exception&) {
      return false;
    }
    return l != EmbreeLayout::Auto && cpu::remember_embree_layout(scene, s.watertight, l, std::strtod(tri.c_str(), nullptr),
                                       std::strtod(quads.c_str(), nullptr), reason);
  }
  int device_count() const override { return 1; }
  int select_device(int) const override { return 0; }
};

}  // namespace

const Tracer& cpu_tracer() {
  static const EmbreeTracer t;
  return t;
}

}  // namespace pb::run
