#include "pathbench/bvh/wide_bvh_build.h"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include "build_box.h"

namespace pb::bvh {

namespace {

using Box = BuildBox;

float axis(const Vec3f& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

// A child while a node is being collapsed: a binary inner node, or a run of the binary
// BVH's triangles (a leaf, or part of one too large for a wide leaf).
struct Item {
  bool range = false;
  uint32_t node = 0;          // binary node (range == false)
  uint32_t first = 0, count = 0;
  Box box;
  bool wide_leaf() const { return range && count <= kWideMaxLeafTris; }
};

class Collapser {
 public:
  Collapser(const BvhHost& b, uint32_t width, WideBvhHost& out) : b_(b), width_(width), out_(out) {}

  void children_of(const Item& it, std::vector<Item>& dst) const {
    if (it.range) {  // split a run in halves
      const uint32_t half = it.count / 2;
      dst.push_back(range_item(it.first, half));
      dst.push_back(range_item(it.first + half, it.count - half));
      return;
    }
    const BvhNode& n = b_.nodes[it.node];
    for (int c = 0; c < 2; ++c) {
      Item ch;
      ch.box = slot_box(n, c);
      if (ch.box.empty()) continue;
      const uint32_t ref = n.child[c];
      if (is_leaf(ref)) {
        ch.range = true;
        ch.first = leaf_first(ref);
        ch.count = leaf_count(ref);
      } else {
        ch.node = ref;
      }
      dst.push_back(ch);
    }
  }

  // Writes node `index` for `root` (a binary node, or a run too large for one leaf).
  void emit(const Item& root, uint32_t index, uint32_t depth) {
    out_.depth = std::max(out_.depth, depth);
    std::vector<Item> ch;
    children_of(root, ch);
    for (;;) {  // open the largest openable child while there is room
      int best = -1;
      for (int i = 0; i < int(ch.size()); ++i)
        if (!ch[i].wide_leaf() && (best < 0 || ch[i].box.area() > ch[best].box.area())) best = i;
      if (best < 0 || ch.size() + 1 > width_) break;
      const Item opened = ch[best];
      ch.erase(ch.begin() + best);
      children_of(opened, ch);
    }
    int slot_of[8] = {};
    assign_slots(ch, slot_of);

    WideNode node{};
    Box box;
    for (const Item& c : ch) box.grow(c.box);
    quantise_frame(box, node);  // (an empty scene's root: no children, any frame)
    uint32_t inner_count = 0;
    for (const Item& c : ch) inner_count += !c.wide_leaf();
    node.child_base = uint32_t(out_.nodes.size());
    out_.nodes.resize(out_.nodes.size() + inner_count);
    node.tri_base = uint32_t(out_.tris.size());
    // Slot order: inner children contiguous by slot, leaf triangles likewise.
    const Item* by_slot[8] = {};
    for (size_t i = 0; i < ch.size(); ++i) by_slot[slot_of[i]] = &ch[i];
    uint32_t tri_offset = 0;
    for (uint32_t s = 0; s < 8; ++s) {
      const Item* c = by_slot[s];
      if (!c) continue;
      quantise_child(node, s, c->box);
      if (c->wide_leaf()) {
        for (uint32_t k = 0; k < c->count; ++k) out_.tris.push_back(b_.tris[c->first + k]);
        node.meta[s] = uint8_t(((1u << c->count) - 1u) << 5 | tri_offset);
        tri_offset += c->count;
        ++out_.leaves;
      } else {
        node.imask |= uint8_t(1u << s);
        node.meta[s] = uint8_t(1u << 5 | (24u + s));
      }
    }
    if (tri_offset > 24) throw std::logic_error("wide bvh: more than 24 triangles in one node");
    out_.nodes[index] = node;
    uint32_t k = 0;
    for (uint32_t s = 0; s < 8; ++s)
      if (by_slot[s] && !by_slot[s]->wide_leaf()) emit(*by_slot[s], node.child_base + k++, depth + 1);
  }

 private:
  Item range_item(uint32_t first, uint32_t count) const {
    Item it;
    it.range = true;
    it.first = first;
    it.count = count;
    for (uint32_t i = first; i < first + count; ++i) {
      const BvhTriangle& t = b_.tris[i];
      Box tb;
      tb.lo = vmin(vmin(Vec3f{t.v0[0], t.v0[1], t.v0[2]}, Vec3f{t.v1[0], t.v1[1], t.v1[2]}), Vec3f{t.v2[0], t.v2[1], t.v2[2]});
      tb.hi = vmax(vmax(Vec3f{t.v0[0], t.v0[1], t.v0[2]}, Vec3f{t.v1[0], t.v1[1], t.v1[2]}), Vec3f{t.v2[0], t.v2[1], t.v2[2]});
      it.box.grow(tb);
    }
    const float p = b_.pad;
    it.box.lo = it.box.lo - Vec3f{p, p, p};
    it.box.hi = it.box.hi + Vec3f{p, p, p};
    return it;
  }

  // Slot s is the node's corner s (bit k set: the + side of axis k); each child goes to
  // the free slot toward which its centre lies furthest, greedily (the paper's auction).
  static void assign_slots(const std::vector<Item>& ch, int (&slot_of)[8]) {
    Box all;
    for (const Item& c : ch) all.grow(c.box);
    const Vec3f mid = all.centre();
    bool used_slot[8] = {}, done[8] = {};
    for (size_t round = 0; round < ch.size(); ++round) {
      double best = -std::numeric_limits<double>::infinity();
      int bc = -1, bs = -1;
      for (size_t c = 0; c < ch.size(); ++c) {
        if (done[c]) continue;
        const Vec3f v = ch[c].box.centre() - mid;
        for (int s = 0; s < 8; ++s) {
          if (used_slot[s]) continue;
          const double score = double(s & 1 ? v.x : -v.x) + double(s & 2 ? v.y : -v.y) + double(s & 4 ? v.z : -v.z);
          if (score > best) { best = score; bc = int(c); bs = s; }
        }
      }
      done[bc] = true;
      used_slot[bs] = true;
      slot_of[bc] = bs;
    }
  }

  // The node's grid: origin at its box's low corner, per axis a power-of-two step with
  // 255 steps covering the box.
  static void quantise_frame(const Box& box, WideNode& n) {
    for (int k = 0; k < 3; ++k) {
      const float lo = box.empty() ? 0.0f : axis(box.lo, k);
      const double ext = box.empty() ? 0.0 : double(axis(box.hi, k)) - lo;
      int e = -126;
      if (ext > 0) {
        std::frexp(ext / 255.0, &e);  // ext / 255 <= 2^e
        e = std::max(e, -126);
        while (double(lo) + 255.0 * std::ldexp(1.0, e) < double(axis(box.hi, k))) ++e;
      }
      if (e > 127) throw std::runtime_error("wide bvh: scene too large for the quantised node format");
      n.p[k] = lo;
      n.e[k] = uint8_t(e + 127);
    }
  }

  // Child box in node steps, rounded outward (checked exactly, in double).
  static void quantise_child(WideNode& n, uint32_t s, const Box& c) {
    for (int k = 0; k < 3; ++k) {
      const double p = n.p[k], step = std::ldexp(1.0, int(n.e[k]) - 127);
      const double lo = std::clamp(std::floor((double(axis(c.lo, k)) - p) / step), 0.0, 255.0);
      const double hi = std::clamp(std::ceil((double(axis(c.hi, k)) - p) / step), 0.0, 255.0);
      if (p + lo * step > axis(c.lo, k) || p + hi * step < axis(c.hi, k))
        throw std::logic_error("wide bvh: a quantised box does not hold its child");
      n.qlo[k][s] = uint8_t(lo);
      n.qhi[k][s] = uint8_t(hi);
    }
  }

  const BvhHost& b_;
  uint32_t width_;
  WideBvhHost& out_;
};

}  // namespace

WideBvhHost collapse_bvh(const BvhHost& binary, uint32_t width) {
  if (width < 2 || width > kWideMaxChildren) throw std::invalid_argument("wide bvh: width must be 2..8");
  if (binary.nodes.empty()) throw std::invalid_argument("wide bvh: the binary BVH has no root");
  const auto t0 = std::chrono::steady_clock::now();
  WideBvhHost out;
  out.width = width;
  out.nodes.reserve(binary.nodes.size() / 2 + 1);
  out.tris.reserve(binary.tris.size());
  out.nodes.resize(1);
  Collapser c(binary, width, out);
  Item root;
  root.node = 0;
  c.emit(root, 0, 1);
  if (out.depth + 1 > uint32_t(kWideStackSize))
    throw std::runtime_error(fmt::format("wide bvh: depth {} exceeds the traversal stack ({})", out.depth, kWideStackSize));
  out.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace pb::bvh
