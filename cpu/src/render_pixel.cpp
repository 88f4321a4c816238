// Pixel-parallel CPU strategy, compiled for one set of material kinds per translation
// unit (PB_CPU_KINDS, features.h): diffuse-only here, every kind in
// render_pixel_all_kinds.cpp. The diffuse-only code is then compiled exactly as in a
// build without the other kinds (the compiler's inlining budget is per translation unit).
#include <tbb/blocked_range2d.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "embree_rays.h"
#include "pathbench/common/path.h"
#include "strategies.h"

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
    RTCRay sr;
    to_embree(q.ray, 1.0f, sr);
    rtcOccluded1(job.embree.handle(), &ctx, &sr);
    count_ray(local.rays, st.depth, kind);
    if (sr.tfar >= 0.0f) shadow_unoccluded(st, q);
  };
  for (;;) {
    if (path_at_final_vertex(job.scene, job.config, st)) {  // only emitted light can still count
      if (path_final_query<Kinds>(job.scene, job.config, st, q)) occlusion_test(&RayCounts::shadow);
      break;
    }
    RTCRayHit rh;
    to_embree(st.ray, kInfinity, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(job.embree.handle(), &ctx, &rh);
    count_ray(local.rays, st.depth, &RayCounts::bounce);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
    bool wants_shadow;
    const PathEvent ev = path_hit<Kinds>(job.scene, job.config, st, surface_hit(job.scene, rh.hit.primID, st.ray), q, wants_shadow);
    if (wants_shadow) occlusion_test(&RayCounts::shadow);
    if (ev == PathEvent::Done) break;
  }
  return Vec3f(st.L);
}

template <class T, uint32_t Kinds> TraceTotals pixel_parallel(const TraceJob& job) {
  const uint32_t w = job.config.width, h = job.config.height;
  tbb::combinable<Local> locals;
  tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, h, kTile, 0, w, kTile), [&](const auto& tile) {
    Local& local = locals.local();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (uint32_t y = tile.rows().begin(); y < tile.rows().end(); ++y)
      for (uint32_t x = tile.cols().begin(); x < tile.cols().end(); ++x) {
        const uint32_t pixel = y * w + x;
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
