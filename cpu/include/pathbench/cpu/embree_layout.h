#pragma once
// EmbreeLayout::Auto: which layout (settings.h) Embree traces a scene faster with. In
// robust mode the answer depends on the scene -- paired into quads, paper-cornell took
// 22% fewer instructions per sample and cornell-box 21% more (docs/notes/cpu-log.md)
// -- so it is measured, not guessed: both layouts trace the same probe rays (camera rays,
// rays leaving random surface points, shadow rays to the emitters), in alternating
// rounds, and quads are kept only when clearly faster. The answer is remembered per scene
// for the life of the process, so every render of a scene in one process (pixel and
// wavefront, say) traces the same layout. Pin the layout (--embree-layout) where runs in
// different processes must trace alike.
#include <cstddef>
#include <string>

#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/cpu/triangle_pairs.h"

namespace pb::cpu {

struct LayoutChoice {
  EmbreeLayout layout = EmbreeLayout::Triangles;
  size_t paired = 0;           // triangles that pair up across shared edges
  double triangles_ns = 0.0;   // probe: best round, nanoseconds per ray (0: not probed)
  double quads_ns = 0.0;
  const char* reason = "";     // why this layout, in words
};

// Probed only when at least 90% of the triangles pair up (else Triangles: unpaired
// triangles are half-empty quads) and the scene has at most 2^16 triangles (building
// it twice stays cheap; on paper-cornell-ico:6, 82k triangles, quads were 1-4% slower).
// `pairs`, where given, receives the pairing the probe made (left empty when the answer
// was remembered or no probe ran), so that the caller need not pair again.
LayoutChoice choose_embree_layout(const Scene& scene, bool watertight, TrianglePairs* pairs = nullptr);

// Makes `choice` this process's answer for `scene` from now on, as if its probe had given
// it (choose_embree_layout then returns it, without pairs). MPI ranks: every rank takes
// rank 0's answer (run/ranks_render.cpp), since the probe is timed and a rank probing beside
// the others' builds could pick another layout, whose films differ in low bits (issue 30).
// Returns false (nothing remembered) where `reason` is not one the probe gives.
bool remember_embree_layout(const Scene& scene, bool watertight, EmbreeLayout layout, double triangles_ns,
                            double quads_ns, const std::string& reason);

}  // namespace pb::cpu
