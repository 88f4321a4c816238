#pragma once
// Private to pathbench_scene_io (and the fuzz targets and reader tests): the scene-file readers working
// on text already read, with every further file (an OBJ's MTL libraries, a JSON
// scene's meshes) read through a FileReader. Production reads files with
// read_input_file; the fuzzers hand in fixed or fuzzed text instead of files.
#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "pathbench/common/affine.h"
#include "pathbench/common/scene.h"

namespace pb::scene_io {

struct FileReader {
  // Returns the contents of `path`; throws InputError (missing, special, over max_bytes).
  std::function<std::string(const std::string& path, const char* what, uint64_t max_bytes)> read;
  // False only when `path` certainly does not exist (for "not found" messages with
  // the line or field that names it).
  std::function<bool(const std::string& path)> exists;
};
// read_input_file and std::filesystem::exists.
FileReader disk_reader();

// What a file holds that pathbench does not model (a texture, a normal map, another
// BSDF or light): each named once in a warning on stderr, or, strict, an InputError.
class Losses {
 public:
  explicit Losses(bool strict = false) : strict_(strict) {}
  // "warning: PATH: WHAT (not modelled; ignored)".
  void report(const std::string& path, const std::string& what) const;
  bool strict() const { return strict_; }

 private:
  bool strict_;
  mutable std::set<std::string> said_;
};

// The one entry point (scene_file.cpp): `text` is the file at `path` (for messages and to
// resolve relative names); the reader is picked by the path's extension (.json, .obj, .ply,
// .off, .gltf, .glb, .xml; InputError for any other) and the scene it returns is finalized
// (Scene::finalize), here and nowhere else.
Scene parse_scene(const std::string& path, const std::string& text, const FileReader& read,
                  const Losses& losses = Losses());

// The readers, one per format, as parse_scene calls them: the scene they return is not
// finalized yet.
Scene parse_scene_json(const std::string& path, const std::string& text, const FileReader& read,
                       const Losses& losses = Losses());
Scene parse_scene_obj(const std::string& path, const std::string& text, const FileReader& read,
                      const Losses& losses = Losses());
// .gltf (JSON; its buffers read through `read`) or .glb (binary), by `binary`.
Scene parse_scene_gltf(const std::string& path, const std::string& text, bool binary, const FileReader& read,
                       const Losses& losses = Losses());
Scene parse_scene_mitsuba(const std::string& path, const std::string& text, const FileReader& read,
                          const Losses& losses = Losses());

// Geometry of one mesh file, with the materials it names (OBJ's MTL; empty for PLY).
struct MeshData {
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<int> material_ids;      // per triangle: index into `materials`, or -1 (none)
  std::vector<Material> materials;
  std::vector<std::string> material_names;
};
MeshData read_ply(const std::string& path, const std::string& text, const Losses& losses);
MeshData read_off(const std::string& path, const std::string& text, const Losses& losses);
// Loop subdivision (Loop 1987), `levels` times: every triangle becomes four, new edge
// points and moved old ones by Loop's weights (boundary and non-manifold edges as
// creases: the boundary rules). Material ids follow the parent triangle.
MeshData loop_subdivide(const MeshData& mesh, int levels);
// An OBJ; with_materials: its MTL libraries through `read`, else none.
MeshData read_obj_mesh(const std::string& path, const std::string& text, bool with_materials, const FileReader& read,
                       const Losses& losses);
// A mesh file named by a scene (JSON "file", Mitsuba "filename"): .obj, .ply or .off, read
// through `read`; `budget` is what the scene's mesh files have used so far (one limit
// for all of them).
MeshData read_mesh_file(const std::string& path, bool with_materials, const FileReader& read, const Losses& losses,
                        uint64_t& budget);

// Triangles of `s` that its instances expanded into (they count against
// limits::kMaxInstancedTriangles, the others against kMaxTriangles).
uint64_t instanced_triangles(const Scene& s);
// Appends `mesh` moved by `to_world` (winding kept; flipped too when flip_winding) and
// returns the index of its first triangle. `materials`: triangle i's scene material
// (one entry: every triangle's). Throws InputError past the scene's triangle limit.
uint32_t append_mesh(Scene& s, const MeshData& mesh, const Affine& to_world, const std::vector<uint32_t>& materials,
                     bool flip_winding = false);
// The same, kept as instancing too: `prototype` is Scene::prototypes' index (add_prototype).
uint32_t add_prototype(Scene& s, std::string name, const MeshData& mesh, const std::vector<uint32_t>& materials);
void add_instance(Scene& s, uint32_t prototype, const Affine& to_world, bool flip_winding = false);

// A scene made of a bare mesh file (OBJ, PLY, glTF without a camera): a camera framing
// its bounds and, when nothing emits, a default area light (with a note on stderr).
void frame_bare_mesh(Scene& s, const std::string& path, bool set_camera, const char* emitter_hint);
// A scene of one mesh without materials (PLY, OFF): grey (0.5) diffuse, framed as above.
Scene bare_mesh_scene(const std::string& path, const MeshData& mesh, const char* emitter_hint);

}  // namespace pb::scene_io
