#include "pathbench/run/ranks_render.h"

#include "pathbench/run/film_hash.h"

#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <optional>
#include <stdexcept>

#include <fmt/core.h>

#include "pathbench/common/errors.h"
#include "pathbench/run/film_hash.h"
#include "pathbench/run/ranks_report.h"
#include "pathbench/run/run_context.h"
#include "pathbench/run/world.h"
#include "film_setup.h"
#include "gpu_reduce.h"
#include "rank_tracer.h"
#include "pathbench/run/tracer.h"

namespace pb::run {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

RankFailure failure_of(std::exception_ptr e, int rank) {
  try {
    std::rethrow_exception(e);
  } catch (const InputError& x) {
    return {rank, kExitBadInput, x.what()};
  } catch (const std::exception& x) {
    return {rank, kExitFailed, x.what()};
  }
}

// After an agreement: the failure, thrown as on_every_rank documents.
void throw_agreed(const World& w, const RankFailure& f) {
  if (!f.failed()) return;
  if (!w.root()) throw PeerFailure(f.code);
  const std::string message = fmt::format("rank {} of {}: {}", f.rank, w.size(), f.message);
  if (f.code == kExitBadInput) throw InputError(message);
  throw std::runtime_error(message);
}

// A CPU rank's threads: the cores the launcher bound it to, or where it bound none
// (mpirun --bind-to none), this node's cores less one per GPU rank, shared by its CPU ranks.
int cpu_share(const std::vector<std::string>& local_devices) {
  cpu_set_t set;
  CPU_ZERO(&set);
  const int bound = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : hardware_threads();
  if (bound < hardware_threads()) return std::max(1, bound);
  const int gpus = int(std::count(local_devices.begin(), local_devices.end(), "gpu"));
  const int cpus = std::max<int>(1, int(local_devices.size()) - gpus);
  return std::max(1, (hardware_threads() - gpus) / cpus);
}

// PATHBENCH_RANK_FILM_HASH (diagnostics, issue 30): 1 puts each CPU rank's own film hash
// (before the reduction) in its report entry; unset, empty or 0: not. Anything else is refused.
bool rank_film_hash_asked() {
  const char* e = std::getenv("PATHBENCH_RANK_FILM_HASH");
  const std::string v = e ? e : "";
  if (v.empty() || v == "0") return false;
  if (v == "1") return true;
  throw InputError(fmt::format("PATHBENCH_RANK_FILM_HASH='{}': expected 1 (each CPU rank's film hash in its "
                               "report entry) or 0",
                               v));
}

int gpu_count() {
  return gpu_tracer().device_count();  // no context yet: the rank has not picked its GPU
}
}  // namespace

void on_every_rank(const std::function<void()>& step) {
  World& w = World::get();
  if (!w.mpi()) return step();
  RankFailure mine;
  try {
    step();
  } catch (const PeerFailure&) {
    throw;
  } catch (...) {
    mine = failure_of(std::current_exception(), w.rank());
  }
  throw_agreed(w, w.agree(mine));
}

std::string rank_device(const std::string& asked) {
  if (asked != "hybrid") return asked;
  World& w = World::get();
  if (w.size() < 2)
    throw InputError("--device hybrid: needs two or more MPI ranks (mpirun -np 2 pathbench render --device hybrid "
                     "...): one process renders on one device");
  // One GPU rank per visible GPU, at least one, and at least one CPU rank per node.
  const int gpu_ranks = std::max(1, std::min(gpu_count(), w.local_size() - 1));
  return w.local_rank() < gpu_ranks ? "gpu" : "cpu";
}

