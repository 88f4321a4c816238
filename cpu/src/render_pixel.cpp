// Pixel-parallel CPU strategy, compiled for one set of material kinds per translation
// unit (PB_CPU_KINDS, features.h): diffuse-only here, every kind in
// render_pixel_all_kinds.cpp. The diffuse-only code is then compiled exactly as in a
// build without the other kinds (the compiler's inlining budget is per translation unit).
// Every sample is one path traced with single rays (rtcIntersect1 / rtcOccluded1); for
// diffuse-only float renders on AVX2 CPUs the path steps of up to eight samples of a
// pixel run together, eight lanes wide (trace_samples_x8), bit-identical to trace_path.
#include <tbb/blocked_range2d.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <memory>
#include <type_traits>

#include "embree_rays.h"
#include "pathbench/common/path.h"
#include "shade_batch.h"
#include "strategies.h"

#include "shade_x8_avx2.h"  // avx2::, the batched path step

#ifndef PB_CPU_KINDS
#define PB_CPU_KINDS kDiffuseOnly
#endif

namespace pb::cpu {

namespace {
constexpr uint32_t kTile = 16;

struct Local {
  RayCounts rays;
  uint64_t paths = 0, discarded = 0;
};

// One complete path, single rays: the reference order of operations, in scalar type T
// and compiled for the material kinds `Kinds` (features.h).
template <class T, uint32_t Kinds>
PB_CPU_FLATTEN Vec3f trace_path(const TraceJob& job, RTCIntersectContext& ctx, uint32_t pixel, uint32_t sample, Local& local) {
  PathState<T> st;
  path_begin(job.scene, job.config, pixel, sample, st);
  ShadowQuery<T> q;
  auto occlusion_test = [&](uint64_t RayCounts::*kind) {
    count_ray(local.rays, st.depth, kind);
    if (!occluded(job.embree, ctx, q.ray, 1.0f)) shadow_unoccluded(st, q);
  };
  for (;;) {
    if (path_at_final_vertex(job.scene, job.config, st)) {  // only emitted light can still count
      if (path_final_query<Kinds>(job.scene, job.config, st, q)) occlusion_test(&RayCounts::shadow);
      break;
    }
    const uint32_t prim = closest_triangle(job.embree, ctx, st.ray);
    count_ray(local.rays, st.depth, &RayCounts::bounce);
    if (prim == RTC_INVALID_GEOMETRY_ID) break;
    bool wants_shadow;
    const PathEvent ev = path_hit<Kinds>(job.scene, job.config, st, surface_hit(job.scene, prim, st.ray), q, wants_shadow);
    if (wants_shadow) occlusion_test(&RayCounts::shadow);
    if (ev == PathEvent::Done) break;
  }
  return Vec3f(st.L);
}

// Diffuse-only float renders on AVX2 CPUs (batched_shading_table): up to eight samples of
// one pixel at a time, each traced as its own path with single rays (rtcIntersect1 /
// rtcOccluded1, in trace_path's order), their path steps run together eight lanes wide
// (shade_x8.h). Every path gets what trace_path would give it, bit for bit.
PB_CPU_FLATTEN void trace_samples_x8(const TraceJob& job, const ShadeTable& table, RTCIntersectContext& ctx, uint32_t pixel,
                                     uint32_t first_sample, int count, Local& local) {
  alignas(64) PathState<float> st[kShadeLanes];
  ShadowQuery<float> q[kShadeLanes];
  PathState<float>* lanes[kShadeLanes];
  uint32_t pixels[kShadeLanes], samples[kShadeLanes];
  for (int i = 0; i < kShadeLanes; ++i) {
    lanes[i] = &st[i < count ? i : 0];
    pixels[i] = pixel;
    samples[i] = first_sample + uint32_t(i < count ? i : 0);
  }
  avx2::begin_paths_x8(job.scene, job.config, pixels, samples, lanes, count);
  auto occlusion_test = [&](int i, uint64_t RayCounts::*kind) {
    count_ray(local.rays, st[i].depth, kind);
    if (!occluded(job.embree, ctx, q[i].ray, 1.0f)) shadow_unoccluded(st[i], q[i]);
  };
  int live[kShadeLanes], n_live = count;
  for (int i = 0; i < count; ++i) live[i] = i;
  while (n_live > 0) {
    // Paths at their last vertex: the emitter screen, then path_final_query (trace_path's first step).
    PathState<float>* at_final[kShadeLanes];
    int final_lane[kShadeLanes], n_final = 0, keep = 0;
    for (int k = 0; k < n_live; ++k) {
      const int i = live[k];
      if (path_at_final_vertex(job.scene, job.config, st[i])) {
        final_lane[n_final] = i;
        at_final[n_final++] = &st[i];
      } else {
        live[keep++] = i;
      }
    }
    n_live = keep;
    if (n_final > 0) {
      for (int k = n_final; k < kShadeLanes; ++k) at_final[k] = at_final[0];
      bool candidate[kShadeLanes];
      avx2::final_vertex_candidates_x8(job.scene, at_final, candidate);
      for (int k = 0; k < n_final; ++k) {
        const int i = final_lane[k];
        if (candidate[k] && path_final_query<kDiffuseOnly>(job.scene, job.config, st[i], q[i]))
          occlusion_test(i, &RayCounts::shadow);
      }
    }
    if (n_live == 0) break;
    // Closest hits, one ray at a time; misses end their paths.
    Shade8 batch;
    batch.lanes = 0;
    for (int k = 0; k < n_live; ++k) {
      const int i = live[k];
      const uint32_t prim = closest_triangle(job.embree, ctx, st[i].ray);
      count_ray(local.rays, st[i].depth, &RayCounts::bounce);
      if (prim == RTC_INVALID_GEOMETRY_ID) continue;
      batch.st[batch.lanes] = &st[i];
      batch.shadow[batch.lanes] = &q[i];
      batch.prim[batch.lanes] = prim;
      live[batch.lanes++] = i;
    }
    n_live = batch.lanes;
    if (n_live == 0) break;
    for (int k = n_live; k < kShadeLanes; ++k) {
      batch.st[k] = batch.st[0];
      batch.shadow[k] = batch.shadow[0];
      batch.prim[k] = batch.prim[0];
    }
    avx2::shade_diffuse_x8(job.scene, job.config, table, batch);
    keep = 0;
    for (int k = 0; k < n_live; ++k) {
      const int i = live[k];
      if (batch.wants_shadow[k]) occlusion_test(i, &RayCounts::shadow);
      if (batch.cont[k]) live[keep++] = i;
    }
    n_live = keep;
  }
  for (int i = 0; i < count; ++i) {
    ++local.paths;
    if (!job.film.add(pixel, Vec3f(st[i].L))) ++local.discarded;
  }
}

template <class T, uint32_t Kinds> TraceTotals pixel_parallel(const TraceJob& job) {
  const std::unique_ptr<ShadeTable> table = batched_shading_table<T, Kinds>(job.scene);
  const uint32_t w = job.config.width, h = job.config.height;
  tbb::combinable<Local> locals;
  tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, h, kTile, 0, w, kTile), [&](const auto& tile) {
    Local& local = locals.local();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (uint32_t y = tile.rows().begin(); y < tile.rows().end(); ++y)
      for (uint32_t x = tile.cols().begin(); x < tile.cols().end(); ++x) {
        const uint32_t pixel = y * w + x;
        if (table) {
          for (uint32_t s = 0; s < job.spp; s += kShadeLanes)
            trace_samples_x8(job, *table, ctx, pixel, s, int(std::min<uint32_t>(kShadeLanes, job.spp - s)), local);
          continue;
        }
        for (uint32_t s = 0; s < job.spp; ++s) {
          Vec3f L = trace_path<T, Kinds>(job, ctx, pixel, s, local);
          ++local.paths;
          if (!job.film.add(pixel, L)) ++local.discarded;  // each pixel has one writer here
        }
      }
    job.progress.advance(uint64_t(tile.rows().size()) * tile.cols().size() * job.spp);
  });
  TraceTotals t;
  locals.combine_each([&](const Local& l) {
    t.rays += l.rays;
    t.paths += l.paths;
    t.discarded += l.discarded;
  });
  t.state_bytes_per_path = sizeof(PathState<T>) + sizeof(ShadowQuery<T>);
  t.paths_in_flight = 0;  // one per thread, in registers and stack
  return t;
}

}  // namespace

// The entry point of this translation unit's instantiations (strategies.h).
template <class T, uint32_t Kinds> TraceTotals render_pixel_parallel_for(const TraceJob& job) {
  return pixel_parallel<T, Kinds>(job);
}

template TraceTotals render_pixel_parallel_for<float, PB_CPU_KINDS>(const TraceJob&);
template TraceTotals render_pixel_parallel_for<double, PB_CPU_KINDS>(const TraceJob&);

}  // namespace pb::cpu
