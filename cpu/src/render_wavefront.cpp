// Ray-parallel ("wavefront") CPU strategy: a pool of paths in flight (wavefront_pool.h),
// one slice of it per thread, each running the stages of render_wavefront_slice.h round after
// round until the frame's samples are all handed out and traced. This file sizes the pool,
// runs the slices and sums their counts.
// Memory is the pool, fixed by --paths-in-flight, never width x height x spp.
// Packets are 16 rays (rtcIntersect16) with AVX-512, 8 otherwise.
// Compiled for one set of material kinds per translation unit (PB_CPU_KINDS,
// features.h): diffuse-only here, every kind in render_wavefront_all_kinds.cpp, so the
// diffuse-only code compiles exactly as in a build without the other kinds.
#include <fmt/core.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <memory>
#include <unistd.h>

#include "pathbench/common/errors.h"
#include "stage_timers.h"
#include "strategies.h"
#include "tiny_scene.h"
#include "wavefront_pool.h"
#include "render_wavefront_slice.h"

#ifndef PB_CPU_KINDS
#define PB_CPU_KINDS kDiffuseOnly
#endif

namespace pb::cpu {

namespace {

// The slices over the pool, one per thread; `k` (width W) where the batched path step runs.
template <class T, uint32_t Kinds, int W>
TraceTotals wavefront(const TraceJob& job, uint64_t paths_in_flight, const BatchKernels* k,
                      std::unique_ptr<ShadeTable> table) {
  // Whole rows from first_pixel on (an MPI rank's band, or the frame).
  SampleSource source(job.config.first_pixel, job.config.width * job.rows, job.config.spp, job.config.first_sample, W);
  const int slices = std::max(1, tbb::this_task_arena::max_concurrency());
  const uint64_t per_slice = std::max<uint64_t>(W, (paths_in_flight + slices - 1) / slices);
  // A pool that cannot fit is a setting to lower, not a std::bad_alloc (exit 2, not 1).
  const double pool_bytes = double(per_slice) * slices * double(PoolSlice<T>::bytes_per_path);
  const double memory = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
  if (memory > 0 && pool_bytes > memory / 2)
    throw InputError(fmt::format("--paths-in-flight {}: the path pool would take {:.1f} GB, more than half of this "
                                 "machine's {:.1f} GB of memory; lower it (0 picks a default)",
                                 paths_in_flight, pool_bytes / 1e9, memory / 1e9));
  const std::unique_ptr<TinyScene> tiny = tiny_scene_for(job.embree, job.scene, k);
  tbb::combinable<Local> locals;
  PB_STAGE_RENDER("wavefront", slices);
  tbb::parallel_for(0, slices, [&](int) {
    PB_STAGE_THREAD();
    auto slice = std::make_unique<Slice<T, Kinds, W>>(job, k, table.get(), tiny.get(), source, per_slice, locals.local());
    slice->run();
  }, tbb::static_partitioner());
  TraceTotals t;
  locals.combine_each([&](const Local& l) {
    t.rays += l.rays;
    t.paths += l.paths;
    t.discarded += l.discarded;
  });
  t.state_bytes_per_path = PoolSlice<T>::bytes_per_path;
  t.paths_in_flight = per_slice * uint64_t(slices);
  t.pool_bytes = t.paths_in_flight * PoolSlice<T>::bytes_per_path;
  t.table_bytes = table ? table->rows.size() * sizeof(float) : 0;
  t.isa = k ? k->isa : Isa::Scalar;
  return t;
}

}  // namespace

// The entry point of this translation unit's instantiations (strategies.h).
// The batched path step where it applies (job.isa a vector ISA, float, diffuse-only, a
// small enough scene); packets as wide as its lanes.
template <class T, uint32_t Kinds> TraceTotals render_wavefront_for(const TraceJob& job, uint64_t paths_in_flight) {
  std::unique_ptr<ShadeTable> table = batched_shading_table<T, Kinds>(job.scene, job.isa);
  const BatchKernels* k = table ? batch_kernels(job.isa) : nullptr;
  if (k && k->lanes == 16) return wavefront<T, Kinds, 16>(job, paths_in_flight, k, std::move(table));
  return wavefront<T, Kinds, 8>(job, paths_in_flight, k, std::move(table));
}

template TraceTotals render_wavefront_for<float, PB_CPU_KINDS>(const TraceJob&, uint64_t);
template TraceTotals render_wavefront_for<double, PB_CPU_KINDS>(const TraceJob&, uint64_t);

}  // namespace pb::cpu
