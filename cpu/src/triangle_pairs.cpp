#include "pathbench/cpu/triangle_pairs.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pb::cpu {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr double kMinCos = 0.5;  // 60 degrees between the normals at most

struct EdgeUse {
  uint64_t key;  // the edge's two vertex ids, smaller first
  uint32_t tri;
  bool operator<(const EdgeUse& o) const { return key != o.key ? key < o.key : tri < o.tri; }
};

struct Candidate {
  double cos;  // |cos| of the angle between the normals (winding may disagree)
  uint32_t a, b;
  bool operator<(const Candidate& o) const {  // best first; ties by triangle ids (deterministic)
    if (cos != o.cos) return cos > o.cos;
    return a != o.a ? a < o.a : b < o.b;
  }
};

Vec3<double> unit_normal(const Scene& s, const Triangle& t) {
  const Vec3<double> p0(s.positions[t.v[0]]), p1(s.positions[t.v[1]]), p2(s.positions[t.v[2]]);
  const Vec3<double> n = cross(p1 - p0, p2 - p0);
  const double len = std::sqrt(dot(n, n));
  return len > 0.0 ? n * (1.0 / len) : Vec3<double>{0.0, 0.0, 0.0};
}

// Whether a and b have exactly two vertices in common (duplicates share three).
bool share_one_edge(const Triangle& a, const Triangle& b) {
  int common = 0;
  for (uint32_t v : a.v) common += v == b.v[0] || v == b.v[1] || v == b.v[2];
  return common == 2;
}

// The quad whose halves are exactly triangles a and b (sharing an edge): a rotated to
// (x, m, y), m its vertex off the edge, gives the quad (m, y, d, x), d b's vertex off the
// edge. Embree's first half (v0, v1, v3) = (m, y, x) is a rotation of a; its second
// (v2, v3, v1) = (d, x, y) has b's vertices.
std::array<uint32_t, 4> quad_of(const Triangle& a, const Triangle& b) {
  auto shared = [&](uint32_t v) { return v == b.v[0] || v == b.v[1] || v == b.v[2]; };
  int m = 0;
  while (shared(a.v[m])) ++m;
  const uint32_t x = a.v[(m + 2) % 3], y = a.v[(m + 1) % 3];
  uint32_t d = b.v[0];
  for (uint32_t v : b.v)
    if (v != x && v != y) d = v;
  return {a.v[m], y, d, x};
}

}  // namespace

TrianglePairs pair_triangles(const Scene& s) {
  const auto n = uint32_t(s.triangles.size());
  // Every edge use, sorted so that the triangles sharing an edge sit together.
  std::vector<EdgeUse> uses;
  uses.reserve(3 * size_t(n));
  for (uint32_t t = 0; t < n; ++t)
    for (int e = 0; e < 3; ++e) {
      const uint32_t p = s.triangles[t].v[e], q = s.triangles[t].v[(e + 1) % 3];
      uses.push_back({(uint64_t(std::min(p, q)) << 32) | std::max(p, q), t});
    }
  tbb::parallel_sort(uses.begin(), uses.end());
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < uses.size();) {
    size_t j = i + 1;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    for (size_t k = i; k + 1 < j; ++k) {  // neighbours along the edge (two on a manifold edge)
      const uint32_t a = uses[k].tri, b = uses[k + 1].tri;
      if (a == b || !share_one_edge(s.triangles[a], s.triangles[b])) continue;
      const double c = std::abs(dot(unit_normal(s, s.triangles[a]), unit_normal(s, s.triangles[b])));
      if (c >= kMinCos) candidates.push_back({c, a, b});
    }
    i = j;
  }
  uses = {};
  tbb::parallel_sort(candidates.begin(), candidates.end());
  std::vector<uint32_t> partner(n, kNone);
  TrianglePairs out;
  for (const Candidate& c : candidates)
    if (partner[c.a] == kNone && partner[c.b] == kNone) {
      partner[c.a] = c.b;
      partner[c.b] = c.a;
      out.paired += 2;
    }
  out.quads.reserve(n - out.paired / 2);
  out.triangle.reserve(2 * (n - out.paired / 2));
  for (uint32_t t = 0; t < n; ++t) {
    const Triangle& tri = s.triangles[t];
    if (partner[t] == kNone) {
      out.quads.push_back({tri.v[0], tri.v[1], tri.v[2], tri.v[2]});
      out.triangle.insert(out.triangle.end(), {t, t});
    } else if (t < partner[t]) {
      out.quads.push_back(quad_of(tri, s.triangles[partner[t]]));
      out.triangle.insert(out.triangle.end(), {t, partner[t]});
    }
  }
  return out;
}

}  // namespace pb::cpu
