// glTF 2.0 scenes (.gltf with its buffers, or .glb) through tinygltf: triangle meshes
// placed by the node hierarchy (matrix or TRS), base-colour factor as diffuse albedo
// (a metallic material as a rough conductor), emissive factor as an area emitter, the
// first perspective camera. tinygltf parses; every accessor is checked here against
// its buffer before a byte is read. Textures, normals, lights, animation and other
// material features are named through Losses.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "readers/gltf_config.h"
#include "readers/gltf_input.h"
#include "readers/readers.h"
#include "scenes/builder.h"

namespace pb::scene_io {

namespace {

namespace fs = std::filesystem;

struct FsContext {
  const FileReader* read;
  uint64_t used = 0;
  std::string error;  // an InputError from the reader, rethrown after tinygltf returns
};

bool fs_exists(const std::string& path, void* user) { return static_cast<FsContext*>(user)->read->exists(path); }
std::string fs_expand(const std::string& path, void*) { return path; }
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto* ctx = static_cast<FsContext*>(user);
  try {
    const std::string text = ctx->read->read(path, "glTF buffer file", limits::kMaxMeshBytes);
    ctx->used += text.size();
    if (ctx->used > limits::kMaxMeshBytes)
      throw InputError(fmt::format("{}: the buffer files of one glTF scene are limited to {} in all", path,
                                   limits::kMaxMeshBytes));
    out->assign(text.begin(), text.end());
    return true;
  } catch (const InputError& e) {
    ctx->error = e.what();
    if (err) *err += e.what();
    return false;
  }
}
bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "pathbench writes no glTF files";
  return false;
}
// Images are never decoded: textures are reported as not modelled.
bool no_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

class GltfReader {
 public:
  GltfReader(const std::string& path, const tinygltf::Model& model, const Losses& losses)
      : path_(path), model_(model), losses_(losses) {}

