#pragma once
// Rays for checking the GPU BVH traversal against Embree, and the comparison rules,
// shared by the host-side test (label unit) and the on-device test (label gpu).
#include <embree3/rtcore.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/scene.h"
#include "pathbench/cpu/embree_scene.h"

namespace pb::bvh::test {

struct Ray3 {
  Vec3f o, d;
  float t_max;
};

struct Hit {
  uint32_t prim = kNoHit;
  float t = 0;
};

// Embree's answers on the same scene, built as the CPU tracer builds it (watertight).
class EmbreeReference {
 public:
  explicit EmbreeReference(const Scene& s) : embree_(cpu::make_embree_scene(s, /*watertight=*/true)), scene_(embree_->handle()) {}
  Hit closest(const Ray3& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    fill(r, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    Hit h;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      h.prim = embree_->triangle(rh.hit);
      h.t = rh.ray.tfar;
    }
    return h;
  }
  bool occluded(const Ray3& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray{};
    fill(r, ray);
    rtcOccluded1(scene_, &ctx, &ray);
    return ray.tfar < 0.0f;
  }

 private:
  static void fill(const Ray3& r, RTCRay& e) {
    e.org_x = r.o.x; e.org_y = r.o.y; e.org_z = r.o.z;
    e.dir_x = r.d.x; e.dir_y = r.d.y; e.dir_z = r.d.z;
    e.tnear = 0.0f;
    e.tfar = r.t_max;
    e.mask = 0xFFFFFFFFu;
    e.time = 0.0f;
    e.flags = 0;
    e.id = 0;
  }
  std::unique_ptr<cpu::EmbreeScene> embree_;
  RTCScene scene_;
};

inline Vec3f random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n;
  for (;;) {
    Vec3f d{n(rng), n(rng), n(rng)};
    float l = length(d);
    if (l > 1e-3f) return d / l;
  }
}

// Random rays from points inside `lo`..`hi` (the inside of a closed box, say).
inline std::vector<Ray3> random_rays(Vec3f lo, Vec3f hi, size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Ray3> rays(n);
  for (auto& r : rays) {
    r.o = {lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng), lo.z + (hi.z - lo.z) * u(rng)};
    r.d = random_direction(rng);
    r.t_max = std::numeric_limits<float>::infinity();
  }
  return rays;
}

// Rays from points inside `lo`..`hi` aimed exactly at the scene's vertices and at
// points on its triangles' edges (unnormalised direction, target at t = 1; t_max = inf).
inline std::vector<Ray3> edge_and_vertex_rays(const Scene& s, Vec3f lo, Vec3f hi, size_t origins, uint32_t seed,
                                              size_t max_triangles = 4096) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec3f> targets;
  const size_t step = std::max<size_t>(1, s.triangles.size() / max_triangles);
  for (size_t i = 0; i < s.triangles.size(); i += step) {
    const Triangle& t = s.triangles[i];
    for (int k = 0; k < 3; ++k) {
      const Vec3f a = s.positions[t.v[k]], b = s.positions[t.v[(k + 1) % 3]];
      targets.push_back(a);
      for (float f : {0.5f, 0.25f, 1.0f / 3.0f}) targets.push_back(a + (b - a) * f);
    }
  }
  std::vector<Ray3> rays;
  for (size_t o = 0; o < origins; ++o) {
    const Vec3f org{lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng), lo.z + (hi.z - lo.z) * u(rng)};
    for (const Vec3f& t : targets) {
      const Vec3f d = t - org;
      if (dot(d, d) > 1e-12f) rays.push_back({org, d, std::numeric_limits<float>::infinity()});
    }
  }
  return rays;
}

inline bool close_rel(float a, float b, float rel) {
  return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b));
}

