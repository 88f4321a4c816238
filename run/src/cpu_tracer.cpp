// The Embree + TBB tracer of cpu/ behind run/'s tracer interface (pathbench/run/tracer.h).
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
  int device_count() const override { return 1; }
  int select_device(int) const override { return 0; }
};

}  // namespace

const Tracer& cpu_tracer() {
  static const EmbreeTracer t;
  return t;
}

}  // namespace pb::run