  Scene read() {
    Scene s;
    s.name = path_;
    report_model_losses();
    prototype_of_mesh_.assign(model_.meshes.size(), -1);
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (size_t(scene) >= model_.scenes.size()) fail(fmt::format("scene {} does not exist", scene));
      roots = model_.scenes[size_t(scene)].nodes;
      if (model_.scenes.size() > 1) losses_.report(path_, fmt::format("{} scenes beyond the default one", model_.scenes.size() - 1));
    } else {
      for (size_t i = 0; i < model_.nodes.size(); ++i) roots.push_back(int(i));  // no scene: every node
    }
    count_placements(roots);
    for (int root : roots) visit(s, root, Affine());
    if (s.triangles.empty()) fail("the scene has no triangle meshes");
    frame_bare_mesh(s, path_, !have_camera_, "emissiveFactor");
    if (have_camera_) s.camera = camera_;
    return s;
  }

 private:
  const std::string& path_;
  const tinygltf::Model& model_;
  const Losses& losses_;
  std::vector<int> prototype_of_mesh_;  // glTF mesh -> Scene prototype, once placed
  std::vector<uint32_t> scene_material_;  // glTF material -> Scene material (+1 slot: the default)
  bool have_camera_ = false;
  Camera camera_{};

  [[noreturn]] void fail(const std::string& what) const { throw InputError(fmt::format("{}: glTF: {}", path_, what)); }

  void report_model_losses() const {
    if (!model_.animations.empty()) losses_.report(path_, fmt::format("{} animations", model_.animations.size()));
    if (!model_.skins.empty()) losses_.report(path_, fmt::format("{} skins", model_.skins.size()));
    if (!model_.lights.empty()) losses_.report(path_, fmt::format("{} KHR_lights_punctual lights", model_.lights.size()));
    for (const std::string& e : model_.extensionsUsed)
      if (e != "KHR_materials_emissive_strength" && e != "KHR_lights_punctual")
        losses_.report(path_, "extension " + e.substr(0, 60));
  }

  Affine local(const tinygltf::Node& n) const {
    if (n.matrix.size() == 16) {
      Affine a;  // glTF stores column-major
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a.m[r][c] = n.matrix[size_t(c * 4 + r)];
      if (n.matrix[3] != 0 || n.matrix[7] != 0 || n.matrix[11] != 0 || n.matrix[15] != 1)
        fail(fmt::format("node '{:.60}': the matrix is not affine (its last row must be 0 0 0 1)", n.name));
      return a;
    }
    if (!n.matrix.empty()) fail(fmt::format("node '{:.60}': a matrix needs 16 numbers", n.name));
    Affine a;
    if (n.scale.size() == 3) a = Affine::scale(n.scale[0], n.scale[1], n.scale[2]);
    if (n.rotation.size() == 4) {
      const double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
      const double len = std::sqrt(x * x + y * y + z * z + w * w);
      if (!(len > 0) || !std::isfinite(len)) fail(fmt::format("node '{:.60}': the rotation quaternion is zero or not finite", n.name));
      a = Affine::quaternion(x / len, y / len, z / len, w / len) * a;
    }
    if (n.translation.size() == 3) a = Affine::translate(n.translation[0], n.translation[1], n.translation[2]) * a;
    return a;
  }

  static uint64_t add_sat(uint64_t a, uint64_t b) { return a + b < a ? UINT64_MAX : a + b; }
  static uint64_t mul_sat(uint64_t a, uint64_t b) {
    uint64_t r = 0;
    return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
  }

  // Triangles and vertices one placement of a mesh adds, from its accessors' counts
  // (make_prototype reads and checks the accessors themselves later).
  std::pair<uint64_t, uint64_t> mesh_size(const tinygltf::Mesh& m) const {
    auto count = [&](int a) -> uint64_t { return a >= 0 && size_t(a) < model_.accessors.size() ? model_.accessors[size_t(a)].count : 0; };
    uint64_t triangles = 0, vertices = 0;
    for (const tinygltf::Primitive& p : m.primitives) {
      if (p.mode < 4 || p.mode > 6) continue;
      const auto pos = p.attributes.find("POSITION");
      const uint64_t nv = pos == p.attributes.end() ? 0 : count(pos->second);
      const uint64_t ni = p.indices >= 0 ? count(p.indices) : nv;
      triangles = add_sat(triangles, p.mode == TINYGLTF_MODE_TRIANGLES ? ni / 3 : ni < 3 ? 0 : ni - 2);
      vertices = add_sat(vertices, nv);
    }
    return {triangles, vertices};
  }

  // How often each node is placed, before any geometry is read: once per path from a
  // root to it. glTF's node graph is a set of trees, but tinygltf does not check that,
  // and 31 nodes each naming the next twice as a child place the last 2^30 times. So
  // the paths are counted (in topological order, saturating; a cycle is refused), and
  // the placements, triangles and vertices they make are checked against the limits.
  void count_placements(const std::vector<int>& roots) const {
    const size_t n = model_.nodes.size();
    auto check = [&](int i) {
      if (i < 0 || size_t(i) >= n) fail(fmt::format("node {} does not exist", i));
      return size_t(i);
    };
    // The nodes reachable from the roots, and their parents among them (per use).
    std::vector<uint32_t> parents(n, 0);
    std::vector<char> reached(n, 0);
    std::vector<size_t> stack;
    size_t reachable = 0;
    for (int r : roots)
      if (const size_t i = check(r); !reached[i]) reached[i] = 1, ++reachable, stack.push_back(i);
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      for (int child : model_.nodes[i].children) {
        const size_t c = check(child);
        ++parents[c];
        if (!reached[c]) reached[c] = 1, ++reachable, stack.push_back(c);
      }
    }
    const uint64_t cap = limits::kMaxPlacements + 1;  // counts saturate here
    std::vector<uint64_t> count(n, 0);
    std::vector<int> depth(n, 0);
    for (int r : roots) count[size_t(r)] = std::min(cap, count[size_t(r)] + 1);
    std::vector<size_t> ready;
    for (size_t i = 0; i < n; ++i)
      if (reached[i] && parents[i] == 0) ready.push_back(i);
    uint64_t placements = 0, triangles = 0, vertices = 0;
    size_t done = 0;
    while (!ready.empty()) {
      const size_t i = ready.back();
      ready.pop_back();
      ++done;
      const tinygltf::Node& node = model_.nodes[i];
      placements = std::min(cap, placements + count[i]);
      if (placements > limits::kMaxPlacements)
        fail(fmt::format("the node hierarchy places nodes more than {} times (the supported maximum; a node that is "
                         "the child of several nodes is placed once per path to it)", limits::kMaxPlacements));
      if (node.mesh >= 0) {
        if (size_t(node.mesh) >= model_.meshes.size())
          fail(fmt::format("node '{:.60}': mesh {} does not exist", node.name, node.mesh));
        const auto [t, v] = mesh_size(model_.meshes[size_t(node.mesh)]);
        triangles = add_sat(triangles, mul_sat(t, count[i]));
        vertices = add_sat(vertices, mul_sat(v, count[i]));
        if (triangles > limits::kMaxTriangles)
          fail(fmt::format("the placed meshes have more than {} triangles in all (the supported maximum; mesh {} is "
                           "placed {} time{})", limits::kMaxTriangles, node.mesh, count[i], count[i] == 1 ? "" : "s"));
        if (vertices > limits::kMaxVertices)
          fail(fmt::format("the placed meshes have more than {} vertices in all (the supported maximum; mesh {} is "
                           "placed {} time{})", limits::kMaxVertices, node.mesh, count[i], count[i] == 1 ? "" : "s"));
      }
      for (int child : node.children) {
        const size_t c = size_t(child);
        count[c] = std::min(cap, count[c] + count[i]);
        if ((depth[c] = std::max(depth[c], depth[i] + 1)) > kMaxDepth)
          fail(fmt::format("the node hierarchy is more than {} levels deep (the supported maximum)", kMaxDepth));
        if (--parents[c] == 0) ready.push_back(c);
      }
    }
    if (done < reachable) {
      size_t on_cycle = 0;
      while (!(reached[on_cycle] && parents[on_cycle] > 0)) ++on_cycle;
      fail(fmt::format("the node hierarchy has a cycle (node {} is on it or below it)", on_cycle));
    }
  }

  // visit() recurses per level: count_placements has bounded the depth.
  static constexpr int kMaxDepth = 64;

  void visit(Scene& s, int index, const Affine& parent) {
    const tinygltf::Node& n = model_.nodes[size_t(index)];
    const Affine to_world = parent * local(n);
    if (!to_world.finite()) fail(fmt::format("node '{:.60}': the transform is not finite", n.name));
    if (n.camera >= 0) place_camera(n, to_world);
    if (n.mesh >= 0) {
      if (prototype_of_mesh_[size_t(n.mesh)] < 0) prototype_of_mesh_[size_t(n.mesh)] = int(make_prototype(s, size_t(n.mesh)));
      if (!(std::fabs(to_world.determinant()) > 0)) fail(fmt::format("node '{:.60}': the transform is singular", n.name));
      // A mirroring transform reverses the winding, as the glTF specification says, so
      // that front faces (and one-sided emitters) stay in front.
      add_instance(s, uint32_t(prototype_of_mesh_[size_t(n.mesh)]), to_world, to_world.determinant() < 0);
    }
    for (int child : n.children) visit(s, child, to_world);
  }

  void place_camera(const tinygltf::Node& n, const Affine& to_world) {
    if (size_t(n.camera) >= model_.cameras.size()) fail(fmt::format("node '{:.60}': camera {} does not exist", n.name, n.camera));
    const tinygltf::Camera& c = model_.cameras[size_t(n.camera)];
    if (have_camera_) {
      losses_.report(path_, "cameras after the first");
      return;
    }
    if (c.type != "perspective") {
      losses_.report(path_, fmt::format("camera '{:.60}' of type '{:.20}' (perspective only)", c.name, c.type));
      return;
    }
    const double fov = c.perspective.yfov * 180.0 / 3.14159265358979323846;
    if (!(fov > 0 && fov < 180)) fail(fmt::format("camera '{:.60}': yfov {} is not between 0 and pi", c.name, c.perspective.yfov));
    const Vec3f eye = to_world.point({0, 0, 0});
    const Vec3f forward = to_world.vector({0, 0, -1}), up = to_world.vector({0, 1, 0});
    if (!is_finite(eye) || is_zero(forward) || is_zero(cross(forward, up)))
      fail(fmt::format("camera '{:.60}': its node's transform is degenerate", c.name));
    camera_ = Camera::look_at(eye, eye + normalize(forward), up, float(fov));
    have_camera_ = true;
  }

  uint32_t material(Scene& s, int index) {
    if (scene_material_.empty()) scene_material_.assign(model_.materials.size() + 1, ~0u);
    if (index < -1 || index >= int(model_.materials.size())) fail(fmt::format("material {} does not exist", index));
    uint32_t& slot = scene_material_[size_t(index + 1)];
    if (slot != ~0u) return slot;
    if (index < 0) return slot = scenes::add_material(s, "default", {0.5f, 0.5f, 0.5f});
    const tinygltf::Material& m = model_.materials[size_t(index)];
    const std::string name = m.name.empty() ? fmt::format("material{}", index) : m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    auto lose = [&](const std::string& what) { losses_.report(path_, fmt::format("material '{:.60}': {}", name, what)); };
    if (pbr.baseColorTexture.index >= 0) lose("baseColorTexture");
    if (pbr.metallicRoughnessTexture.index >= 0) lose("metallicRoughnessTexture");
    if (m.normalTexture.index >= 0) lose("normalTexture (normal map)");
    if (m.occlusionTexture.index >= 0) lose("occlusionTexture");
    if (m.emissiveTexture.index >= 0) lose("emissiveTexture");
    if (m.alphaMode != "OPAQUE") lose("alphaMode " + m.alphaMode.substr(0, 10));
    double strength = 1;
    for (const auto& [ext, value] : m.extensions) {
      if (ext == "KHR_materials_emissive_strength" && value.Has("emissiveStrength"))
        strength = value.Get("emissiveStrength").GetNumberAsDouble();
      else
        lose("extension " + ext.substr(0, 60));
    }
    const auto& bc = pbr.baseColorFactor;
    if (bc.size() != 4) fail(fmt::format("material '{:.60}': baseColorFactor needs 4 numbers", name));
    if (bc[3] < 1) lose("base-colour alpha (transparency)");
    Material mat{};
    mat.albedo = {float(bc[0]), float(bc[1]), float(bc[2])};
    if (m.emissiveFactor.size() == 3)
      mat.emission = Vec3f{float(m.emissiveFactor[0]), float(m.emissiveFactor[1]), float(m.emissiveFactor[2])} * float(strength);
    // A metal (metallicFactor >= 0.5) is a GGX conductor of roughness alpha = r^2 (the
    // glTF convention), a mirror below pathbench's smallest alpha; anything else is
    // Lambertian, without the specular layer of glTF's dielectric model.
    if (pbr.metallicFactor > 0 && pbr.metallicFactor < 1) lose(fmt::format("metallicFactor {} (metal or not only)", pbr.metallicFactor));
    if (pbr.metallicFactor >= 0.5) {
      const double alpha = pbr.roughnessFactor * pbr.roughnessFactor;
      mat.kind = alpha < Material::kMinAlpha ? MaterialKind::Mirror : MaterialKind::RoughConductor;
      mat.alpha = float(std::max(alpha, double(Material::kMinAlpha)));
    } else {
      losses_.report(path_, "the specular layer of non-metallic materials (rendered as Lambertian)");
    }
    return slot = scenes::append_material(s, name, mat);
  }

  // The accessor's elements as doubles: `components` each, checked against its buffer.
  std::vector<double> read_accessor(int index, int components, bool integer, const char* what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size()) fail(fmt::format("{}: accessor {} does not exist", what, index));
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    if (a.sparse.isSparse) fail(fmt::format("{}: sparse accessors are not supported", what));
    const int type_components = a.type == TINYGLTF_TYPE_SCALAR ? 1 : a.type == TINYGLTF_TYPE_VEC3 ? 3 : 0;
    if (type_components != components) fail(fmt::format("{}: expected {} accessor", what, components == 1 ? "a SCALAR" : "a VEC3"));
    size_t size = 0;
    switch (a.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: size = integer ? 0 : 4; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = integer ? 1 : 0; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = integer ? 2 : 0; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = integer ? 4 : 0; break;
      default: break;
    }
    if (size == 0)
      fail(fmt::format("{}: component type {} is not supported here ({})", what, a.componentType,
                       integer ? "unsigned byte, short or int" : "float"));
    if (a.count > 3 * limits::kMaxTriangles) fail(fmt::format("{}: {} elements: more than the supported maximum", what, a.count));
    std::vector<double> out;
    if (a.count == 0) return out;
    if (a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size())
      fail(fmt::format("{}: accessor {} has no valid bufferView", what, index));
    const tinygltf::BufferView& v = model_.bufferViews[size_t(a.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= model_.buffers.size()) fail(fmt::format("{}: buffer {} does not exist", what, v.buffer));
    const std::vector<unsigned char>& data = model_.buffers[size_t(v.buffer)].data;
    const uint64_t element = size * uint64_t(components);
    const uint64_t stride = v.byteStride ? v.byteStride : element;
    if (stride < element) fail(fmt::format("{}: byteStride {} is below the element size {}", what, stride, element));
    // The bytes read are [byteOffset, byteOffset + stride * (count - 1) + element) of the
    // view, and the view [byteOffset, byteOffset + byteLength) of the buffer. Every sum
    // and product is checked: offsets near 2^64 must not wrap past the check to a read
    // before or after the buffer.
    uint64_t end = 0;
    if (__builtin_mul_overflow(stride, uint64_t(a.count - 1), &end) || __builtin_add_overflow(end, element, &end) ||
        __builtin_add_overflow(end, uint64_t(a.byteOffset), &end) || v.byteOffset > data.size() ||
        v.byteLength > data.size() - v.byteOffset || end > v.byteLength)
      fail(fmt::format("{}: accessor {} (byteOffset {}, {} elements of stride {}) reaches outside its bufferView {} "
                       "(byteOffset {}, byteLength {}) or buffer {} ({} bytes)",
                       what, index, a.byteOffset, a.count, stride, a.bufferView, v.byteOffset, v.byteLength, v.buffer,
                       data.size()));
    const unsigned char* base = data.data() + v.byteOffset + a.byteOffset;
    out.reserve(a.count * size_t(components));
    for (size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < components; ++c) {
        const unsigned char* p = base + i * stride + size_t(c) * size;
        switch (size) {
          case 1: out.push_back(p[0]); break;
          case 2: { uint16_t x; std::memcpy(&x, p, 2); out.push_back(x); break; }
          case 4:
            if (integer) { uint32_t x; std::memcpy(&x, p, 4); out.push_back(x); }
            else { float x; std::memcpy(&x, p, 4); out.push_back(x); }
            break;
        }
      }
    return out;
  }

  uint32_t make_prototype(Scene& s, size_t mesh_index) {
    const tinygltf::Mesh& m = model_.meshes[mesh_index];
    MeshData mesh;
    std::vector<uint32_t> mats;
    for (size_t pi = 0; pi < m.primitives.size(); ++pi) {
      const tinygltf::Primitive& p = m.primitives[pi];
      const std::string what = fmt::format("mesh '{:.60}' primitive {}", m.name, pi);
      if (p.mode < 4 || p.mode > 6) {
        losses_.report(path_, fmt::format("{}: points or lines (mode {})", what, p.mode));
        continue;
      }
      if (!p.targets.empty()) losses_.report(path_, "morph targets");
      for (const auto& [attr, unused] : p.attributes)
        if (attr != "POSITION") losses_.report(path_, "vertex attribute " + attr.substr(0, 40));
      const auto pos = p.attributes.find("POSITION");
      if (pos == p.attributes.end()) fail(what + ": no POSITION attribute");
      const std::vector<double> xyz = read_accessor(pos->second, 3, false, what.c_str());
      const uint32_t base = uint32_t(mesh.positions.size()), nv = uint32_t(xyz.size() / 3);
      for (size_t i = 0; i + 2 < xyz.size(); i += 3) mesh.positions.push_back({float(xyz[i]), float(xyz[i + 1]), float(xyz[i + 2])});
      std::vector<double> idx;
      if (p.indices >= 0) idx = read_accessor(p.indices, 1, true, what.c_str());
      else for (uint32_t i = 0; i < nv; ++i) idx.push_back(i);
      for (double i : idx)
        if (i >= nv) fail(fmt::format("{}: index {} is out of range ({} vertices)", what, i, nv));
      // The triangles this adds, refused before they are made (count_placements has
      // checked the scene's total from the same accessors' counts).
      const uint64_t adds = p.mode == TINYGLTF_MODE_TRIANGLES ? idx.size() / 3 : idx.size() < 3 ? 0 : idx.size() - 2;
      if (mesh.triangles.size() + adds > limits::kMaxTriangles)
        fail(fmt::format("more than {} triangles: the supported maximum per scene", limits::kMaxTriangles));
      const uint32_t mat = material(s, p.material);
      auto tri = [&](size_t a, size_t b, size_t c) {
        mesh.triangles.push_back({{base + uint32_t(idx[a]), base + uint32_t(idx[b]), base + uint32_t(idx[c])}});
        mats.push_back(mat);
      };
      if (p.mode == TINYGLTF_MODE_TRIANGLES) {
        if (idx.size() % 3) fail(fmt::format("{}: {} indices is not a whole number of triangles", what, idx.size()));
        for (size_t i = 0; i + 2 < idx.size(); i += 3) tri(i, i + 1, i + 2);
      } else if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (size_t i = 0; i + 2 < idx.size(); ++i) i % 2 ? tri(i + 1, i, i + 2) : tri(i, i + 1, i + 2);
      } else {
        for (size_t i = 1; i + 1 < idx.size(); ++i) tri(0, i, i + 1);
      }
    }
    return add_prototype(s, m.name.empty() ? fmt::format("mesh{}", mesh_index) : m.name, mesh, mats);
  }
};

}  // namespace