// t agrees within 1e-5 relative, or within what float coordinates can resolve at all:
// a vertex minus the ray origin is rounded to the ulp of the larger coordinate, so a hit
// close to a far-from-zero origin has a larger relative error in t (on any tracer).
inline bool t_agrees(const Ray3& r, float a, float b) {
  const float scale = std::max({std::fabs(r.o.x), std::fabs(r.o.y), std::fabs(r.o.z), std::fabs(r.o.x + a * r.d.x),
                                std::fabs(r.o.y + a * r.d.y), std::fabs(r.o.z + a * r.d.z)});
  const float floor_t = 8.0f * scale * 0x1p-24f / std::max(length(r.d), 1e-30f);
  return std::fabs(a - b) <= std::max(1e-5f * std::max(std::fabs(a), std::fabs(b)), floor_t);
}

struct Agreement {
  size_t rays = 0;
  size_t hit_miss_mismatch = 0;  // one hits, the other does not
  size_t prim_mismatch = 0;      // both hit, different triangles
  size_t prim_mismatch_not_tie = 0;  // ... and the distances differ by more than 1e-5
  size_t t_mismatch = 0;         // same triangle, t differs by more than 1e-5 relative
  size_t misses = 0;             // of the checked tracer
  size_t at_target_edge = 0;     // edge rays: disagreement about the aimed-at edge itself
  bool edge_rays = false;        // rays aim at an edge or vertex at t = 1
  std::string first_problem;
  size_t grazing = 0;            // hits at < 3 degrees to the surface: t is ill-conditioned
  // `cos_ours`: |cos| between the ray and the normal of the triangle we hit (1 if unknown).
  void add(const Ray3& r, const Hit& ours, const Hit& ref, float cos_ours = 1.0f) {
    ++rays;
    if (edge_rays && ours.prim != kNoHit && ours.prim == ref.prim && cos_ours < 0.05f) {
      ++grazing;
      return;
    }
    if (ours.prim == kNoHit) ++misses;
    auto note = [&](const char* what) {
      if (first_problem.empty()) {
        char buf[400];
        std::snprintf(buf, sizeof buf, "%s: o=(%.9g,%.9g,%.9g) d=(%.9g,%.9g,%.9g) ours prim %u t %.9g, ref prim %u t %.9g",
                      what, r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, ours.prim, ours.t, ref.prim, ref.t);
        first_problem = buf;
      }
    };
    if ((ours.prim == kNoHit) != (ref.prim == kNoHit)) {
      const float t_hit = ours.prim == kNoHit ? ref.t : ours.t;
      if (edge_rays && std::fabs(t_hit - 1.0f) < 1e-2f) {  // grazed the aimed-at rim, or not
        ++at_target_edge;
        return;
      }
      ++hit_miss_mismatch;
      note("hit/miss differs");
      return;
    }
    if (ours.prim == kNoHit) return;
    if (ours.prim != ref.prim) {
      ++prim_mismatch;
      // A ray aimed at a boundary edge (a silhouette, an open mesh's rim) may graze it
      // on one tracer and pass on the other: both answers are right there.
      if (edge_rays && !t_agrees(r, ours.t, ref.t) && std::fabs(std::min(ours.t, ref.t) - 1.0f) < 1e-2f) {
        ++at_target_edge;
        return;
      }
      if (!t_agrees(r, ours.t, ref.t)) {
        ++prim_mismatch_not_tie;
        note("different triangle at a different distance");
      }
    } else if (!t_agrees(r, ours.t, ref.t)) {
      ++t_mismatch;
      note("same triangle, t differs");
    }
  }
};

inline float hit_cos(const Scene& s, const Ray3& r, const Hit& h) {
  if (h.prim == kNoHit) return 1.0f;
  const Triangle& t = s.triangles[h.prim];
  const Vec3f n = normalize(cross(s.positions[t.v[1]] - s.positions[t.v[0]], s.positions[t.v[2]] - s.positions[t.v[0]]));
  return std::fabs(dot(n, normalize(r.d)));
}

}  // namespace pb::bvh::test
