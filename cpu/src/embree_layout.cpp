#include "pathbench/cpu/embree_layout.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <utility>
#include <vector>

#include "embree_rays.h"
#include "pathbench/common/camera.h"
#include "pathbench/common/ray_offset.h"
#include "pathbench/cpu/embree_scene.h"
#include "pathbench/cpu/triangle_pairs.h"

namespace pb::cpu {

namespace {

constexpr double kMinPairedShare = 0.9;
constexpr size_t kMaxProbedTriangles = size_t(1) << 16;
// Quads are kept only when they take less than this share of the triangles' time: a
// margin well above the probe's noise, so a loaded machine does not flip the answer.
constexpr double kQuadsShareToWin = 0.9;
constexpr int kRounds = 5;
// Up to this many rounds while the share is within kCloseToTheLine of kQuadsShareToWin.
constexpr int kMaxRounds = 25;
constexpr double kCloseToTheLine = 0.1;
constexpr uint32_t kCameraGrid = 48;      // 48 x 48 camera rays
constexpr uint32_t kSurfaceRays = 2304;   // as many rays leaving surfaces, and shadow rays

struct ProbeRays {
  std::vector<Ray<float>> closest;
  std::vector<Ray<float>> shadow;  // reaching their target at t = 1
};

// A uniform point on triangle `t` and its unit normal.
Vec3f point_on(const Scene& s, uint32_t t, float u1, float u2, Vec3f& n) {
  const Vec3f a = s.positions[s.triangles[t].v[0]], b = s.positions[s.triangles[t].v[1]],
              c = s.positions[s.triangles[t].v[2]];
  n = normalize(cross(b - a, c - a));
  const float su = std::sqrt(u1);
  return a + (b - a) * (1.0f - su) + (c - a) * (u2 * su);
}

// What a path tracer asks of this scene, roughly: camera rays, rays leaving surface
// points into the hemisphere, shadow rays from there to the emitters (to other surface
// points where there are none). Fixed seed: the same rays every time.
ProbeRays probe_rays(const Scene& s) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_int_distribution<size_t> any_triangle(0, s.triangles.size() - 1);
  ProbeRays r;
  for (uint32_t y = 0; y < kCameraGrid; ++y)
    for (uint32_t x = 0; x < kCameraGrid; ++x)
      r.closest.push_back(camera_ray<float>(s.camera, x, y, kCameraGrid, kCameraGrid, u(rng), u(rng)));
  for (uint32_t i = 0; i < kSurfaceRays; ++i) {
    Vec3f n, m;
    const Vec3f p = point_on(s, uint32_t(any_triangle(rng)), u(rng), u(rng), n);
    Vec3f d = normalize(Vec3f{g(rng), g(rng), g(rng)});
    if (dot(d, n) < 0.0f) n = -n;  // leave on the side the direction points to
    const Vec3f o = offset_ray_origin(p, n, s.offset);
    r.closest.push_back({o, d});
    const uint32_t target = s.emitters.empty() ? uint32_t(any_triangle(rng))
                                               : s.emitters[std::min<size_t>(s.emitters.size() - 1, size_t(u(rng) * s.emitters.size()))];
    const Vec3f q = point_on(s, target, u(rng), u(rng), m);
    r.shadow.push_back({o, q - o});
  }
  return r;
}

// Nanoseconds per ray for tracing every probe ray once (closest hits, then shadow rays).
double trace_ns_per_ray(const EmbreeScene& e, const ProbeRays& r) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  uint32_t hits = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (const Ray<float>& ray : r.closest) hits += closest_triangle(e, ctx, ray) != RTC_INVALID_GEOMETRY_ID;
  for (const Ray<float>& ray : r.shadow) hits += occluded(e, ctx, ray, 0.999f);
  const auto t1 = std::chrono::steady_clock::now();
  asm volatile("" : : "r"(hits));  // the loops' results are used
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / double(r.closest.size() + r.shadow.size());
}

