// Ray-parallel ("wavefront") CPU strategy. Each thread owns a slice of the pool of
// paths in flight and runs the stages over the whole slice in turn:
//   generate (fill free slots with new samples) -> final vertex (paths whose next hit
//   can only add emission: emitter query instead of a closest hit) -> intersect (packets
//   of W rays) -> shade (shared path step) -> shadow (packets of W) -> accumulate
// Memory is the pool, fixed by --paths-in-flight, never width x height x spp.
// Diffuse-only float renders with a vector ISA (--isa; the paper's benchmark) run
// generate, final vertex and shade a vector's width of paths at a time (BatchKernels,
// shade_x8.h: the path step's arithmetic lane-wise in its own order, so the image stays
// bit-identical to the pixel strategy's); everything else runs the scalar path step one
// path at a time. Packets are 16 rays (rtcIntersect16) with AVX-512, 8 otherwise.
// Compiled for one set of material kinds per translation unit (PB_CPU_KINDS,
// features.h): diffuse-only here, every kind in render_wavefront_all_kinds.cpp, so the
// diffuse-only code compiles exactly as in a build without the other kinds.
#include <fmt/core.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <memory>
#include <type_traits>
#include <unistd.h>
#include <vector>

#include "embree_rays.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/path.h"
#include "shade_batch.h"
#include "strategies.h"
#include "tiny_scene.h"
#include "wavefront_pool.h"

#ifndef PB_CPU_KINDS
#define PB_CPU_KINDS kDiffuseOnly
#endif

