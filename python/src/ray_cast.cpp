#include "ray_cast.h"

#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "pathbench/bvh/traversal.h"

namespace pb::python {

namespace {

constexpr size_t kGrain = 1024;  // rays per task: enough to amortise TBB, small enough to balance
constexpr float kInf = std::numeric_limits<float>::infinity();

Vec3f row(const float* a, size_t i) { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }

bool finite(Vec3f v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
// Inside the supported coordinate range (limits.h): Embree aborts the process on ray
// origins or directions beyond ~1.8e18, so larger values never reach it.
bool in_range(Vec3f v) {
  const float m = float(limits::kMaxCoordinate);
  return std::fabs(v.x) <= m && std::fabs(v.y) <= m && std::fabs(v.z) <= m;
}

void fill(const RayBatch& r, size_t i, RTCRay& e) {
  e.org_x = r.origins[3 * i]; e.org_y = r.origins[3 * i + 1]; e.org_z = r.origins[3 * i + 2];
  e.dir_x = r.directions[3 * i]; e.dir_y = r.directions[3 * i + 1]; e.dir_z = r.directions[3 * i + 2];
  e.tnear = r.tnear_at(i);
  e.tfar = r.tfar_at(i);
  e.time = 0.0f;
  e.mask = 0xFFFFFFFFu;
  e.id = 0;
  e.flags = 0;
}

template <class F> void parallel_rays(size_t n, F&& per_ray) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) per_ray(i);
  });
}

}  // namespace

Backend parse_backend(std::string_view name) {
  if (name == "embree") return Backend::Embree;
  if (name == "bvh") return Backend::Bvh;
  throw InputError(fmt::format("backend must be 'embree' or 'bvh', got '{}'", name));
}

void validate(const RayBatch& r, Backend backend, bool watertight) {
  if (backend == Backend::Bvh && !watertight)
    throw InputError("backend 'bvh' is always watertight (the GPU tracer's triangle test): pass watertight=True");
  for (size_t i = 0; i < r.n; ++i) {
    const Vec3f o = row(r.origins, i), d = row(r.directions, i);
    if (!finite(o)) throw InputError(fmt::format("origins[{}] is not finite: ({}, {}, {})", i, o.x, o.y, o.z));
    if (!finite(d)) throw InputError(fmt::format("directions[{}] is not finite: ({}, {}, {})", i, d.x, d.y, d.z));
    if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) throw InputError(fmt::format("directions[{}] is zero", i));
    if (!in_range(o))
      throw InputError(fmt::format("origins[{}] = ({:g}, {:g}, {:g}) is outside the supported coordinate range +-{:g}",
                                   i, o.x, o.y, o.z, limits::kMaxCoordinate));
    if (!in_range(d))
      throw InputError(fmt::format("directions[{}] = ({:g}, {:g}, {:g}) is outside the supported range +-{:g} "
                                   "(directions need not be normalised, but must be that small)",
                                   i, d.x, d.y, d.z, limits::kMaxCoordinate));
    const float tn = r.tnear_at(i), tf = r.tfar_at(i);
    if (!(std::isfinite(tn) && tn >= 0.0f))
      throw InputError(fmt::format("tnear[{}] = {}: must be finite and >= 0", i, tn));
    if (!(tf >= tn)) throw InputError(fmt::format("tfar[{}] = {}: must be >= tnear ({}) and not NaN", i, tf, tn));
    if (backend == Backend::Bvh && tn != 0.0f)
      throw InputError(fmt::format("tnear[{}] = {}: backend 'bvh' supports tnear = 0 only (its traversal tests "
                                   "ray_t_min < t < tfar, t_min a few float ulps of the origin: watertight.h)", i, tn));
  }
}

void intersect(const SceneHandle& scene, const RayBatch& rays, Backend backend, bool watertight, bool* hit,
               uint32_t* prim, float* t) {
  validate(rays, backend, watertight);
  auto store = [&](size_t i, uint32_t p, float tt) {
    hit[i] = p != bvh::kNoHit;
    prim[i] = p;
    t[i] = hit[i] ? tt : kInf;
  };
  if (backend == Backend::Embree) {
    const cpu::EmbreeScene& embree = scene.embree(watertight);
    const RTCScene s = embree.handle();
    parallel_rays(rays.n, [&](size_t i) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      RTCRayHit rh;
      fill(rays, i, rh.ray);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(s, &ctx, &rh);
      store(i, rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? bvh::kNoHit : embree.triangle(rh.hit), rh.ray.tfar);
    });
  } else {
    const bvh::BvhView view = scene.bvh().view();
    parallel_rays(rays.n, [&](size_t i) {
      float tt = kInf;
      const uint32_t p = bvh::intersect_closest(view, row(rays.origins, i), row(rays.directions, i), rays.tfar_at(i), tt);
      store(i, p, tt);
    });
  }
}

void occluded(const SceneHandle& scene, const RayBatch& rays, Backend backend, bool watertight, bool* out) {
  validate(rays, backend, watertight);
  if (backend == Backend::Embree) {
    const RTCScene s = scene.embree(watertight).handle();
    parallel_rays(rays.n, [&](size_t i) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      RTCRay ray;
      fill(rays, i, ray);
      rtcOccluded1(s, &ctx, &ray);
      out[i] = ray.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
    });
  } else {
    const bvh::BvhView view = scene.bvh().view();
    parallel_rays(rays.n, [&](size_t i) {
      out[i] = bvh::occluded(view, row(rays.origins, i), row(rays.directions, i), rays.tfar_at(i));
    });
  }
}

}  // namespace pb::python
