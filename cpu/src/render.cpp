#include "pathbench/cpu/render.h"

#include <fmt/core.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "pathbench/cpu/embree_scene.h"
#include "pathbench/cpu/isa.h"
#include "pathbench/common/errors.h"
#include "strategies.h"

namespace pb::cpu {

uint64_t default_paths_in_flight(int threads) { return uint64_t(threads) * 4096; }

nlohmann::json instancing_report(const Scene& scene, const EmbreeScene& embree, Instancing asked) {
  const auto& f = embree.instancing();
  const bool used = embree.instanced();
  const char* why = used                     ? "Embree instances of the scene's prototypes"
                    : scene.instances.empty() ? "the scene has no instances: traced flat"
                    : asked == Instancing::Off ? "asked off: traced flat"
                    : asked == Instancing::Auto
                        ? "auto on the CPU: traced flat, bit for bit (Embree instances may name another triangle "
                          "at a copy's edges; --instancing on uses them)"
                        : "the quads layout asked for: traced flat";
  return InstancingSummary{asked, used, why, scene.instances.size(), scene.prototypes.size(), f.instances,
                           f.prototypes, f.instances_left_flat, used ? f.flat_triangles : scene.triangles.size(),
                           uint64_t(std::max<int64_t>(0, embree.bytes())), embree.build_seconds()}
      .to_json();
}

void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report) {
  render(scene, *make_embree_scene(scene, settings.watertight, settings.embree_layout, settings.instancing), settings,
         film, report);
}

void render(const Scene& scene, const EmbreeScene& embree, const RenderSettings& settings, Film& film,
            RunReport& report) {
  if (film.width() != settings.width || film.height() != settings.height)
    throw std::logic_error("film size does not match the settings");
  const Isa isa = resolve_isa(settings.isa);  // InputError where the CPU lacks the asked ISA

  std::unique_ptr<tbb::global_control> limit;
  if (settings.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, settings.threads);
  const int threads = settings.threads > 0 ? settings.threads : tbb::this_task_arena::max_concurrency();

  Progress progress(fmt::format("render {} cpu/{}", scene.name, to_string(settings.strategy)),
                    settings.traced_samples(), settings.progress);
  // Samples [first_sample, first_sample + traced_spp()) of each pixel of rows [first_row,
  // first_row + traced_rows()) (an MPI rank's share or chunk).
  TraceJob job{embree, scene.view(), settings.path_config(), settings.traced_rows(), film,
               progress, isa};

  const auto t0 = std::chrono::steady_clock::now();
  // A pool larger than the frame's samples would only hold empty slots (--paths-in-flight 1e8 for 64
  // samples once took 10 GB).
  const uint64_t pif = std::min(settings.paths_in_flight ? settings.paths_in_flight : default_paths_in_flight(threads),
                                std::max<uint64_t>(1, settings.traced_samples()));
  const bool dbl = settings.precision == Precision::Double;
  TraceTotals totals;
  if (settings.strategy == Strategy::Pixel) {
    totals = dbl ? render_pixel_parallel<double>(job) : render_pixel_parallel<float>(job);
  } else {
    totals = dbl ? render_wavefront<double>(job, pif) : render_wavefront<float>(job, pif);
  }
  const auto t1 = std::chrono::steady_clock::now();
  progress.finish();

  report.seconds = std::chrono::duration<double>(t1 - t0).count();
  report.rays = totals.rays;
  report.paths = totals.paths;
  report.discarded_samples = totals.discarded;
  report.state_bytes_per_path = totals.state_bytes_per_path;
  report.paths_in_flight = totals.paths_in_flight;
  report.threads = threads;
  report.tracer_host_bytes =
      film.bytes() + totals.pool_bytes + totals.table_bytes + uint64_t(std::max<int64_t>(0, embree.peak_bytes()));
  report.extra["embree_bytes"] = embree.peak_bytes();
  const LayoutChoice& layout = embree.layout_choice();
  report.extra["embree_layout"] = {{"asked", to_string(settings.embree_layout)},
                                   {"used", to_string(layout.layout)},
                                   {"why", layout.reason},
                                   {"probe_ns_per_ray", nullptr}};
  if (layout.triangles_ns > 0)
    report.extra["embree_layout"]["probe_ns_per_ray"] = {{"triangles", layout.triangles_ns}, {"quads", layout.quads_ns}};
  report.extra["instancing"] = instancing_report(scene, embree, settings.instancing);
  // The ISA the path step ran with (scalar where the batched one does not apply:
  // double, other materials, big scenes), the one asked, and what the CPU offers.
  report.extra["isa"] = to_string(totals.isa);
  report.extra["isa_asked"] = to_string(settings.isa);
  report.extra["cpu_flags"] = cpu_vector_flags();
  report.extra["film_bytes"] = film.bytes();
  report.extra["pool_bytes"] = totals.pool_bytes;
  report.extra["shade_table_bytes"] = totals.table_bytes;
}

}  // namespace pb::cpu