std::string settings_key(const Scene& scene, const RenderSettings& s) {
  // FNV-1a over the scene's arrays: two nodes' copies of a scene file must agree.
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  mix(scene.positions.data(), scene.positions.size() * sizeof(scene.positions[0]));
  mix(scene.triangles.data(), scene.triangles.size() * sizeof(scene.triangles[0]));
  mix(scene.material_ids.data(), scene.material_ids.size() * sizeof(uint32_t));
  mix(scene.materials.data(), scene.materials.size() * sizeof(scene.materials[0]));
  return fmt::format(
      "scene={} scene_hash={:016x} width={} height={} spp={} bounces={} sampling={} strategy={} seed={} rr={} "
      "rr_start={} paths_in_flight={} variance={} watertight={} precision={} embree_layout={} isa={} instancing={}",
      scene.name, h, s.width, s.height, s.spp, s.max_bounces, to_string(s.sampling), to_string(s.strategy), s.seed,
      s.russian_roulette, s.rr_start_depth, s.paths_in_flight, s.variance, s.watertight, to_string(s.precision),
      to_string(s.embree_layout), to_string(s.isa), to_string(s.instancing));
}

bool render_ranks(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report,
                  const RunOptions& options, const std::string& run_key) {
  World& w = World::get();
  if (!w.mpi() || w.size() == 1) {
    render(scene, settings, film, report, options);
    return true;
  }
  // 1. One frame: every rank asks for the same one (MPMD lines may differ in device and threads only).
  const std::string key = settings_key(scene, settings) + (run_key.empty() ? "" : " " + run_key);
  const std::vector<std::string> keys = w.all(key);
  on_every_rank([&] {
    if (keys[size_t(w.rank())] != keys[0])
      throw InputError(fmt::format("its settings differ from rank 0's: {} (MPMD lines may differ only in --device "
                                   "and --threads)", first_difference(keys[0], keys[size_t(w.rank())])));
  });
  // 2. Each rank's device: GPU ranks take local rank % visible GPUs, CPU ranks their cores.
  const std::vector<std::string> local_devices = w.local_all(to_string(settings.device));
  const std::vector<std::string> devices = w.all(to_string(settings.device));
  RenderSettings s = settings;
  std::unique_ptr<RankTracer> tracer;
  int gpu_index = -1;
  bool rank_film_hash = false;
  on_every_rank([&] { rank_film_hash = rank_film_hash_asked(); });
  // What a tracer measures to prepare the scene (the CPU's Embree layout under auto: a timed
  // probe) is rank 0's on every rank (Tracer::measured): each rank probing for itself, beside
  // the others' start, once picked another layout on one rank of three (a film differing in
  // low bits, the same image bytes: issue 30, docs/mpi.md). CPU ranks beside GPUs trace the
  // GPU's BVH and measure nothing.
  const bool all_cpu = std::find(devices.begin(), devices.end(), "gpu") == devices.end();
  std::string measured;
  on_every_rank([&] {
    if (all_cpu && w.root()) measured = cpu_tracer().measured(scene, s);
  });
  measured = w.all(measured)[0];
  on_every_rank([&] {
    if (all_cpu && !w.root() && !cpu_tracer().adopt_measured(scene, s, measured))
      throw std::runtime_error(fmt::format("rank 0's measured choices cannot be read: '{}'", measured));
  });
  on_every_rank([&] {
    // Before any other CUDA call (RankTracer's device check), so the rank's context is on its GPU.
    if (s.device == Device::Gpu) gpu_index = gpu_tracer().select_device(w.local_rank());
    if (s.device == Device::Cpu && s.threads == 0) s.threads = cpu_share(local_devices);
    // A CPU rank beside GPU ranks traces the GPU's samples, bit for bit (the hybrid's
    // image is then one GPU's, whichever rank took which chunk).
    const bool beside_gpus = std::find(devices.begin(), devices.end(), "gpu") != devices.end();
    const bool gpu_samples = s.device == Device::Cpu && beside_gpus;
    tracer = std::make_unique<RankTracer>(scene, s, options, gpu_samples);
    // What the rank's tracer runs (the host tracer of the GPU's samples runs every strategy).
    if (!gpu_samples) validate_for_tracer(s, s.device);
    prepare_film(scene, s, options, film);  // the frame's scale on every rank
    tracer->warm_up(film);
  });
  Balance balance = options.balance;
  if (balance == Balance::Auto)
    balance = std::all_of(devices.begin(), devices.end(), [&](const auto& d) { return d == devices[0]; })
                  ? Balance::Static : Balance::Dynamic;
  if (!w.can_dispense()) balance = Balance::Static;
  // CPU ranks of the pixel strategy take whole batches of samples, aligned as one process's
  // packets (kSampleBatch, ranks.h); every other rank traces each ray alone.
  const uint32_t batch = all_cpu && s.strategy == Strategy::Pixel ? kSampleBatch : 1;
  // How the films come together: GPU ranks through NCCL where they can (gpu_reduce.h),
  // the rest through MPI. Set up (communicator, page-locked film on the GPU root) before
  // the frame's clock starts.
  GpuReduction gred;
  on_every_rank([&] { gred = prepare_gpu_reduction(w, s.device == Device::Gpu, gpu_index); });
  const bool cpu_ranks = std::find(devices.begin(), devices.end(), "cpu") != devices.end();
  // MPI has nothing left to add where NCCL brought every film to rank 0.
  const bool mpi_after_nccl = cpu_ranks || gred.root != 0;
  // A GPU rank that downloads a film it keeps (NCCL's root, or every GPU rank without NCCL)
  // downloads into page-locked memory.
  PinnedFilm pinned(film, s.device == Device::Gpu && (!gred.nccl || w.rank() == gred.root));
  // Overlap: a static split over GPU ranks alone traces in bands of rows and reduces each
  // band on NCCL's stream while the next traces (gpu_reduce.h: reduction_bands); 1: at the end.
  // (The count from rank 0's share, the largest: the same on every rank.)
  const uint64_t rank_samples = uint64_t(s.width) * s.height * share_of(0, uint32_t(w.size()), s.spp).count;
  const uint32_t bands = gred.nccl && !cpu_ranks && balance == Balance::Static
                             ? reduction_bands(rank_samples, s.height, gred.bands_asked) : 1;
  on_every_rank([&] { warm_gpu_reduction(gred, tracer->device_film(), bands > 1 && w.rank() == gred.root); });
  // Dynamic balancing: a rank's probe chunk measures its rate: ~2 M samples fill a GPU (an
  // H100 runs ~270 k threads at once), 64 per thread keep a CPU rank's short. Each rank
  // traces one before the frame's clock starts (as it warms up), and every rank's rate
  // seeds the dispenser, so the first grants already follow the rates: a GPU that does
  // nearly all of the work takes the frame in one chunk.
  const uint64_t probe_samples = s.device == Device::Gpu ? uint64_t(1) << 21 : uint64_t(std::max(1, s.threads)) * 64;
  const uint64_t probe = std::max<uint64_t>(1, (probe_samples + s.width - 1) / s.width);
  std::vector<double> rates;
  if (balance == Balance::Dynamic) {
    double rate = 0;
    on_every_rank([&] {
      const uint64_t n = std::min<uint64_t>(probe, uint64_t(s.height) * s.spp);
      double seconds = 0;
      for (const FrameBlock& b : blocks_of({0, n}, s.spp, s.height)) seconds += tracer->calibrate(b, film, scene.max_emission());
      rate = seconds > 0 ? double(n) / seconds : 0.0;
    });
    for (const std::string& r : w.all(fmt::format("{:a}", rate))) rates.push_back(std::strtod(r.c_str(), nullptr));
  }

  // Dynamic balancing only: rank 0 then serves it (its units: rows x samples). Made before
  // the frame's clock (rank 0's server thread), started after the common start.
  std::optional<SampleDispenser> dispenser;
  if (balance == Balance::Dynamic) dispenser.emplace(w, uint64_t(s.height) * s.spp, rates, s.spp, batch);

  // 3. The frame: from a common start to the reduced film on rank 0.
  const nlohmann::json load0 = load_sample();
  w.barrier();
  const Clock::time_point t0 = Clock::now();
  if (dispenser) dispenser->start();
  RunReport mine;
  RankFailure failed;
  uint64_t samples = 0;           // (pixel, sample) pairs this rank traced
  std::vector<RowRange> rows;     // dynamic: the rows this rank traced (all its film holds)
  int chunks = 0;
  uint64_t granted = 0;  // rank 0, dynamic: chunks handed out in all
  auto trace = [&](const FrameBlock& b) {
    tracer->trace(b, film, mine);
    samples += uint64_t(b.rows) * s.width * b.samples;
    add_rows(rows, b);
  };
  std::vector<int> senders;  // rank 0, dynamic: the other ranks that were granted samples
  {
    try {
      if (balance == Balance::Static && bands > 1) {
        // Every GPU rank starts every band's reduction, in order: a rank with no samples, or
        // whose tracer failed (the agreement below then ends the frame), too, so that no
        // rank's NCCL stream waits for a band that never comes.
        const SampleShare share = share_of(uint32_t(w.rank()), uint32_t(w.size()), s.spp);
        for (uint32_t k = 0; k < bands; ++k) {
          const auto [first_row, rows] = band_rows(k, bands, s.height);
          try {
            if (!failed.failed() && share.count && rows) trace({first_row, rows, share.first, share.count}), ++chunks;
          } catch (...) {
            failed = failure_of(std::current_exception(), w.rank());
          }
          reduce_gpu_band(gred, tracer->device_film(), film, w.rank() == gred.root, first_row, rows);
        }
      } else if (balance == Balance::Static) {
        const SampleShare share = share_of(uint32_t(w.rank()), uint32_t(w.size()), s.spp, batch);
        if (share.count) trace({0, s.height, share.first, share.count}), ++chunks;
      } else {
        double rate = rates.empty() ? 0.0 : rates[size_t(w.rank())];  // units per second in the last chunk
        for (;;) {
          const UnitRange range = dispenser->next(rate, probe);
          if (range.count == 0) break;
          const double before = mine.seconds;
          for (const FrameBlock& b : blocks_of(range, s.spp, s.height)) trace(b);
          if (mine.seconds > before) rate = double(range.count) / (mine.seconds - before);
          ++chunks;
        }
      }
    } catch (...) {
      failed = failure_of(std::current_exception(), w.rank());
      if (dispenser) dispenser->abort();
    }
    if (dispenser) dispenser->finish();
    throw_agreed(w, w.agree(failed));
    if (dispenser && w.root()) granted = dispenser->chunks_granted(), senders = dispenser->ranks_granted();
  }
  // PATHBENCH_RANK_FILM_HASH=1 (diagnostics, issue 30): each CPU rank's own film before the
  // reduction, hashed into its report entry, so that runs that differ say whether a rank's
  // samples or the reduction did. Costs each such rank a pass over its film inside the frame,
  // which the others wait for in the reduction's agreement: a rank that traced nothing (the
  // hybrid's CPU rank beside a GPU that took the frame) holds the zero film and hashes nothing
  // (at 2048x2048 that pass delayed the 2 x H100 hybrid's frame by ~25 ms, 0.97x the GPU alone).
  const std::string part_hash =
      rank_film_hash && s.device == Device::Cpu && samples > 0 ? film_hash(film) : std::string();
  const double busy_wall = since(t0);
  const Clock::time_point r0 = Clock::now();
  const double wait_seconds = std::chrono::duration<double>(r0 - t0).count() - mine.seconds;
  double bound_seconds = 0, nccl_seconds = 0, download_seconds = 0, mpi_seconds = 0;
  bool by_nccl = false;
  on_every_rank([&] {
    // GPU ranks: added on the GPUs onto the lowest GPU rank, which alone downloads the sum
    // (banded: the bands' reductions and downloads started as they were traced: the rest of them).
    bool downloaded = false;
    if (bands > 1) downloaded = by_nccl = finish_gpu_bands(w, gred, tracer->device_film(), bound_seconds, nccl_seconds);
    else by_nccl = reduce_gpu_films(w, gred, tracer->device_film(), bound_seconds, nccl_seconds);
    const Clock::time_point d0 = Clock::now();
    if (!by_nccl || (w.rank() == gred.root && !downloaded)) tracer->finish(film, mine);  // GPU ranks: the download
    download_seconds = since(d0);
    const Clock::time_point m0 = Clock::now();
    if (by_nccl && !mpi_after_nccl) return;
    if (by_nccl) {
      // The GPU ranks' sum, on gred.root, travels to rank 0 as rows, with the CPU ranks' rows.
      std::vector<RowRange> send = rows;
      if (s.device == Device::Gpu) send = w.rank() == gred.root ? std::vector<RowRange>{{0, s.height}}
                                                                : std::vector<RowRange>{};
      else if (balance == Balance::Static) send = {{0, s.height}};
      w.reduce_film_rows(film, send);
    } else {
      // A static split's ranks each hold every pixel (MPI_Reduce); dynamic chunks' ranks hold
      // bands of rows, and only those travel, from the ranks rank 0 granted samples: a rank
      // that traced nothing (a CPU rank beside a GPU that took the frame) sends nothing and
      // rank 0 waits for no collective (issue 30).
      balance == Balance::Dynamic ? w.send_film_rows(film, rows, senders) : w.reduce_film(film);
    }
    mpi_seconds = since(m0);
  });
  const double reduce_seconds = since(r0), frame_seconds = since(t0);

  // 4. One report, on rank 0.
  mine.peak_host_bytes = peak_resident_bytes();
  nlohmann::json entry = rank_entry(w.rank(), w.host(), s, mine, gpu_index, samples, chunks, busy_wall);
  // Where this rank's frame went: tracing (its tracer calls), waiting (chunk requests, the
  // slowest rank), and the reduction (bound check, NCCL, the download, MPI).
  if (!part_hash.empty()) entry["film_hash"] = part_hash;  // this rank's film before the reduction
  if (mine.extra.contains("embree_layout")) entry["embree_layout"] = mine.extra["embree_layout"];  // the layout it traced
  entry["trace_seconds"] = mine.seconds;
  entry["wait_seconds"] = std::max(0.0, wait_seconds);
  entry["reduce_seconds"] = reduce_seconds;
  entry["reduce_parts"] = {{"overflow_bound", bound_seconds}, {"nccl", nccl_seconds},
                           {"download", download_seconds}, {"mpi", mpi_seconds}};
  const std::vector<std::string> ranks = w.gather(entry.dump());
  on_every_rank([&] {
    if (!w.root()) return;
    report = mine;
    report.scene = scene.name;
    report.triangles = scene.triangles.size();
    report.settings = settings;
    report.settings.threads = s.threads;
    report.load = load_between(load0, load_sample());
    report.fingerprint = run_fingerprint(s.device == Device::Gpu);
    merge_ranks(report, ranks, frame_seconds, reduce_seconds, balance == Balance::Dynamic ? "dynamic" : "static");
    if (balance == Balance::Dynamic) report.extra["ranks"]["chunks_granted"] = granted;
    report.extra["ranks"]["reduction"] = {
        {"gpu_ranks", by_nccl ? "nccl" : "mpi"}, {"why", gred.why},
        {"bands", bands},  // > 1: reduced band by band while the next band traced (gpu_reduce.h)
        {"nccl_version", gred.nccl_version.empty() ? nlohmann::json(nullptr) : nlohmann::json(gred.nccl_version)},
        {"share_of_frame", frame_seconds > 0 ? reduce_seconds / frame_seconds : 0.0}};
    check_discarded(scene, settings, report);
    report.extra["film_hash"] = film_hash(film);  // the reduced film's: the same as one process's
  });
  return w.root();
}

}  // namespace pb::run
