// Pixel-parallel CPU strategy, compiled for one set of material kinds per translation
// unit (PB_CPU_KINDS, features.h): diffuse-only here, every kind in
// render_pixel_all_kinds.cpp. The diffuse-only code is then compiled exactly as in a
// build without the other kinds (the compiler's inlining budget is per translation unit).
// Every sample is one path traced with single rays (rtcIntersect1 / rtcOccluded1); for
// diffuse-only float renders with a vector ISA (--isa) up to 16 (AVX-512) or 8 (AVX2)
// samples of a pixel run together, a vector wide, their rays as one packet
// (trace_samples_batched; single rays there measured 8.8% more instructions:
// docs/notes/cpu-log.md), bit-identical to trace_path.
#include <tbb/blocked_range2d.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <type_traits>

#include "embree_rays.h"
#include "pathbench/common/path.h"
#include "shade_batch.h"
#include "stage_timers.h"
#include "strategies.h"
#include "tiny_scene.h"

#ifndef PB_CPU_KINDS
#define PB_CPU_KINDS kDiffuseOnly
#endif

namespace pb::cpu {

namespace {
// Tiles of 8 x 8 pixels: at 16 tiles a thread (16 x 16, 256x256 on 16 cores) the last tiles
// left up to 7% of the threads' time idle at the frame's end (stage timers on the GPU host's
// Xeon); at 64 a thread, ~1% (docs/notes/cpu-log.md, 2026-11-27).
constexpr uint32_t kTile = 8;
// The final vertex's shadow rays go through the tiny test only where a batch has at least this
// many. With the tiny test of 2026-11-24 (~2,300 instructions a packet of 8, what a scene of
// general triangles still costs) 4 paid against one rtcOccluded1 a ray (~800); the axis-plane
// test answers a box's shadow packet in ~400 (docs/notes/cpu-log.md, 2026-11-27, part 2), so
// there one ray already pays: callgrind, pixel, quads, --isa avx2, 64x64x16: 1050.8
// instructions a sample with 4, 1046.0 with 1.
int tiny_final_min(const TinyScene& t) { return t.general.empty() ? 1 : 4; }

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

// One thread's packets for the batched samples (W = the kernels' width): the fields
// that never change (tnear, time, mask, id, flags) are set once per tile, not per call,
// and tfar / geomID are put back only where Embree changed them (reset_packet).
template <int W> struct PixelPackets {
  alignas(64) RTCRayHitNt<W> hit;
  alignas(64) RTCRayNt<W> shadow;
  PixelPackets() {
    init_packet_constants(hit.ray);
    init_packet_constants(shadow);
    reset_packet(hit);
    reset_packet(shadow);
  }
};

// Diffuse-only float renders with a vector ISA (batched_shading_table): up to W = k.lanes
// samples of one pixel at a time, each its own path, traced together: their rays as one
// packet of W (closest hits, then shadow rays), their path steps run together W wide
// (shade_x8.h). Every path gets what trace_path would give it, bit for bit.
// The live samples always share one depth (each vertex moves every one of them on by
// one), so the last-vertex test and the ray counts are per batch, not per lane. The
// kernels write the rays straight into the packets (begin_paths; the shading's `next`
// and `shadow` streams, whose lane order is the live list's), so no ray is transposed.
template <int W>
PB_CPU_FLATTEN void trace_samples_batched(const TraceJob& job, const BatchKernels& k, const ShadeTable& table,
                                          const TinyScene* tiny, RTCIntersectContext& ctx, PixelPackets<W>& packets,
                                          uint32_t pixel, uint32_t first_sample, int count, Local& local) {
  alignas(64) PathState<float> st[W];
  PathState<float>* lanes[W];
  uint32_t pixels[W], samples[W];
  for (int i = 0; i < W; ++i) {
    lanes[i] = &st[i < count ? i : 0];
    pixels[i] = pixel;
    samples[i] = first_sample + uint32_t(i < count ? i : 0);
  }
  float* hit_rays[6];
  packet_arrays(packets.hit.ray, hit_rays);
  {
    PB_STAGE(kCamera);
    k.begin_paths(job.scene, job.config, pixels, samples, lanes, count, hit_rays);
  }
  // The shading's streams: next rays into the hit packet, shadow rays into the shadow
  // packet; tags are indices into st.
  uint32_t live[W], shadowed[W];
  alignas(64) float contribution[3][W];
  ShadeStream next{}, shadow{};
  for (int j = 0; j < 6; ++j) next.ray[j] = hit_rays[j];
  next.tag = live;
  packet_arrays(packets.shadow, shadow.ray);
  for (int j = 0; j < 3; ++j) shadow.contribution[j] = contribution[j];
  shadow.tag = shadowed;
  int n_live = count;
  for (int i = 0; i < count; ++i) live[i] = uint32_t(i);
  while (n_live > 0) {
    const uint32_t depth = st[live[0]].depth;  // every live sample's
    if (path_at_final_vertex(job.scene, job.config, st[live[0]])) {
      // The emitter screen, then path_final_query (trace_path's first step); the paths end.
      PB_STAGE(kFinal);
      PathState<float>* at_final[W];
      for (int j = 0; j < W; ++j) at_final[j] = &st[live[j < n_live ? j : 0]];
      bool candidate[W];
      k.final_vertex_candidates(job.scene, at_final, candidate);
      // The emitter queries' shadow rays: one tiny test for all of them where there is one
      // and they are enough to pay for it (tiny_final_min; a proven answer is Embree's, and
      // tiny_occluded asks the single-ray rtcOccluded1 for each unsure one), otherwise that
      // rtcOccluded1 for every one, as this step always did, so every ray gets the answer it
      // got before (docs/notes/cpu-log.md, 2026-11-27).
      ShadowQuery<float> q[W];
      uint32_t of[W];  // the query's sample
      int n_q = 0;
      for (int j = 0; j < n_live; ++j)
        if (candidate[j] && path_final_query<kDiffuseOnly>(job.scene, job.config, st[live[j]], q[n_q])) {
          const Ray<float>& r = q[n_q].ray;
          packets.shadow.org_x[n_q] = r.o.x; packets.shadow.org_y[n_q] = r.o.y; packets.shadow.org_z[n_q] = r.o.z;
          packets.shadow.dir_x[n_q] = r.d.x; packets.shadow.dir_y[n_q] = r.d.y; packets.shadow.dir_z[n_q] = r.d.z;
          of[n_q++] = live[j];
        }
      if (n_q > 0) {
        (depth == 0 ? local.rays.camera : local.rays.shadow) += uint64_t(n_q);  // count_ray, per query
        bool blocked[W];
        if (tiny && n_q >= tiny_final_min(*tiny)) {
          PB_STAGE(kShadow);
          float* rays[6];
          packet_arrays(packets.shadow, rays);
          tiny_occluded<W>(k, *tiny, job.embree, ctx, rays, packets.shadow, n_q, blocked);  // tfar: 1 (PixelPackets)
        } else {
          PB_STAGE(kShadowEmbree);
          for (int i = 0; i < n_q; ++i) blocked[i] = occluded(job.embree, ctx, q[i].ray, 1.0f);
        }
        for (int i = 0; i < n_q; ++i)
          if (!blocked[i]) shadow_unoccluded(st[of[i]], q[i]);
      }
      break;
    }
    // Closest hits (one packet); misses end their paths.
    uint32_t hit[W];
    {
      PB_STAGE(kClosest);
      closest_hits<W>(k, tiny, job.embree, ctx, hit_rays, packets.hit, n_live, hit);  // tfar, geomID: PixelPackets
    }
    (depth == 0 ? local.rays.camera : local.rays.bounce) += uint64_t(n_live);
    ShadeBatch batch;
    batch.lanes = 0;
    for (int j = 0; j < n_live; ++j) {
      if (hit[j] == RTC_INVALID_GEOMETRY_ID) continue;
      const uint32_t i = live[j];
      batch.st[batch.lanes] = &st[i];
      batch.prim[batch.lanes] = hit[j];
      batch.tag[batch.lanes++] = i;
    }
    if (batch.lanes == 0) break;
    for (int j = batch.lanes; j < W; ++j) {
      batch.st[j] = batch.st[0];
      batch.prim[j] = batch.prim[0];
      batch.tag[j] = batch.tag[0];
    }
    next.n = shadow.n = 0;
    batch.next = &next;
    batch.shadow = &shadow;
    {
      PB_STAGE(kShade);
      k.shade_diffuse(job.scene, job.config, table, batch);
    }
    if (shadow.n > 0) {
      const int n_shadowed = int(shadow.n);
      local.rays.shadow += uint64_t(n_shadowed);  // depth >= 0 here: never a camera ray
      bool blocked[W];
      PB_STAGE(kShadow);
      shadows_blocked<W>(k, tiny, job.embree, ctx, shadow.ray, packets.shadow, n_shadowed, blocked);  // tfar: 1
      for (int j = 0; j < n_shadowed; ++j)
        if (!blocked[j]) {
          Vec3f& L = st[shadowed[j] & ~ShadeStream::kEnds].L;  // shadow_unoccluded
          L += Vec3f{contribution[0][j], contribution[1][j], contribution[2][j]};
        }
    }
    n_live = int(next.n);
  }
  PB_STAGE(kFilm);
  for (int i = 0; i < count; ++i) {
    ++local.paths;
    if (!job.film.add(pixel, Vec3f(st[i].L))) ++local.discarded;
  }
}

// The samples of every pixel of a tile, W at a time.
template <int W>
void trace_tile_batched(const TraceJob& job, const BatchKernels& k, const ShadeTable& table, const TinyScene* tiny,
                        RTCIntersectContext& ctx, const tbb::blocked_range2d<uint32_t>& tile, Local& local) {
  PixelPackets<W> packets;
  for (uint32_t y = tile.rows().begin(); y < tile.rows().end(); ++y)
    for (uint32_t x = tile.cols().begin(); x < tile.cols().end(); ++x)
      for (uint32_t s = job.config.first_sample, end = s + job.config.spp; s < end; s += W)
        trace_samples_batched<W>(job, k, table, tiny, ctx, packets, y * job.config.width + x, s,
                                 int(std::min<uint32_t>(W, end - s)), local);
}

template <class T, uint32_t Kinds> TraceTotals pixel_parallel(const TraceJob& job) {
  const std::unique_ptr<ShadeTable> table = batched_shading_table<T, Kinds>(job.scene, job.isa);
  const BatchKernels* k = table ? batch_kernels(job.isa) : nullptr;
  const std::unique_ptr<TinyScene> tiny = tiny_scene_for(job.embree, job.scene, k);
  const uint32_t w = job.config.width, y0 = job.config.first_pixel / w;
  tbb::combinable<Local> locals;
  PB_STAGE_RENDER("pixel", tbb::this_task_arena::max_concurrency());
  uint32_t tile_size = kTile;
#if defined(PB_STAGE_TIMERS) && PB_STAGE_TIMERS
  if (const char* e = std::getenv("PB_PIXEL_TILE")) tile_size = uint32_t(std::max(1, std::atoi(e)));  // profiling only
#endif
  tbb::parallel_for(tbb::blocked_range2d<uint32_t>(y0, y0 + job.rows, tile_size, 0, w, tile_size), [&](const auto& tile) {
    PB_STAGE_THREAD();
    Local& local = locals.local();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    if (table) {
      if (k->lanes == 16) trace_tile_batched<16>(job, *k, *table, tiny.get(), ctx, tile, local);
      else trace_tile_batched<8>(job, *k, *table, tiny.get(), ctx, tile, local);
    } else {
      for (uint32_t y = tile.rows().begin(); y < tile.rows().end(); ++y)
        for (uint32_t x = tile.cols().begin(); x < tile.cols().end(); ++x) {
          const uint32_t pixel = y * w + x;
          for (uint32_t s = job.config.first_sample, end = s + job.config.spp; s < end; ++s) {
            Vec3f L = trace_path<T, Kinds>(job, ctx, pixel, s, local);
            ++local.paths;
            if (!job.film.add(pixel, L)) ++local.discarded;  // each pixel has one writer here
          }
        }
    }
    job.progress.advance(uint64_t(tile.rows().size()) * tile.cols().size() * job.config.spp);
  });
  TraceTotals t;
  locals.combine_each([&](const Local& l) {
    t.rays += l.rays;
    t.paths += l.paths;
    t.discarded += l.discarded;
  });
  t.state_bytes_per_path = sizeof(PathState<T>) + sizeof(ShadowQuery<T>);
  t.paths_in_flight = 0;  // one per thread, in registers and stack
  t.isa = k ? k->isa : Isa::Scalar;
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
