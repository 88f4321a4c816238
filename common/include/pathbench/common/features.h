#pragma once
// Model only what a scene requires: the path step is compiled for a set of material
// kinds fixed at compile time (a bit mask, `Kinds`), so a diffuse-only render contains
// no branch, no load and no state for mirrors, glass or rough metal. A tracer picks the
// instantiation once per render from the scene's features:
//
//   with_features(scene.features.material_kinds, [&](auto kinds) {
//     constexpr uint32_t K = decltype(kinds)::value;
//     ... path_hit<K>(...) ...
//   });
//
// Two instantiations exist: diffuse-only, and every kind this build has. (Another one
// is one line in with_features, at the cost of compiling the tracers once more.)
// Built with PATHBENCH_EXTRA_MATERIALS=OFF there are no other kinds at all: scenes that
// need them fail to load (Scene::finalize).
#include <cstdint>
#include <stdexcept>
#include <type_traits>

#include "pathbench/common/scene.h"

#ifndef PATHBENCH_EXTRA_MATERIALS
#define PATHBENCH_EXTRA_MATERIALS 1
#endif

namespace pb {

constexpr uint32_t kind_bit(MaterialKind k) { return 1u << uint32_t(k); }
constexpr uint32_t kDiffuseOnly = kind_bit(MaterialKind::Diffuse);
constexpr uint32_t kAllMaterialKinds = kind_bit(MaterialKind::Diffuse) | kind_bit(MaterialKind::Mirror) |
                                       kind_bit(MaterialKind::Dielectric) | kind_bit(MaterialKind::RoughConductor);
// What this build can render; also the default instantiation of the path step (so
// callers that do not dispatch stay correct for every scene).
constexpr uint32_t kCompiledMaterialKinds = PATHBENCH_EXTRA_MATERIALS ? kAllMaterialKinds : kDiffuseOnly;

template <uint32_t Kinds> constexpr bool has_kind(MaterialKind k) { return (Kinds & kind_bit(k)) != 0; }

// Material `m` is of kind K, decided at compile time wherever `Kinds` leaves no choice
// (K absent: false; K the only kind: true, and m.kind is never read).
template <uint32_t Kinds, MaterialKind K> PB_HD bool is_kind(const Material& m) {
  if constexpr (!has_kind<Kinds>(K)) return false;
  else if constexpr (Kinds == kind_bit(K)) return true;
  else return m.kind == K;
}

// Kinds with a delta BSDF: no light sampling at their vertices, and an emitter found
// through them counts with MIS weight 1.
constexpr uint32_t kDeltaKinds = kind_bit(MaterialKind::Mirror) | kind_bit(MaterialKind::Dielectric);

template <uint32_t K> using MaterialKinds = std::integral_constant<uint32_t, K>;

// Calls fn(MaterialKinds<K>{}) with the smallest compiled instantiation K that covers
// `kinds` (a SceneFeatures::material_kinds mask) and returns what it returns.
template <class Fn> decltype(auto) with_features(uint32_t kinds, Fn&& fn) {
  if ((kinds & ~kCompiledMaterialKinds) != 0)
    throw std::logic_error("with_features: the scene uses material kinds this build does not have "
                           "(Scene::finalize should have refused it)");
  // (A diffuse-only build has one instantiation and one call: nothing for the compiler
  // to weigh differently from a build that never had other kinds.)
  if constexpr (kCompiledMaterialKinds != kDiffuseOnly)
    if ((kinds & ~kDiffuseOnly) != 0) return fn(MaterialKinds<kCompiledMaterialKinds>{});
  return fn(MaterialKinds<kDiffuseOnly>{});
}

}  // namespace pb
