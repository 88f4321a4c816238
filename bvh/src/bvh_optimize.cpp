// Treelet restructuring of the flattened binary BVH (Karras & Aila, "Fast Parallel Construction
// of High-Quality Bounding Volume Hierarchies", HPG 2013): bottom-up, each inner node and up to
// six of its descendants (the treelet: expanded by largest area until it has 7 leaves) are
// rearranged into the binary tree over the same 7 subtrees with the least SAH cost, found by
// dynamic programming over the subsets of the leaves. Leaves and their triangles stay as they
// are, and so do the boxes of the subtrees below a treelet. A treelet's new inner nodes bound
// the (padded) boxes they join. The nodes are then renumbered depth first.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include <tbb/parallel_for.h>

#include "pathbench/bvh/bvh_build.h"
#include "build_box.h"

namespace pb::bvh {

namespace {

using Box = BuildBox;

// The SAH's area of a box, its extents taken in double (the builders' Box::area takes them in
// float): what the restructuring's costs and decisions were measured with.
double sah_area(const Box& b) {
  if (b.empty()) return 0;
  const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
  return 2.0 * (x * y + y * z + z * x);
}

void set_slot(BvhNode& n, int c, uint32_t ref, const Box& b) {
  set_slot_box(n, c, b);
  n.child[c] = ref;
}

constexpr int kTreeletLeaves = 7;

class Restructurer {
 public:
  // The SAH's weights: tri_cost a triangle tested, node_cost a node visited (BvhBuildOptions'
  // intersection_cost and traversal_cost).
  Restructurer(std::vector<BvhNode>& nodes, double tri_cost, double node_cost)
      : n_(nodes), tri_cost_(tri_cost), node_cost_(node_cost), cost_(nodes.size()) {}

  // One bottom-up pass; returns the tree's SAH cost (unnormalised) after it. The subtrees
  // below kCutDepth are passed in parallel (a treelet lies inside its root's subtree, so
  // disjoint subtrees never touch the same node), then the levels above them in order: the
  // result does not depend on the threads.
  double pass() {
    std::vector<uint32_t> cut;
    collect(0, 0, cut);
    tbb::parallel_for(size_t(0), cut.size(), [&](size_t i) { post_order(cut[i], true, kNoLimit); });
    post_order(0, true, kCutDepth);
    return cost_[0];
  }
  double cost() {
    post_order(0, false, kNoLimit);
    return cost_[0];
  }

 private:
  // A subtree's cost: a leaf's triangles, or a node's own cost and its children's.
  double ref_cost(uint32_t ref, const Box& b) const {
    return is_leaf(ref) ? tri_cost_ * sah_area(b) * leaf_count(ref) : cost_[ref];
  }
  void update_cost(uint32_t i) {
    const BvhNode& n = n_[i];
    Box u;
    double c = 0;
    for (int k = 0; k < 2; ++k) {
      if (empty_slot(n, k)) continue;
      const Box b = slot_box(n, k);
      u.grow(b);
      c += ref_cost(n.child[k], b);
    }
    cost_[i] = c + node_cost_ * sah_area(u);
  }

  static constexpr uint32_t kCutDepth = 8, kNoLimit = ~0u;

  // The inner nodes at kCutDepth (the roots of the subtrees passed in parallel).
  void collect(uint32_t i, uint32_t depth, std::vector<uint32_t>& cut) const {
    if (depth == kCutDepth) {
      cut.push_back(i);
      return;
    }
    for (int k = 0; k < 2; ++k)
      if (!empty_slot(n_[i], k) && !is_leaf(n_[i].child[k])) collect(n_[i].child[k], depth + 1, cut);
  }

  // Iterative post order from `root`: a node after both its children. Nodes `limit` levels
  // below the root are taken as done (their subtrees were passed already).
  void post_order(uint32_t root, bool restructure, uint32_t limit) {
    struct Item { uint32_t node, depth; bool seen; };
    std::vector<Item> stack{{root, 0, false}};
    while (!stack.empty()) {
      const Item it = stack.back();
      stack.pop_back();
      if (it.seen) {
        update_cost(it.node);
        if (restructure) treelet(it.node);
        continue;
      }
      stack.push_back({it.node, it.depth, true});
      if (it.depth + 1 >= limit) continue;
      for (int k = 0; k < 2; ++k) {
        const BvhNode& n = n_[it.node];
        if (!empty_slot(n, k) && !is_leaf(n.child[k])) stack.push_back({n.child[k], it.depth + 1, false});
      }
    }
  }

