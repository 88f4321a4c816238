#pragma once
// Host side of the wide BVH (wide_bvh.h): the binary BVH of bvh_build.h collapsed into
// nodes of up to 4 or 8 children (greedy: open the child of largest surface area until
// the node is full), child boxes quantised outward, each node's leaf triangles stored
// together in traversal order. Plain C++, as bvh_build.h.
#include <cstdint>
#include <vector>

#include "pathbench/bvh/bvh_build.h"
#include "pathbench/bvh/wide_bvh.h"

namespace pb::bvh {

struct WideBvhHost {
  std::vector<WideNode> nodes;
  std::vector<BvhTriangle> tris;
  uint32_t width = 8;       // children a node at most
  uint32_t depth = 0;       // longest root-to-leaf path, in nodes
  uint32_t leaves = 0;
  double build_seconds = 0;  // the collapse alone

  WideBvhView view() const { return {nodes.data(), tris.data(), uint32_t(nodes.size()), uint32_t(tris.size())}; }
  uint64_t bytes() const { return nodes.size() * sizeof(WideNode) + tris.size() * sizeof(BvhTriangle); }
};

// `width` is 2..8. Leaves of the binary BVH larger than kWideMaxLeafTris are split
// (build it with max_leaf_size = kWideMaxLeafTris to avoid that).
WideBvhHost collapse_bvh(const BvhHost& binary, uint32_t width);

}  // namespace pb::bvh