namespace pb::cpu {

namespace {

// Packet width W: the batch's width, so one batch of rays is one packet: 16 with
// AVX-512 (Embree's AVX-512 kernels trace 16 natively), 8 with AVX2 and for the scalar
// path step. (Measured with callgrind on an AVX2 machine: 16-wide packets ran through
// the same Embree kernel at the same instruction count there.)
// (intersect_packet, occluded_packet: embree_rays.h.)

// With kernels `k` (float, a vector ISA) k->lanes new paths at a time (begin_paths).
template <class T>
PB_CPU_FLATTEN void stage_generate(const TraceJob& job, const BatchKernels* k, SampleSource& src, PoolSlice<T>& pool) {
  uint64_t n = pool.free.size();
  if (n == 0) return;
  const uint64_t start = src.claim(n);
  uint64_t i = 0;
  if constexpr (std::is_same_v<T, float>) {
    if (k) {
      const int width = k->lanes;
      for (; i < n; i += uint64_t(width)) {
        const int lanes = int(std::min<uint64_t>(uint64_t(width), n - i));
        uint32_t pixel[kMaxShadeLanes], sample[kMaxShadeLanes];
        PathState<float>* st[kMaxShadeLanes];
        for (int l = 0; l < width; ++l) {
          const uint64_t g = start + i + uint64_t(l < lanes ? l : 0);
          pixel[l] = src.pixel_of(g);
          sample[l] = src.sample_of(g);
          if (l < lanes) {
            st[l] = &pool.state[pool.free.back()];
            pool.live.push_back(pool.free.back());
            pool.free.pop_back();
          } else {
            st[l] = st[0];
          }
        }
        k->begin_paths(job.scene, job.config, pixel, sample, st, lanes);
      }
      return;
    }
  }
  for (; i < n; ++i) {
    const uint32_t slot = pool.free.back();
    pool.free.pop_back();
    path_begin(job.scene, job.config, src.pixel_of(start + i), src.sample_of(start + i), pool.state[slot]);
    pool.live.push_back(slot);
  }
}

// Paths whose next hit could only add emitted light leave the live list here: their
// occlusion test (if they face an emitter) joins the shadow stage, and they are done.
// With kernels `k` (float, a vector ISA: see batched_shading_table) k->lanes paths at a
// time are first screened for an emitter along their ray (shade_x8.h); the scalar query
// runs only for the lanes that may have one, and gives every path what it would have
// given it anyway.
template <class T, uint32_t Kinds>
PB_CPU_FLATTEN void stage_final_vertex(const TraceJob& job, const BatchKernels* k, PoolSlice<T>& pool, Local& local) {
  auto final_query = [&](uint32_t slot) {
    const PathState<T>& st = pool.state[slot];
    if (path_final_query<Kinds>(job.scene, job.config, st, pool.shadow[slot])) {
      pool.shadowed.push_back(slot);
      count_ray(local.rays, st.depth, &RayCounts::shadow);
    }
    pool.done.push_back(slot);
  };
  PathState<float>* lanes[kMaxShadeLanes];
  uint32_t lane_slots[kMaxShadeLanes];
  int n = 0;
  auto flush = [&] {
    if constexpr (std::is_same_v<T, float>) {
      for (int i = n; i < k->lanes; ++i) lanes[i] = lanes[0];
      bool candidate[kMaxShadeLanes];
      k->final_vertex_candidates(job.scene, lanes, candidate);
      for (int i = 0; i < n; ++i) {
        if (candidate[i]) final_query(lane_slots[i]);
        else pool.done.push_back(lane_slots[i]);
      }
    }
    n = 0;
  };
  size_t keep = 0;
  for (uint32_t slot : pool.live) {
    const PathState<T>& st = pool.state[slot];
    if (!path_at_final_vertex(job.scene, job.config, st)) {
      pool.live[keep++] = slot;
      continue;
    }
    if constexpr (std::is_same_v<T, float>) {
      if (k) {
        lanes[n] = &pool.state[slot];
        lane_slots[n] = slot;
        if (++n == k->lanes) flush();
        continue;
      }
    }
    final_query(slot);
  }
  if (n > 0) flush();
  pool.live.resize(keep);
}

// The rays of records[slots[0..n)] (path states or shadow queries, whose first six floats
// are the ray) into a packet by one transpose (k->rays_to_packet, whose width is W);
// false (nothing done) without kernels or for double records, which the caller
// converts lane by lane (set_lane).
template <int W, class Record>
bool rays_to_packet(const BatchKernels* k, const std::vector<Record>& records, const uint32_t* slots, int n,
                    RTCRayNt<W>& r) {
  if constexpr (std::is_same_v<Record, PathState<float>> || std::is_same_v<Record, ShadowQuery<float>>) {
    if (!k) return false;
    const void* rows[W];
    for (int i = 0; i < W; ++i) rows[i] = &records[slots[i < n ? i : 0]];
    float* const out[6] = {r.org_x, r.org_y, r.org_z, r.dir_x, r.dir_y, r.dir_z};
    k->rays_to_packet(rows, out);
    return true;
  }
  return false;
}

// With kernels `k` (float, a vector ISA) each packet's rays come by one transpose
// (rays_to_packet) instead of lane by lane.
// With `tiny` (and k) the tiny-scene test answers first, Embree only where it is unsure.
template <int W, class T>
void stage_intersect(const TraceJob& job, const BatchKernels* k, const TinyScene* tiny, PoolSlice<T>& pool,
                     RTCIntersectContext& ctx, Local& local) {
  alignas(64) RTCRayHitNt<W> packet;
  alignas(64) int valid[W];
  init_packet_constants(packet.ray);
  for (size_t base = 0; base < pool.live.size(); base += W) {
    const int n = int(std::min<size_t>(W, pool.live.size() - base));
    const uint32_t* slots = &pool.live[base];
    const bool filled = rays_to_packet<W>(k, pool.state, slots, n, packet.ray);
    for (int i = 0; i < W; ++i) {
      valid[i] = i < n ? -1 : 0;
      if (i < n) {
        const PathState<T>& st = pool.state[slots[i]];
        count_ray(local.rays, st.depth, &RayCounts::bounce);
        if (!filled) set_lane(packet.ray, i, st.ray, kInfinity);
      }
      packet.ray.tfar[i] = kInfinity;
      packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    }
    if (tiny && filled) {
      uint32_t prim[W];
      tiny_closest<W>(*k, *tiny, job.embree, ctx, packet, n, prim);
      for (int i = 0; i < n; ++i) pool.prim[slots[i]] = prim[i];
      continue;
    }
    intersect_packet(valid, job.embree.handle(), &ctx, packet);
    for (int i = 0; i < n; ++i) pool.prim[slots[i]] = packet_triangle(job.embree, packet, i);
  }
}

// Diffuse-only scenes in float (the paper's case) with a vector ISA: k.lanes paths at a
// time (shade_x8.h), bit-identical to the scalar path step below.
PB_CPU_FLATTEN void stage_shade_batched(const TraceJob& job, const BatchKernels& k, const ShadeTable& table,
                                        PoolSlice<float>& pool, Local& local) {
  pool.next_live.clear();
  ShadeBatch batch;
  auto flush = [&] {
    for (int i = batch.lanes; i < k.lanes; ++i) {  // idle lanes repeat lane 0
      batch.st[i] = batch.st[0];
      batch.shadow[i] = batch.shadow[0];
      batch.prim[i] = batch.prim[0];
    }
    k.shade_diffuse(job.scene, job.config, table, batch);
    for (int i = 0; i < batch.lanes; ++i) {
      const uint32_t slot = uint32_t(batch.st[i] - pool.state.data());
      if (batch.wants_shadow[i]) {
        pool.shadowed.push_back(slot);
        ++local.rays.shadow;
      }
      (batch.cont[i] ? pool.next_live : pool.done).push_back(slot);
    }
    batch.lanes = 0;
  };
  batch.lanes = 0;
  for (uint32_t slot : pool.live) {
    if (pool.prim[slot] == RTC_INVALID_GEOMETRY_ID) {
      pool.done.push_back(slot);
      continue;
    }
    batch.st[batch.lanes] = &pool.state[slot];
    batch.shadow[batch.lanes] = &pool.shadow[slot];
    batch.prim[batch.lanes] = pool.prim[slot];
    if (++batch.lanes == k.lanes) flush();
  }
  if (batch.lanes > 0) flush();
  std::swap(pool.live, pool.next_live);
}

// `table`: non-null where the batched shading runs (batched_shading_table), with `k`.
template <class T, uint32_t Kinds>
PB_CPU_FLATTEN void stage_shade(const TraceJob& job, const BatchKernels* k, const ShadeTable* table, PoolSlice<T>& pool,
                                Local& local) {
  if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly) {
    if (table) {
      stage_shade_batched(job, *k, *table, pool, local);
      return;
    }
  }
  pool.next_live.clear();
  for (uint32_t slot : pool.live) {
    PathState<T>& st = pool.state[slot];
    if (pool.prim[slot] == RTC_INVALID_GEOMETRY_ID) {
      pool.done.push_back(slot);
      continue;
    }
    bool wants_shadow;
    const PathEvent ev =
        path_hit<Kinds>(job.scene, job.config, st, surface_hit(job.scene, pool.prim[slot], st.ray), pool.shadow[slot], wants_shadow);
    if (wants_shadow) {
      pool.shadowed.push_back(slot);
      ++local.rays.shadow;
    }
    if (ev == PathEvent::Continue) pool.next_live.push_back(slot);
    else pool.done.push_back(slot);
  }
  std::swap(pool.live, pool.next_live);
}

template <int W, class T>
void stage_shadow(const TraceJob& job, const BatchKernels* k, const TinyScene* tiny, PoolSlice<T>& pool,
                  RTCIntersectContext& ctx) {
  alignas(64) RTCRayNt<W> packet;
  alignas(64) int valid[W];
  init_packet_constants(packet);
  for (size_t base = 0; base < pool.shadowed.size(); base += W) {
    const int n = int(std::min<size_t>(W, pool.shadowed.size() - base));
    const uint32_t* slots = &pool.shadowed[base];
    const bool filled = rays_to_packet<W>(k, pool.shadow, slots, n, packet);
    for (int i = 0; i < W; ++i) {
      valid[i] = i < n ? -1 : 0;
      if (i < n && !filled) set_lane(packet, i, pool.shadow[slots[i]].ray, 1.0f);
      packet.tfar[i] = 1.0f;
    }
    if (tiny && filled) {
      bool blocked[W];
      tiny_occluded<W>(*k, *tiny, job.embree, ctx, packet, n, blocked);
      for (int i = 0; i < n; ++i)
        if (!blocked[i]) shadow_unoccluded(pool.state[slots[i]], pool.shadow[slots[i]]);
      continue;
    }
    occluded_packet(valid, job.embree.handle(), &ctx, packet);
    for (int i = 0; i < n; ++i) {
      const uint32_t slot = slots[i];
      if (packet.tfar[i] >= 0.0f) shadow_unoccluded(pool.state[slot], pool.shadow[slot]);
    }
  }
  pool.shadowed.clear();
}

template <class T> void stage_accumulate(const TraceJob& job, PoolSlice<T>& pool, Local& local) {
  for (uint32_t slot : pool.done) {
    const PathState<T>& st = pool.state[slot];
    if (!job.film.add_atomic(st.pixel, Vec3f(st.L))) ++local.discarded;
    pool.free.push_back(slot);
  }
  local.paths += pool.done.size();
  job.progress.advance(pool.done.size());
  pool.done.clear();
}

// The stages above, in scalar type T, compiled for the material kinds `Kinds`
// (features.h), with packets of W rays; `k` (width W) where the batched path step runs.
template <class T, uint32_t Kinds, int W>
TraceTotals wavefront(const TraceJob& job, uint64_t paths_in_flight, const BatchKernels* k,
                      std::unique_ptr<ShadeTable> table) {
  const uint32_t pixels = job.config.width * job.config.height;
  SampleSource source(uint64_t(pixels) * job.spp, pixels, job.config.first_sample);
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
  tbb::parallel_for(0, slices, [&](int) {
    Local& local = locals.local();
    PoolSlice<T> pool(per_slice);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (;;) {
      stage_generate(job, k, source, pool);
      if (pool.live.empty()) break;
      stage_final_vertex<T, Kinds>(job, k, pool, local);
      stage_intersect<W>(job, k, tiny.get(), pool, ctx, local);
      stage_shade<T, Kinds>(job, k, table.get(), pool, local);
      stage_shadow<W>(job, k, tiny.get(), pool, ctx);
      stage_accumulate(job, pool, local);
    }
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
