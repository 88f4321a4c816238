#pragma once
// Small helpers shared by the scene tests (test_scene_builtins.cpp, test_scene_files.cpp).
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene.h"

namespace pb::scene_test {

// The message of the InputError that f throws, or "(no InputError)".
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

inline Vec3f normal_of(const Scene& s, const Triangle& t) {
  const Vec3f a = s.positions[t.v[0]], b = s.positions[t.v[1]], c = s.positions[t.v[2]];
  return normalize(cross(b - a, c - a));
}

inline uint32_t material_named(const Scene& s, const std::string& name) {
  for (uint32_t i = 0; i < s.material_names.size(); ++i)
    if (s.material_names[i] == name) return i;
  ADD_FAILURE() << "no material " << name;
  return 0;
}

// The scene has `count` emissive triangles, all facing straight down.
inline void expect_emitters_face_down(const Scene& s, size_t count) {
  ASSERT_EQ(s.emitters.size(), count);
  for (uint32_t e : s.emitters) EXPECT_NEAR(normal_of(s, s.triangles[e]).y, -1, 1e-6) << "emitter " << e;
}

}  // namespace pb::scene_test
