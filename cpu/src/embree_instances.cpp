// The instanced Embree scene (EmbreeScene's Instanced constructor): Embree instancing
// for the acceleration structure only. Each prototype is one Embree scene in its own
// coordinates, each SceneInstance an RTC_GEOMETRY_TYPE_INSTANCE of it, and the
// triangles no instance covers (walls, lights, instances that lost triangles to
// finalize(), copies rounded far from their prototype's image: exact_copy) one ordinary
// triangle geometry. Embree then names a triangle; the path step recomputes the hit on
// the flat, world-space triangle (surface_hit), so shading
// sees exactly the flat scene's triangles. Whether Embree names the same triangle as
// in the flat scene is tested, not assumed (tests/unit/test_instancing.cpp, docs/notes/cpu-log.md).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <unordered_map>

#include "pathbench/cpu/embree_flags.h"
#include "pathbench/cpu/embree_scene.h"

namespace pb::cpu {

namespace {

// One triangle geometry of `positions` and `triangles`, attached to `scene` as `id`.
void attach_triangles(RTCDevice device, RTCScene scene, const std::vector<Vec3f>& positions,
                      const std::vector<Triangle>& triangles, unsigned id) {
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
  std::memcpy(v, positions.data(), positions.size() * sizeof(Vec3f));
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(uint32_t), triangles.size()));
  std::memcpy(idx, triangles.data(), triangles.size() * sizeof(Triangle));
  rtcCommitGeometry(g);
  rtcAttachGeometryByID(scene, g, id);
  rtcReleaseGeometry(g);
}

// Whether the instance's flat triangles are its prototype's image under its transform up
// to the rounding of that one expansion (half an ulp; a few ulps allowed). Not so where the
// scene was rebased far from the origin or rescaled after loading: the flat copy was
// rounded at the user's coordinates, and Embree's instance (the prototype, transformed
// exactly) would be another surface, a thousandth of the scene off at 3e5 from the origin.
// Such copies stay flat.
bool exact_copy(const Scene& s, const SceneInstance& in) {
  float largest = 0;
  for (uint32_t k = 0; k < in.triangle_count; ++k)
    for (uint32_t v : s.triangles[in.first_triangle + k].v)
      largest = std::max({largest, std::fabs(s.positions[v].x), std::fabs(s.positions[v].y), std::fabs(s.positions[v].z)});
  return instance_deviation(s, in) <= std::ldexp(double(largest), -22);
}

}  // namespace

void EmbreeScene::build_instanced(const Scene& s, bool watertight) {
  // An instance is traced as an instance only where it kept every prototype triangle
  // (then its flat triangles are first_triangle + the prototype's primitive ids) and its
  // flat copy is the prototype's image (exact_copy).
  std::vector<char> covered(s.triangles.size(), 0);
  std::vector<RTCScene> proto_scene(s.prototypes.size(), nullptr);
  unsigned id = 0;
  for (const SceneInstance& in : s.instances) {
    const ScenePrototype& p = s.prototypes.at(in.prototype);
    if (in.triangle_count != p.triangles.size() || p.triangles.empty() || !exact_copy(s, in)) {
      ++facts_.instances_left_flat;
      continue;
    }
    RTCScene& ps = proto_scene[in.prototype];
    if (!ps) {
      ps = rtcNewScene(device_);
      rtcSetSceneFlags(ps, embree_scene_flags(watertight));
      rtcSetSceneBuildQuality(ps, RTC_BUILD_QUALITY_HIGH);
      attach_triangles(device_, ps, p.positions, p.triangles, 0);
      rtcCommitScene(ps);
      prototypes_.push_back(ps);
    }
    const Affine m = traced_to_world(s, in);
    float xfm[12];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) xfm[4 * r + c] = float(m.m[r][c]);
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, ps);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, xfm);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene_, g, id++);
    rtcReleaseGeometry(g);
    instance_first_.push_back(in.first_triangle);
    std::memset(covered.data() + in.first_triangle, 1, in.triangle_count);
  }
  facts_.instances = instance_first_.size();
  facts_.prototypes = prototypes_.size();

  // The rest: its own compact vertex array (only the vertices its triangles use).
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::unordered_map<uint32_t, uint32_t> vertex;
  for (uint32_t i = 0; i < s.triangles.size(); ++i) {
    if (covered[i]) continue;
    Triangle t{};
    for (int k = 0; k < 3; ++k) {
      auto [it, added] = vertex.try_emplace(s.triangles[i].v[k], uint32_t(positions.size()));
      if (added) positions.push_back(s.positions[s.triangles[i].v[k]]);
      t.v[k] = it->second;
    }
    triangles.push_back(t);
    rest_.push_back(i);
  }
  facts_.flat_triangles = rest_.size();
  if (!triangles.empty()) attach_triangles(device_, scene_, positions, triangles, id);
}

}  // namespace pb::cpu