  void treelet(uint32_t root) {
    const BvhNode& r = n_[root];
    if (empty_slot(r, 0) || empty_slot(r, 1)) return;
    uint32_t leaf_ref[kTreeletLeaves];
    Box leaf_box[kTreeletLeaves];
    int n = 0;
    for (int k = 0; k < 2; ++k) { leaf_ref[n] = r.child[k]; leaf_box[n] = slot_box(r, k); ++n; }
    uint32_t inner[kTreeletLeaves - 1] = {root};
    int ni = 1;
    while (n < kTreeletLeaves) {  // open the largest inner treelet leaf with two children
      int best = -1;
      for (int k = 0; k < n; ++k) {
        if (is_leaf(leaf_ref[k])) continue;
        const BvhNode& c = n_[leaf_ref[k]];
        if (empty_slot(c, 0) || empty_slot(c, 1)) continue;
        if (best < 0 || sah_area(leaf_box[k]) > sah_area(leaf_box[best])) best = k;
      }
      if (best < 0) break;
      const uint32_t opened = leaf_ref[best];
      const BvhNode& c = n_[opened];
      inner[ni++] = opened;
      leaf_ref[best] = c.child[0]; leaf_box[best] = slot_box(c, 0);
      leaf_ref[n] = c.child[1]; leaf_box[n] = slot_box(c, 1);
      ++n;
    }
    if (n < 3) return;
    const uint32_t full = (1u << n) - 1;
    Box box[1 << kTreeletLeaves];
    double area[1 << kTreeletLeaves], best_cost[1 << kTreeletLeaves];
    uint32_t split[1 << kTreeletLeaves] = {};
    for (uint32_t m = 1; m <= full; ++m) {
      const int low = __builtin_ctz(m);
      box[m] = box[m & (m - 1)];
      box[m].grow(leaf_box[low]);
      area[m] = sah_area(box[m]);
    }
    for (int k = 0; k < n; ++k) best_cost[1u << k] = ref_cost(leaf_ref[k], leaf_box[k]);
    for (uint32_t m = 1; m <= full; ++m) {
      if ((m & (m - 1)) == 0) continue;
      // Partitions (p, m ^ p) with p holding m's lowest leaf: each split once.
      const uint32_t low = m & (~m + 1), rest = m ^ low;
      double b = std::numeric_limits<double>::infinity();
      uint32_t bp = 0;
      for (uint32_t s = (rest - 1) & rest;; s = (s - 1) & rest) {  // s: proper subsets of rest
        const uint32_t p = s | low;
        const double c = best_cost[p] + best_cost[m ^ p];
        if (c < b) { b = c; bp = p; }
        if (s == 0) break;
      }
      best_cost[m] = b + node_cost_ * area[m];
      split[m] = bp;
    }
    if (!(best_cost[full] < cost_[root] * (1.0 - 1e-9))) return;  // no gain: leave it
    int next_inner = 1;
    rebuild(full, root, split, leaf_ref, leaf_box, box, best_cost, inner, next_inner);
  }

  // Writes the subtree of leaf set m into node `at` (m has two or more leaves).
  void rebuild(uint32_t m, uint32_t at, const uint32_t* split, const uint32_t* leaf_ref, const Box* leaf_box,
               const Box* box, const double* best_cost, const uint32_t* inner, int& next_inner) {
    const uint32_t part[2] = {split[m], m ^ split[m]};
    for (int k = 0; k < 2; ++k) {
      const uint32_t p = part[k];
      if ((p & (p - 1)) == 0) {
        const int leaf = __builtin_ctz(p);
        set_slot(n_[at], k, leaf_ref[leaf], leaf_box[leaf]);
      } else {
        const uint32_t idx = inner[next_inner++];
        rebuild(p, idx, split, leaf_ref, leaf_box, box, best_cost, inner, next_inner);
        set_slot(n_[at], k, idx, box[p]);
      }
    }
    cost_[at] = best_cost[m];
  }

  std::vector<BvhNode>& n_;
  double tri_cost_, node_cost_;
  std::vector<double> cost_;
};

// Depth-first renumbering (the order the flattener writes): node 0 the root, each node's
// first child right after it. Returns the depth as the flattener counts it: the inner nodes
// on the longest path from the root to a leaf.
uint32_t renumber(std::vector<BvhNode>& nodes) {
  std::vector<BvhNode> out;
  out.reserve(nodes.size());
  uint32_t depth = 0;
  struct Item { uint32_t old, parent; int slot; uint32_t level; };
  std::vector<Item> stack{{0, 0, -1, 0}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const uint32_t idx = uint32_t(out.size());
    out.push_back(nodes[it.old]);
    if (it.slot >= 0) out[it.parent].child[it.slot] = idx;
    depth = std::max(depth, it.level + 1);
    for (int k = 1; k >= 0; --k) {  // child 0 popped first
      const BvhNode& n = nodes[it.old];
      if (!empty_slot(n, k) && !is_leaf(n.child[k])) stack.push_back({n.child[k], idx, k, it.level + 1});
    }
  }
  nodes.swap(out);
  return depth;
}

}  // namespace

BvhOptimizeResult optimize_treelets(std::vector<BvhNode>& nodes, const BvhBuildOptions& o) {
  BvhOptimizeResult r;
  if (nodes.empty() || o.optimize_passes == 0) return r;
  Restructurer t(nodes, o.intersection_cost, o.traversal_cost);
  r.cost_before = t.cost();
  r.cost_after = r.cost_before;
  for (uint32_t p = 0; p < o.optimize_passes; ++p) r.cost_after = t.pass();
  r.depth = renumber(nodes);
  return r;
}

}  // namespace pb::bvh
