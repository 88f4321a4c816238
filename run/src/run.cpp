#include "pathbench/run/run.h"

#include <fmt/core.h>

#include <optional>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "pathbench/run/energy.h"
#include "pathbench/run/film_hash.h"
#include "pathbench/run/run_context.h"
#include "pathbench/run/tracer.h"
#include "film_setup.h"

namespace pb::run {

bool gpu_available(std::string* why_not) { return gpu_tracer().available(why_not); }

// A film where most samples were discarded (NaN, infinite, or beyond its fixed-point
// range) is wrong, not noisy: fail rather than write it. Within the supported emission
// range this takes extreme geometry (a light 1e-10 from a wall, say).
void check_discarded(const Scene& scene, const RenderSettings& s, const RunReport& report) {
  const double samples = double(s.width) * double(s.height) * double(s.spp);
  const double discarded = double(report.discarded_samples);
  if (samples > 0 && discarded > limits::kMaxDiscardedFraction * samples)
    throw InputError(fmt::format("{}: {} of {} samples ({:.1f}%) were discarded as NaN, infinite or beyond the "
                                 "film's range; the image would be wrong, so none is written (emission is "
                                 "limited to {:g}; very bright lights very close to surfaces also overflow)",
                                 scene.name, report.discarded_samples, uint64_t(samples), 100 * discarded / samples,
                                 limits::kMaxEmission));
}

void check_for_tracer(const RenderSettings& s) {
  s.validate();
  if (s.device == Device::Gpu) {
    std::string why;
    if (!gpu_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
  }
  validate_for_tracer(s, s.device);  // what the device's tracer runs, before it builds anything
}

void render(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, const RunOptions& options) {
  render_with(scene, s, film, report, options,
              [&] { tracer(s.device).render(scene, s, film, report, options.profile); });
}

void render_with(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, const RunOptions& options,
                 const std::function<void()>& trace) {
  check_for_tracer(s);
  prepare_film(scene, s, options, film);
  report.scene = scene.name;
  report.triangles = scene.triangles.size();
  report.settings = s;
  const nlohmann::json start = load_sample();
  std::optional<EnergyMeter> meter;  // around the tracer call: its build and its frame
  if (options.energy) meter.emplace(s.device);
  trace();
  // The load around the tracer alone (so that a contended run can be told from a slow
  // one) and the machine it ran on, filled here once for every caller.
  report.load = load_between(start, load_sample());
  if (meter) {
    report.extra["energy"] = meter->stop();
    add_energy_rates(report.extra["energy"], report.rays.total(), 1);
  }
  report.fingerprint = run_fingerprint(s.device == Device::Gpu);
  report.peak_host_bytes = peak_resident_bytes();
  check_discarded(scene, s, report);
  // The image's checksum beside its speed (the history stores both in one row).
  report.extra["film_hash"] = film_hash(film);
}

void prepare_film(const Scene& scene, const RenderSettings& s, const RunOptions& options, Film& film) {
  const bool variance = s.variance || options.keep_variance || film.has_variance();
  if (film.width() != s.width || film.height() != s.height || film.has_variance() != variance)
    film = Film(s.width, s.height, variance);
  film.begin(s.spp, scene.max_emission());
}

Rendered render(const Scene& scene, const RenderSettings& settings, const RunOptions& options) {
  Rendered r;
  render(scene, settings, r.film, r.report, options);
  return r;
}

double render_seconds(const RunReport& r) { return r.settings.device == Device::Gpu ? r.device_seconds : r.seconds; }

std::string machine_folder(Device device) {
  if (device == Device::Gpu) return gpu_tracer().machine_slug();
  return machine_slug();
}

}  // namespace pb::run