Scene parse_scene_gltf(const std::string& path, const std::string& text, bool binary, const FileReader& read,
                       const Losses& losses) {
  tinygltf::TinyGLTF loader;
  FsContext ctx{&read};
  loader.SetFsCallbacks({&fs_exists, &fs_expand, &fs_read, &fs_write, &ctx});
  loader.SetImageLoader(&no_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string dir = fs::path(path).parent_path().string();
  if (text.size() > limits::kMaxMeshBytes) throw InputError(fmt::format("{}: glTF files are limited to {}", path, limits::kMaxMeshBytes));
  check_gltf_json_shape(path, gltf_json_text(path, text, binary));
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(text.data()),
                                              unsigned(text.size()), dir)
                : loader.LoadASCIIFromString(&model, &err, &warn, text.data(), unsigned(text.size()), dir);
  } catch (const std::logic_error& e) {
    // tinygltf 2.7 indexes with at() where it did not check a size (a GLB buffer of
    // byteLength 0: data.at(0)); nothing was read out of bounds.
    throw InputError(fmt::format("{}: malformed glTF: {:.200}", path, e.what()));
  }
  if (!ctx.error.empty()) throw InputError(ctx.error);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == '.')) err.pop_back();
    std::replace(err.begin(), err.end(), '\n', ' ');
    throw InputError(fmt::format("{}: malformed glTF: {:.300}", path, err.empty() ? "tinygltf failed" : err));
  }
  return GltfReader(path, model, losses).read();
}

}  // namespace pb::scene_io
