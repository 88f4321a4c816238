#pragma once
// Private to the Mitsuba 3 XML reader (mitsuba_scene.cpp, mitsuba_bsdf.cpp,
// mitsuba_shapes.cpp): a plugin element's properties, read by name and type, so that
// whatever a reader did not ask for can be named as not modelled.
#include <pugixml.hpp>

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "pathbench/common/affine.h"
#include "readers/readers.h"

namespace pb::scene_io::mitsuba {

// The document with its <default> values and ids, and the file's name for messages.
struct Document {
  std::string path;
  const Losses* losses;
  std::map<std::string, std::string> defaults;     // <default name value>: "$name" in attributes
  std::map<std::string, pugi::xml_node> ids;        // id -> element (bsdf, shapegroup, ...)
  // Bytes of <default> values substituted so far (attr), at most kMaxExpandedBytes.
  static constexpr uint64_t kMaxExpandedBytes = uint64_t(64) << 20;
  mutable uint64_t expanded = 0;

  [[noreturn]] void fail(const pugi::xml_node& at, const std::string& what) const;
  // An attribute with "$name" replaced by its <default>; "" when absent.
  std::string attr(const pugi::xml_node& n, const char* name) const;
  // "<shape type="sphere">" for messages.
  static std::string describe(const pugi::xml_node& n);
};

// The property elements (<float name=...>, <rgb>, <transform>, ...) of one plugin.
class Props {
 public:
  Props(const Document& doc, pugi::xml_node plugin);
  bool has(const std::string& name) const { return by_name_.count(name) != 0; }
  double number(const std::string& name, double fallback);
  int integer(const std::string& name, int fallback);
  std::string string(const std::string& name, const std::string& fallback);
  bool boolean(const std::string& name, bool fallback);
  Vec3f point(const std::string& name, Vec3f fallback);
  // rgb / spectrum (uniform) / float colour; a texture or a spectrum by wavelength is
  // reported lost and gives `fallback`.
  Vec3f colour(const std::string& name, Vec3f fallback);
  Affine transform(const std::string& name);  // identity when absent
  // Nested plugin elements (bsdf, emitter, shape, ...) and <ref>s, in order.
  std::vector<pugi::xml_node> children(const char* tag) const;
  // Names every property not read, and every nested plugin element not in `handled`.
  void finish(const std::set<std::string>& handled = {}) const;
  const Document& doc() const { return doc_; }
  pugi::xml_node node() const { return plugin_; }

 private:
  const Document& doc_;
  pugi::xml_node plugin_;
  std::map<std::string, pugi::xml_node> by_name_;
  std::set<std::string> used_;
  pugi::xml_node take(const std::string& name);
};

// Numbers separated by commas and/or blanks.
std::vector<double> numbers(const Document& doc, const pugi::xml_node& at, std::string_view text);

// <bsdf> (or the element a <ref> names) -> pathbench material, with losses reported.
Material read_bsdf(const Document& doc, pugi::xml_node bsdf, int depth = 0);

// Mitsuba's built-in shapes as meshes in their own coordinates.
MeshData rectangle_mesh();                       // [-1, 1]^2 at z = 0, facing +z
MeshData cube_mesh();                            // [-1, 1]^3, facing out
MeshData sphere_mesh(Vec3f centre, float radius);  // tessellated (kSphereTriangles), facing out
inline constexpr uint32_t kSphereTriangles = 4096;

}  // namespace pb::scene_io::mitsuba
