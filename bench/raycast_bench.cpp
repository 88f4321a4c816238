#include "raycast_bench.h"

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <limits>
#include <memory>

#include "pathbench/common/errors.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/common/path.h"
#include "pathbench/common/settings.h"
#include "pathbench/cpu/embree_scene.h"  // the tracer's own Embree scene
#include "scene_cache.h"

namespace pb::bench {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr size_t kChunk = 1024;
constexpr uint64_t kBounceSeed = 0x5eedb0a7c0ffee01ull;  // rays per task; also the stream length for the 1M api

enum class Api { Intersect1, Intersect16, Intersect1M, Occluded1, Occluded16, Occluded1M };
const char* api_name(Api a) {
  switch (a) {
    case Api::Intersect1: return "intersect1";
    case Api::Intersect16: return "intersect16";
    case Api::Intersect1M: return "intersect1M";
    case Api::Occluded1: return "occluded1";
    case Api::Occluded16: return "occluded16";
    case Api::Occluded1M: return "occluded1M";
  }
  return "?";
}
bool occluded(Api a) { return a == Api::Occluded1 || a == Api::Occluded16 || a == Api::Occluded1M; }

void set_ray(RTCRay& r, const RaySet& s, size_t i, float tfar) {
  r.org_x = s.ox[i]; r.org_y = s.oy[i]; r.org_z = s.oz[i];
  r.dir_x = s.dx[i]; r.dir_y = s.dy[i]; r.dir_z = s.dz[i];
  r.tnear = 0.0f;
  r.tfar = tfar;
  r.time = 0.0f;
  r.mask = 0xFFFFFFFFu;
  r.id = uint32_t(i);
  r.flags = 0;
}
template <class P> void set_lane(P& r, int k, const RaySet& s, size_t i, float tfar) {
  r.org_x[k] = s.ox[i]; r.org_y[k] = s.oy[i]; r.org_z[k] = s.oz[i];
  r.dir_x[k] = s.dx[i]; r.dir_y[k] = s.dy[i]; r.dir_z[k] = s.dz[i];
  r.tnear[k] = 0.0f;
  r.tfar[k] = tfar;
  r.time[k] = 0.0f;
  r.mask[k] = 0xFFFFFFFFu;
  r.id[k] = uint32_t(i);
  r.flags[k] = 0;
}

struct Closest {
  bool hit;
  uint32_t prim;
  float t;
};
Closest closest_hit(const cpu::EmbreeScene& embree, RTCIntersectContext& ctx, const RaySet& s, size_t i) {
  RTCRayHit rh;
  set_ray(rh.ray, s, i, kInf);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree.handle(), &ctx, &rh);
  const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  return {hit, hit ? embree.triangle(rh.hit) : 0u, rh.ray.tfar};
}
void push(RaySet& s, Vec3f o, Vec3f d) {
  s.ox.push_back(o.x); s.oy.push_back(o.y); s.oz.push_back(o.z);
  s.dx.push_back(d.x); s.dy.push_back(d.y); s.dz.push_back(d.z);
}
void fill_occlusion_distances(const cpu::EmbreeScene& scene, RaySet& s) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  s.t_occluded.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    Closest c = closest_hit(scene, ctx, s, i);
    s.t_occluded[i] = c.hit ? c.t * 0.999f : kInf;
  }
}

struct Prepared {
  std::unique_ptr<cpu::EmbreeScene> embree;
  RaySets rays;
};

