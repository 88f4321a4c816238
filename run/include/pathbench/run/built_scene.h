#pragma once
// A scene built once on its device for many frames (the suite's benchmarks, issue 28): the
// CPU's Embree scene, or the GPU's BVH built and uploaded, then any number of frames on it.
// Each frame is what run::render gives for the same settings (the same film, report and
// checks: validation, film, energy, fingerprint, film hash) without the build, so that a
// benchmark times and meters the frames alone and reports the build apart. The build is
// the device tracer's PreparedScene (tracer.h); this adds run::render's checks and report.
#include <memory>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/run.h"
#include "pathbench/run/tracer.h"

namespace pb::run {

class BuiltScene {
 public:
  // Validates `settings` and checks the device as render() does, then builds the device's
  // structure for `scene` (which must outlive this object). Throws InputError as render().
  BuiltScene(const Scene& scene, const RenderSettings& settings);
  ~BuiltScene();
  BuiltScene(const BuiltScene&) = delete;
  BuiltScene& operator=(const BuiltScene&) = delete;
  // Wall seconds of the build (Embree's commit; on the GPU the BVH build and the upload).
  double build_seconds() const { return build_seconds_; }
  // Whether frames with `settings` can use this structure: the same device, instancing,
  // watertightness and Embree layout (size, samples, bounces, sampling and ISA may differ).
  bool serves(const RenderSettings& settings) const;
  // One frame: render(scene, settings, film, report, options) on the structure built once.
  // Throws std::logic_error where !serves(settings).
  void render(const RenderSettings& settings, Film& film, RunReport& report, const RunOptions& options = {}) const;

 private:
  const Scene& scene_;
  RenderSettings built_for_;
  double build_seconds_ = 0;
  std::unique_ptr<PreparedScene> prepared_;  // the device tracer's (run/tracer.h)
};

}  // namespace pb::run
