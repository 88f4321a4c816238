#pragma once
// What the batched shading (shade_x8.h) reads and writes, and the table of its entry
// points per instruction set (BatchKernels), compiled for the build's baseline
// instruction set (shade_x8.h itself is AVX2 or AVX-512 code, in shade_avx2.cpp and
// shade_avx512.cpp).
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

#include "pathbench/common/path.h"
#include "pathbench/common/settings.h"

namespace pb::cpu {

struct TinyScene;  // tiny_scene.h

// The widest batch: AVX-512's 16 float lanes (AVX2: 8). Arrays are sized for it; a
// kernel reads its own width of them.
constexpr int kMaxShadeLanes = 16;

// Where the shading kernel appends the lanes of one kind (ShadeBatch::next, ::final,
// ::shadow), packed in lane order, as structures of arrays: the rays land where the next
// packet is traced from (an Embree packet's org/dir arrays, or the wavefront's live
// rays), with no per-lane loop and no transpose (docs/notes/cpu-log.md, "SoA hand-over").
struct ShadeStream {
  float* ray[6];           // org x, y, z, dir x, y, z (unused by the final stream)
  float* contribution[3];  // the shadow stream's: added to L where the ray is unoccluded
  uint32_t* tag;           // the lane's ShadeBatch::tag (shadow stream: | kEnds where the path ends)
  uint32_t n;              // entries so far: the kernel appends at n and advances it
  static constexpr uint32_t kEnds = 0x80000000u;
};

// One batch: up to a kernel's width of paths that hit a triangle, and where shading them
// sends each one. Every used lane goes to exactly one of: `next` (goes on, its next
// vertex before final_depth), `final` (goes on to its last vertex: depth >= final_depth
// after this one), `done` (ended, no shadow ray), or `shadow` only (ended; done once its
// shadow ray is answered); a path going on may be in `shadow` too.
struct ShadeBatch {
  PathState<float>* st[kMaxShadeLanes];
  uint32_t prim[kMaxShadeLanes];  // hit triangle of each lane
  uint32_t tag[kMaxShadeLanes];   // the caller's name for each lane (a pool slot, a sample)
  int lanes;                      // lanes in use; the rest repeat lane 0 and write nothing
  uint32_t final_depth = ~0u;     // a lane going on to this depth goes to `final`
  ShadeStream* next = nullptr;    // rays (origin, direction) and tags
  ShadeStream* final = nullptr;   // tags (may be null where final_depth is never reached)
  ShadeStream* shadow = nullptr;  // shadow rays (origin, segment), contributions, tags
  uint32_t done;                  // out: bit i, lane i ended without a shadow ray
};

// Per triangle, everything shading reads of it, as three rows of eight floats so eight
// lanes load it with three 8x8 transposes instead of ~20 scalar loads each:
//   row 0: v0.xyz, e1.xyz, e2.xy     row 1: e2.z, ng.xyz, albedo.xyz, emits
//   row 2: emission.xyz, scatters, 0 x 4
// e1 = v1 - v0, e2 = v2 - v0 and ng = fnormalize(fcross(e1, e2)) are computed exactly as
// surface_hit and path_hit compute them (same float operations, so the same bits);
// `emits` and `scatters` are masks (-1 or 0): emission nonzero, albedo nonzero.
// 96 bytes a triangle: built only for scenes up to kMaxTriangles (the rest shade one
// path at a time).
struct ShadeTable {
  static constexpr uint32_t kRowFloats = 24;
  static constexpr uint32_t kMaxTriangles = 1u << 16;
  std::vector<float> rows;