// Casts every ray of `s` once with `api` on all threads; returns the hit count.
uint64_t cast_all(RTCScene scene, Api api, const RaySet& s, bool coherent) {
  tbb::enumerable_thread_specific<uint64_t> hits(0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.size(), kChunk), [&](const tbb::blocked_range<size_t>& range) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    uint64_t h = 0;
    const size_t b = range.begin(), e = range.end();
    const bool occ = occluded(api);
    auto tfar = [&](size_t i) { return occ ? s.t_occluded[i] : kInf; };
    switch (api) {
      case Api::Intersect1:
        for (size_t i = b; i < e; ++i) {
          RTCRayHit rh;
          set_ray(rh.ray, s, i, kInf);
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(scene, &ctx, &rh);
          h += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        break;
      case Api::Occluded1:
        for (size_t i = b; i < e; ++i) {
          RTCRay r;
          set_ray(r, s, i, tfar(i));
          rtcOccluded1(scene, &ctx, &r);
          h += r.tfar < 0.0f;
        }
        break;
      case Api::Intersect16:
      case Api::Occluded16:
        for (size_t i = b; i < e; i += 16) {
          alignas(64) int valid[16];
          const int n = int(std::min<size_t>(16, e - i));
          if (api == Api::Intersect16) {
            alignas(64) RTCRayHit16 p;
            for (int k = 0; k < 16; ++k) {
              valid[k] = k < n ? -1 : 0;
              set_lane(p.ray, k, s, k < n ? i + k : i, kInf);
              p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, scene, &ctx, &p);
            for (int k = 0; k < n; ++k) h += p.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
          } else {
            alignas(64) RTCRay16 p;
            for (int k = 0; k < 16; ++k) {
              valid[k] = k < n ? -1 : 0;
              set_lane(p, k, s, k < n ? i + k : i, tfar(k < n ? i + k : i));
            }
            rtcOccluded16(valid, scene, &ctx, &p);
            for (int k = 0; k < n; ++k) h += p.tfar[k] < 0.0f;
          }
        }
        break;
      case Api::Intersect1M: {
        thread_local std::vector<RTCRayHit> buf;
        buf.resize(e - b);
        for (size_t i = b; i < e; ++i) {
          set_ray(buf[i - b].ray, s, i, kInf);
          buf[i - b].hit.geomID = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect1M(scene, &ctx, buf.data(), unsigned(e - b), sizeof(RTCRayHit));
        for (size_t i = 0; i < e - b; ++i) h += buf[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
        break;
      }
      case Api::Occluded1M: {
        thread_local std::vector<RTCRay> buf;
        buf.resize(e - b);
        for (size_t i = b; i < e; ++i) set_ray(buf[i - b], s, i, tfar(i));
        rtcOccluded1M(scene, &ctx, buf.data(), unsigned(e - b), sizeof(RTCRay));
        for (size_t i = 0; i < e - b; ++i) h += buf[i].tfar < 0.0f;
        break;
      }
    }
    hits.local() += h;
  });
  return hits.combine([](uint64_t a, uint64_t b) { return a + b; });
}

void run_raycast(benchmark::State& state, const RaycastCase& c, Api api, bool coherent) {
  std::shared_ptr<Prepared> prep;
  try {
    const std::string kind = fmt::format("raycast:{}x{}", c.width, c.height);
    prep = std::static_pointer_cast<Prepared>(cached_extra(c.scene, kind));
    if (!prep) {
      std::shared_ptr<const Scene> scene = cached_scene(c.scene);
      prep = std::make_shared<Prepared>();
      prep->embree = cpu::make_embree_scene(*scene, RenderSettings{}.watertight);  // as the tracers run by default
      prep->rays = make_ray_sets(*scene, *prep->embree, c.width, c.height);
      store_extra(c.scene, kind, prep);
    }
  } catch (const InputError& e) {
    state.SkipWithError(fmt::format("scene not available: {}", e.what()).c_str());
    return;
  }
  const RaySet& rays = coherent ? prep->rays.coherent : prep->rays.incoherent;
  if (rays.size() == 0) {
    state.SkipWithError("no rays: every camera ray missed the scene");
    return;
  }
  using benchmark::Counter;
  const RTCScene handle = prep->embree->handle();
  uint64_t hits = 0;
  const double cpu0 = process_cpu_seconds();
  for (auto _ : state) {
    hits = cast_all(handle, api, rays, coherent);
    benchmark::DoNotOptimize(hits);
  }
  // Process CPU time (every thread), per iteration: beside the wall time it tells a
  // contended run (wall up, CPU flat) from a slower one (both up). Google Benchmark's
  // cpu_time is the main thread's only.
  state.counters["process_cpu_seconds"] = Counter(process_cpu_seconds() - cpu0, Counter::kAvgIterations);
  state.counters["rays_per_second"] = Counter(double(rays.size()), Counter::kIsIterationInvariantRate);
  state.counters["rays"] = double(rays.size());
  state.counters["hit_fraction"] = double(hits) / double(rays.size());
  state.counters["triangles"] = double(cached_scene(c.scene)->triangles.size());
  // Not "threads": Google Benchmark writes its own "threads" key in every row.
  state.counters["cpu_threads"] = double(tbb::this_task_arena::max_concurrency());
  state.SetLabel(std::string("embree_layout=") + to_string(prep->embree->layout()));  // as render benchmarks
}

}  // namespace

RaySets make_ray_sets(const Scene& scene, const cpu::EmbreeScene& embree, uint32_t width, uint32_t height) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  const SceneView view = scene.view();
  PathConfig cfg{2, Sampling::Cosine, false, 3, width, height, 0};
  RaySets out;
  for (uint32_t pixel = 0; pixel < width * height; ++pixel) {
    PathState<float> st;
    path_begin(view, cfg, pixel, 0, st);
    push(out.coherent, st.ray.o, st.ray.d);
    const Closest c = closest_hit(embree, ctx, out.coherent, out.coherent.size() - 1);
    if (!c.hit) continue;
    const SurfaceHit<float> h = surface_hit(view, c.prim, st.ray);
    const Vec3f n = dot(h.ng, st.ray.d) < 0.0f ? h.ng : -h.ng;  // the side the camera ray came from
    const Uniform4 u = RngStream{pixel, kBounceSeed}.draw(0, 1, 0);  // a stream of its own
    const Vec3f d = normalize(Frame<float>::from_normal(n).to_world(sample_cosine_hemisphere(u.v[0], u.v[1])));
    push(out.incoherent, offset_ray_origin(h.p, n, view.offset), d);
  }
  fill_occlusion_distances(embree, out.coherent);
  fill_occlusion_distances(embree, out.incoherent);
  return out;
}

void register_raycast_benchmarks(const RaycastCase& c) {
  for (bool coherent : {true, false})
    for (Api api : {Api::Intersect1, Api::Intersect16, Api::Intersect1M, Api::Occluded1, Api::Occluded16,
                    Api::Occluded1M}) {
      const std::string name =
          fmt::format("raycast/cpu/{}/{}/{}", api_name(api), coherent ? "coherent" : "incoherent", c.scene);
      auto* b = benchmark::RegisterBenchmark(name.c_str(), [c, api, coherent](benchmark::State& st) {
        run_raycast(st, c, api, coherent);
      });
      b->UseRealTime()->Unit(benchmark::kMillisecond);
    }
}

}  // namespace pb::bench
