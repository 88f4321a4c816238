// Experiment (issue 32): the binary BVH collapsed to 4-wide float nodes (wide4_float.h).
#include "pathbench/bvh/wide4_float.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace pb::bvh {

namespace {

struct Child {
  uint32_t ref;  // a binary node index or a leaf reference
  float lo[3], hi[3];
  double area() const {
    const double ex = double(hi[0]) - lo[0], ey = double(hi[1]) - lo[1], ez = double(hi[2]) - lo[2];
    return 2.0 * (ex * ey + ey * ez + ez * ex);
  }
};

void children_of(const std::vector<BvhNode>& b, uint32_t node, std::vector<Child>& dst) {
  const BvhNode& n = b[node];
  for (int c = 0; c < 2; ++c) {
    if (n.x[2 * c] == std::numeric_limits<float>::infinity()) continue;  // empty slot
    dst.push_back({n.child[c], {n.x[2 * c], n.y[2 * c], n.z[2 * c]}, {n.x[2 * c + 1], n.y[2 * c + 1], n.z[2 * c + 1]}});
  }
}

struct Collapse {
  const std::vector<BvhNode>& b;
  std::vector<Wide4Node> out;
  uint32_t depth = 0;

  void emit(uint32_t binary_node, uint32_t index, uint32_t level) {
    depth = std::max(depth, level);
    std::vector<Child> ch;
    children_of(b, binary_node, ch);
    for (;;) {  // open the largest inner child while there is room
      int best = -1;
      for (int i = 0; i < int(ch.size()); ++i)
        if (!is_leaf(ch[i].ref) && (best < 0 || ch[i].area() > ch[best].area())) best = i;
      if (best < 0 || ch.size() + 1 > 4) break;
      const uint32_t opened = ch[best].ref;
      ch.erase(ch.begin() + best);
      children_of(b, opened, ch);
    }
    Wide4Node n{};
    const float inf = std::numeric_limits<float>::infinity();
    uint32_t inner[4] = {}, next = uint32_t(out.size());
    for (int k = 0; k < 4; ++k) {
      if (k >= int(ch.size())) {
        n.lox[k] = n.hix[k] = n.loy[k] = n.hiy[k] = n.loz[k] = n.hiz[k] = inf;
        n.child[k] = make_leaf_ref(0, 1);
        continue;
      }
      const Child& c = ch[k];
      n.lox[k] = c.lo[0]; n.loy[k] = c.lo[1]; n.loz[k] = c.lo[2];
      n.hix[k] = c.hi[0]; n.hiy[k] = c.hi[1]; n.hiz[k] = c.hi[2];
      if (is_leaf(c.ref)) {
        n.child[k] = c.ref;
      } else {
        inner[k] = next++;
        n.child[k] = inner[k];
      }
    }
    out.resize(next);
    out[index] = n;
    for (int k = 0; k < int(ch.size()); ++k)
      if (!is_leaf(ch[k].ref)) emit(ch[k].ref, inner[k], level + 1);
  }
};

}  // namespace

std::vector<BvhNode> collapse_to_wide4(const std::vector<BvhNode>& binary, uint32_t& depth) {
  if (binary.empty()) throw std::invalid_argument("wide4: the binary BVH has no root");
  Collapse c{binary, {}, 0};
  c.out.resize(1);
  c.emit(0, 0, 1);
  // At most 3 entries pushed a level: the stack must hold them all.
  if (3 * c.depth + 1 > uint32_t(kTraversalStackSize))
    throw std::runtime_error("wide4: the collapsed tree is too deep for the traversal stack");
  depth = c.depth;
  std::vector<BvhNode> slots(c.out.size() * 2);
  std::copy_n(reinterpret_cast<const BvhNode*>(c.out.data()), slots.size(), slots.data());
  return slots;
}

}  // namespace pb::bvh
