// `paper-cornell-ico:L`: the paper's box with an icosphere of subdivision level L
// inside (20 * 4^L triangles; L = 8 gives 1,310,720), for scaling the triangle count
// while the light transport stays that of the paper's scene.
#include <cmath>
#include <vector>

#include "builder.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb {

namespace scenes {

namespace {

// Edge (a, b), a < b, to the id of its midpoint vertex: open addressing over
// 64-bit keys, sized once per level (a std::unordered_map is several times slower
// and larger at level 10's 8 million edges).
class EdgeMidpoints {
 public:
  explicit EdgeMidpoints(size_t edges) {
    int bits = 4;
    while ((size_t(1) << bits) < 2 * edges) ++bits;
    keys_.assign(size_t(1) << bits, kEmpty);
    values_.resize(keys_.size());
    mask_ = keys_.size() - 1;
    shift_ = 64 - bits;
  }
  // Returns the midpoint of (a, b), creating it in `positions` (on the unit sphere).
  uint32_t get(uint32_t a, uint32_t b, std::vector<Vec3f>& positions) {
    if (a > b) std::swap(a, b);
    const uint64_t key = (uint64_t(a) << 32) | b;
    size_t i = size_t((key * 0x9E3779B97F4A7C15ull) >> shift_);  // Fibonacci hashing
    while (keys_[i] != kEmpty) {
      if (keys_[i] == key) return values_[i];
      i = (i + 1) & mask_;
    }
    keys_[i] = key;
    values_[i] = uint32_t(positions.size());
    positions.push_back(normalize(positions[a] + positions[b]));
    return values_[i];
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t(0);
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> values_;
  size_t mask_ = 0;
  int shift_ = 60;
};

}  // namespace

void append_icosphere(Scene& s, Vec3f centre, float radius, int level, uint32_t material) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3f> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3f& v : p) v = normalize(v);
  // Counter-clockwise seen from outside.
  std::vector<Triangle> tris = {{{0, 11, 5}}, {{0, 5, 1}},  {{0, 1, 7}},   {{0, 7, 10}}, {{0, 10, 11}},
                                {{1, 5, 9}},  {{5, 11, 4}}, {{11, 10, 2}}, {{10, 7, 6}}, {{7, 1, 8}},
                                {{3, 9, 4}},  {{3, 4, 2}},  {{3, 2, 6}},   {{3, 6, 8}},  {{3, 8, 9}},
                                {{4, 9, 5}},  {{2, 4, 11}}, {{6, 2, 10}},  {{8, 6, 7}},  {{9, 8, 1}}};
  for (int l = 0; l < level; ++l) {
    // Each triangle becomes four; each edge (shared by two triangles) gets one midpoint.
    EdgeMidpoints mid(tris.size() * 3 / 2);
    p.reserve(p.size() + tris.size() * 3 / 2);
    std::vector<Triangle> next;
    next.reserve(tris.size() * 4);
    for (const Triangle& tr : tris) {
      const uint32_t a = tr.v[0], b = tr.v[1], c = tr.v[2];
      const uint32_t ab = mid.get(a, b, p), bc = mid.get(b, c, p), ca = mid.get(c, a, p);
      next.push_back({{a, ab, ca}});
      next.push_back({{b, bc, ab}});
      next.push_back({{c, ca, bc}});
      next.push_back({{ab, bc, ca}});
    }
    tris = std::move(next);
  }
  const uint32_t base = uint32_t(s.positions.size());
  s.positions.reserve(s.positions.size() + p.size());
  for (const Vec3f& v : p) s.positions.push_back(centre + v * radius);
  s.triangles.reserve(s.triangles.size() + tris.size());
  for (const Triangle& tr : tris) s.triangles.push_back({{base + tr.v[0], base + tr.v[1], base + tr.v[2]}});
  s.material_ids.resize(s.triangles.size(), material);
}

}  // namespace scenes

Scene make_paper_cornell_ico(int level) {
  Scene s = make_paper_cornell();
  s.name = "paper-cornell-ico:" + std::to_string(level);
  const uint32_t grey = scenes::add_material(s, "sphere", {0.5f, 0.5f, 0.5f});
  scenes::append_icosphere(s, {0, -4, -4}, 5.0f, level, grey);
  s.finalize();
  return s;
}

}  // namespace pb
