#pragma once
// How the CPU tracer builds its Embree scenes. ROBUST matters: without it, Embree 3's
// triangle test is not watertight and rays aimed exactly at shared edges and vertices
// of a closed mesh slip through (measured: 2.4% of such rays in the paper's box,
// tests/unit/test_stability.cpp) -- the paper's black seams, by another route.
#include <embree3/rtcore.h>

namespace pb::cpu {

// `watertight` = RenderSettings::watertight (on by default); off trades the
// guarantee for speed (about 30% fewer instructions per sample on paper-cornell).
inline constexpr RTCSceneFlags embree_scene_flags(bool watertight) {
  return watertight ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE;
}

}  // namespace pb::cpu