  static bool fits(const SceneView& s) { return s.num_triangles <= kMaxTriangles; }
  explicit ShadeTable(const SceneView& s) : rows(size_t(s.num_triangles) * kRowFloats, 0.0f) {
    for (uint32_t t = 0; t < s.num_triangles; ++t) {
      const Triangle tri = s.triangles[t];
      const Vec3f v0 = s.positions[tri.v[0]];
      const Vec3f e1 = s.positions[tri.v[1]] - v0;
      const Vec3f e2 = s.positions[tri.v[2]] - v0;
      const Vec3f ng = fnormalize(fcross(e1, e2));
      const Material& m = s.material_of(t);
      const int32_t emits = is_zero(m.emission) ? 0 : -1, scatters = is_zero(m.albedo) ? 0 : -1;
      float* r = &rows[size_t(t) * kRowFloats];
      const float head[16] = {v0.x, v0.y, v0.z, e1.x, e1.y, e1.z, e2.x, e2.y,
                              e2.z, ng.x, ng.y, ng.z, m.albedo.x, m.albedo.y, m.albedo.z, 0.0f};
      std::memcpy(r, head, sizeof head);
      std::memcpy(r + 15, &emits, sizeof emits);
      r[16] = m.emission.x; r[17] = m.emission.y; r[18] = m.emission.z;
      std::memcpy(r + 19, &scatters, sizeof scatters);
    }
  }
  const float* row(uint32_t triangle) const { return &rows[size_t(triangle) * kRowFloats]; }
};

// The batched path step of one instruction set, `lanes` paths at a time (shade_x8.h;
// pointers: the functions are compiled for that instruction set in their own
// translation units). Arrays passed in hold `lanes` entries; idle lanes repeat lane 0.
struct BatchKernels {
  Isa isa;
  int lanes;
  // path_begin for `lanes` paths (the first `used` of them are stored); `rays`, unless
  // null: their camera rays also to rays[0..6)[0..used) (org x, y, z, dir x, y, z).
  void (*begin_paths)(const SceneView&, const PathConfig&, const uint32_t* pixel, const uint32_t* sample,
                      PathState<float>* const* st, int used, float* const* rays);
  // Whether an emitter may lie along each path's ray (false only where the scalar
  // path_final_query would find none).
  void (*final_vertex_candidates)(const SceneView&, PathState<float>* const* st, bool* candidate);
  // surface_hit + path_hit for the batch's lanes (diffuse-only, float); its lanes to
  // the batch's streams.
  void (*shade_diffuse)(const SceneView&, const PathConfig&, const ShadeTable&, ShadeBatch&);
  // sincos_turns<float> (sampling.h) of `lanes` turn fractions (for the tests).
  void (*sincos_turns)(const float* u, float* s, float* c);
  // The tiny-scene test (tiny_x8.h) of `lanes` rays (org_dir: six arrays, as an
  // Embree packet's and the shading's streams; tfar: the packet's): closest hit (scene triangle, or
  // RTC_INVALID_GEOMETRY_ID) or blocked, per lane. Returns the lanes left unsure (bit i:
  // lane i), whose answer is Embree's to give.
  uint32_t (*tiny_closest)(const TinyScene&, const float* const* org_dir, const float* tfar, uint32_t* triangle);
  uint32_t (*tiny_occluded)(const TinyScene&, const float* const* org_dir, const float* tfar, bool* blocked);
};
const BatchKernels& avx2_kernels();    // shade_avx2.cpp
const BatchKernels& avx512_kernels();  // shade_avx512.cpp

// The kernels for a resolved ISA (cpu/isa.h), or null for Isa::Scalar.
inline const BatchKernels* batch_kernels(Isa isa) {
  return isa == Isa::Avx512 ? &avx512_kernels() : isa == Isa::Avx2 ? &avx2_kernels() : nullptr;
}

// The batched shading runs for diffuse-only float renders with a vector ISA, in scenes
// small enough for its table: then this returns the table, otherwise null.
template <class T, uint32_t Kinds> std::unique_ptr<ShadeTable> batched_shading_table(const SceneView& s, Isa isa) {
  if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly)
    if (batch_kernels(isa) && ShadeTable::fits(s)) return std::make_unique<ShadeTable>(s);
  return nullptr;
}

}  // namespace pb::cpu
