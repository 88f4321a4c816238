#pragma once
// The builders' box (bvh_build.cpp, wide_bvh_build.cpp, bvh_optimize.cpp) and a binary node's
// child slots read and written as boxes. Host code only.
#include <limits>

#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/common/math.h"

namespace pb::bvh {

struct BuildBox {
  Vec3f lo{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
           std::numeric_limits<float>::infinity()};
  Vec3f hi{-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
           -std::numeric_limits<float>::infinity()};
  void grow(Vec3f p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  void grow(const BuildBox& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  // Never grown, or the binary BVH's mark of an empty slot (a box at +infinity).
  bool empty() const { return !(lo.x <= hi.x) || lo.x == std::numeric_limits<float>::infinity(); }
  double area() const {
    if (empty()) return 0;
    const Vec3f e = hi - lo;
    return 2.0 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
  }
  Vec3f centre() const { return (lo + hi) * 0.5f; }
};

// A binary node's child slot c: empty (the box at +infinity finish_node writes), its box, and
// writing a box into it (the child reference is the caller's).
inline bool empty_slot(const BvhNode& n, int c) { return n.x[2 * c] == std::numeric_limits<float>::infinity(); }
inline BuildBox slot_box(const BvhNode& n, int c) {
  BuildBox b;
  b.lo = {n.x[2 * c], n.y[2 * c], n.z[2 * c]};
  b.hi = {n.x[2 * c + 1], n.y[2 * c + 1], n.z[2 * c + 1]};
  return b;
}
inline void set_slot_box(BvhNode& n, int c, const BuildBox& b) {
  n.x[2 * c] = b.lo.x; n.x[2 * c + 1] = b.hi.x;
  n.y[2 * c] = b.lo.y; n.y[2 * c + 1] = b.hi.y;
  n.z[2 * c] = b.lo.z; n.z[2 * c + 1] = b.hi.z;
}

}  // namespace pb::bvh