// Every reason the probe gives (measure), so that a remembered choice keeps a static string.
constexpr const char* kReasons[] = {"no triangles", "over 65536 triangles: not probed",
                                    "fewer than 90% of the triangles pair up", "quads measured faster",
                                    "quads not measured clearly faster"};

LayoutChoice measure(const Scene& s, bool watertight, TrianglePairs& pairs) {
  LayoutChoice c;
  if (s.triangles.empty()) {
    c.reason = kReasons[0];
    return c;
  }
  if (s.triangles.size() > kMaxProbedTriangles) {
    c.reason = kReasons[1];
    return c;
  }
  pairs = pair_triangles(s);
  c.paired = pairs.paired;
  if (c.paired < kMinPairedShare * double(s.triangles.size())) {
    c.reason = kReasons[2];
    return c;
  }
  const EmbreeScene triangles(s, watertight, LayoutChoice{EmbreeLayout::Triangles}),
      quads(s, watertight, LayoutChoice{EmbreeLayout::Quads}, pairs);
  const ProbeRays rays = probe_rays(s);
  trace_ns_per_ray(triangles, rays);  // warm-up: caches, lazily built parts
  trace_ns_per_ray(quads, rays);
  c.triangles_ns = c.quads_ns = std::numeric_limits<double>::infinity();
  // Alternating, best round of each (load only adds time). Where the answer is close to the
  // line after kRounds (a loaded machine: MPI ranks starting together), more rounds, so that a
  // few slowed rounds do not decide it: every process of a run should get one answer.
  for (int round = 0; round < kMaxRounds; ++round) {
    if (round >= kRounds && std::abs(c.quads_ns / c.triangles_ns - kQuadsShareToWin) > kCloseToTheLine) break;
    const bool quads_first = round % 2 == 1;
    for (int k = 0; k < 2; ++k) {
      if ((k == 0) == quads_first) c.quads_ns = std::min(c.quads_ns, trace_ns_per_ray(quads, rays));
      else c.triangles_ns = std::min(c.triangles_ns, trace_ns_per_ray(triangles, rays));
    }
  }
  const bool quads_win = c.quads_ns < kQuadsShareToWin * c.triangles_ns;
  c.layout = quads_win ? EmbreeLayout::Quads : EmbreeLayout::Triangles;
  c.reason = quads_win ? kReasons[3] : kReasons[4];
  return c;
}

// FNV-1a over the bytes the layout depends on.
uint64_t fingerprint(const Scene& s, bool watertight) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  mix(s.positions.data(), s.positions.size() * sizeof(Vec3f));
  mix(s.triangles.data(), s.triangles.size() * sizeof(Triangle));
  mix(s.emitters.data(), s.emitters.size() * sizeof(uint32_t));
  mix(&s.camera, sizeof(s.camera));
  mix(&watertight, sizeof(watertight));
  return h;
}

std::mutex& known_mutex() {
  static std::mutex m;
  return m;
}
std::map<uint64_t, LayoutChoice>& known_layouts() {
  static std::map<uint64_t, LayoutChoice> known;
  return known;
}

}  // namespace

bool remember_embree_layout(const Scene& s, bool watertight, EmbreeLayout layout, double triangles_ns,
                            double quads_ns, const std::string& reason) {
  for (const char* r : kReasons)
    if (reason == r) {
      const std::lock_guard<std::mutex> lock(known_mutex());
      known_layouts()[fingerprint(s, watertight)] = LayoutChoice{layout, 0, triangles_ns, quads_ns, r};
      return true;
    }
  return false;
}

LayoutChoice choose_embree_layout(const Scene& s, bool watertight, TrianglePairs* pairs) {
  auto& known = known_layouts();
  const uint64_t key = fingerprint(s, watertight);
  const std::lock_guard<std::mutex> lock(known_mutex());
  if (auto it = known.find(key); it != known.end()) return it->second;
  TrianglePairs made;
  known[key] = measure(s, watertight, made);
  if (pairs) *pairs = std::move(made);
  return known[key];
}

}  // namespace pb::cpu
