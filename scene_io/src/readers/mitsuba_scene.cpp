// Mitsuba 3 XML scenes (a subset) through pugixml: shapes obj, ply, rectangle, cube
// and sphere (tessellated) placed by to_world, shapegroup/instance (expanded, with
// the instancing kept in Scene), the BSDFs of mitsuba_bsdf.cpp, area emitters, the
// perspective sensor, hdrfilm size, sampler sample_count and path max_depth (as the
// render's defaults). Everything else the file holds is named through Losses.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "pathbench/common/scene_warnings.h"
#include "pathbench/common/errors.h"
#include "readers/mitsuba.h"
#include "scenes/builder.h"

namespace pb::scene_io {

namespace {

namespace fs = std::filesystem;
using mitsuba::Document;
using mitsuba::Props;

class MitsubaReader {
 public:
  MitsubaReader(Document& doc, const FileReader& read) : doc_(doc), read_(read) {}

  Scene read(const pugi::xml_node& root) {
    Scene s;
    s.name = doc_.path;
    const std::string version = root.attribute("version").value();
    if (version.empty() || version[0] < '2')
      doc_.losses->report(doc_.path, fmt::format("scene version '{:.20}' (read as Mitsuba 3)", version));
    collect(root, 0);
    bool have_sensor = false;
    for (pugi::xml_node n : root.children()) {
      if (n.type() != pugi::node_element) continue;
      const std::string tag = n.name();
      if (tag == "default" || tag == "bsdf" || tag == "texture") continue;  // collected / by reference
      if (tag == "shape" && doc_.attr(n, "type") == "shapegroup") continue;  // placed by its instances
      if (tag == "shape") {
        read_shape(s, n, nullptr);
      } else if (tag == "sensor") {
        if (have_sensor) doc_.losses->report(doc_.path, "sensors after the first");
        else read_sensor(s, n);
        have_sensor = true;
      } else if (tag == "integrator") {
        read_integrator(s, n);
      } else if (tag == "emitter") {
        doc_.losses->report(doc_.path, fmt::format("emitter '{:.30}' (area emitters on shapes only)", doc_.attr(n, "type")));
      } else {
        doc_.losses->report(doc_.path, fmt::format("{} at the top of the scene", Document::describe(n)));
      }
    }
    if (spheres_)
      scene_warning(fmt::format("{}: {} <shape type=\"sphere\">{} tessellated into {} triangles each (pathbench traces "
                                "triangles only)", doc_.path, spheres_, spheres_ == 1 ? "" : "s", mitsuba::kSphereTriangles));
    if (!have_sensor) doc_.fail(root, "the scene has no <sensor type=\"perspective\"> (pathbench needs its camera)");
    if (s.triangles.empty()) doc_.fail(root, "the scene has no shapes with triangles");
    return s;
  }

 private:
  Document& doc_;
  const FileReader& read_;
  uint64_t mesh_bytes_ = 0;
  uint64_t spheres_ = 0;  // said once, after reading (not a line per sphere)
  std::map<std::string, uint32_t> prototype_of_group_;

  // <default>s and ids, anywhere (ids are referenced before or after their definition).
  void collect(const pugi::xml_node& n, int depth) {
    if (depth > 32) doc_.fail(n, "elements nested more than 32 deep");
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      if (std::string(c.name()) == "default" && depth == 0)
        doc_.defaults[c.attribute("name").value()] = c.attribute("value").value();
      if (std::string(c.name()) == "include") doc_.fail(c, "<include> is not supported (put the scene in one file)");
      if (c.attribute("id") && std::string(c.name()) != "ref" && !doc_.ids.emplace(c.attribute("id").value(), c).second)
        doc_.fail(c, "another element has the same id");
      collect(c, depth + 1);
    }
  }

  void read_integrator(Scene& s, const pugi::xml_node& n) {
    const std::string type = doc_.attr(n, "type");
    Props p(doc_, n);
    if (type != "path") {
      doc_.losses->report(doc_.path, fmt::format("integrator '{:.30}' (pathbench traces paths)", type));
      return;
    }
    // Mitsuba counts path segments: max_depth 3 = two bounces; -1 = unbounded.
    const int depth = p.integer("max_depth", -1);
    if (depth == 0 || depth < -1) doc_.fail(n, fmt::format("max_depth {} renders nothing (use -1 or at least 1)", depth));
    s.render_defaults.max_bounces = depth < 0 ? -1 : depth - 1;
    p.integer("rr_depth", 5);  // Russian roulette is pathbench's own (--rr)
    p.boolean("hide_emitters", false);
    p.finish();
  }

  void read_sensor(Scene& s, const pugi::xml_node& n) {
    if (doc_.attr(n, "type") != "perspective")
      doc_.fail(n, "only the perspective sensor is supported (pathbench's camera is a pinhole)");
    Props p(doc_, n);
    uint32_t width = 768, height = 576;  // Mitsuba's hdrfilm defaults
    for (pugi::xml_node film : p.children("film")) {
      Props f(doc_, film);
      if (doc_.attr(film, "type") != "hdrfilm") doc_.losses->report(doc_.path, Document::describe(film));
      const int w = f.integer("width", 768), h = f.integer("height", 576);
      if (w < 1 || h < 1 || w > 65536 || h > 65536) doc_.fail(film, fmt::format("a {}x{} film is out of range", w, h));
      width = uint32_t(w), height = uint32_t(h);
      f.string("pixel_format", "rgb"), f.string("component_format", "float16"), f.string("file_format", "openexr");
      bool box = false;
      for (pugi::xml_node r : f.children("rfilter")) box = doc_.attr(r, "type") == "box";
      if (!box)
        doc_.losses->report(doc_.path, "the film's reconstruction filter, unless it is 'box' (pathbench filters with a box)");
      f.finish({"rfilter"});
    }
    for (pugi::xml_node sampler : p.children("sampler")) {
      Props sp(doc_, sampler);
      const int spp = sp.integer("sample_count", 4);
      if (spp < 1) doc_.fail(sampler, "sample_count must be at least 1");
      s.render_defaults.spp = uint32_t(spp);
      sp.integer("seed", 0);
      sp.finish();
    }
    s.render_defaults.width = width, s.render_defaults.height = height;
    // The field of view along fov_axis (or from a 35 mm focal length), as a vertical one.
    double fov = 0;
    std::string axis = p.string("fov_axis", "x");
    if (p.has("fov")) {
      fov = p.number("fov", 0);
    } else {
      const std::string fl = p.string("focal_length", "50mm");
      const auto mm = mitsuba::numbers(doc_, n, fl.substr(0, fl.find("mm")));
      if (mm.size() != 1 || !(mm[0] > 0)) doc_.fail(n, fmt::format("focal_length '{:.20}' is not a length in mm", fl));
      fov = 2 * std::atan(18.0 / mm[0]) * 180 / 3.14159265358979323846;  // 36 mm across, along x
      axis = "x";
    }
    if (!(fov > 0 && fov < 180)) doc_.fail(n, fmt::format("fov {} is not between 0 and 180 degrees", fov));
    const double aspect = double(width) / height, t = std::tan(fov * 3.14159265358979323846 / 360);
    if (axis == "smaller") axis = width < height ? "x" : "y";
    if (axis == "larger") axis = width > height ? "x" : "y";
    double tan_y = t;
    if (axis == "x") tan_y = t / aspect;
    else if (axis == "diagonal") tan_y = t / std::sqrt(aspect * aspect + 1);
    else if (axis != "y") doc_.fail(n, fmt::format("unknown fov_axis '{:.20}' (x, y, diagonal, smaller, larger)", axis));
    p.number("near_clip", 0.01), p.number("far_clip", 1e4);
    const Affine m = p.transform("to_world");
    const Vec3f eye = m.point({0, 0, 0}), forward = m.vector({0, 0, 1}), up = m.vector({0, 1, 0});
    if (is_zero(forward) || is_zero(cross(forward, up))) doc_.fail(n, "the camera's to_world is degenerate");
    s.camera = Camera::look_at(eye, eye + normalize(forward), up, float(2 * std::atan(tan_y) * 180 / 3.14159265358979323846));
    p.finish({"film", "sampler"});
  }

  // The shape's material: its <bsdf> or <ref>, and its area emitter's radiance.
  uint32_t shape_material(Scene& s, Props& p, const std::string& name) {
    Material m{};
    m.albedo = {0.5f, 0.5f, 0.5f};  // Mitsuba's default: diffuse 0.5
    std::vector<pugi::xml_node> bsdfs = p.children("bsdf");
    for (pugi::xml_node r : p.children("ref")) bsdfs.push_back(r);
    if (bsdfs.size() > 1) doc_.fail(p.node(), "more than one BSDF");
    if (!bsdfs.empty()) m = mitsuba::read_bsdf(doc_, bsdfs[0]);
    for (pugi::xml_node e : p.children("emitter")) {
      if (doc_.attr(e, "type") != "area") {
        doc_.losses->report(doc_.path, fmt::format("emitter '{:.30}' on a shape (area only)", doc_.attr(e, "type")));
        continue;
      }
      Props ep(doc_, e);
      m.emission = ep.colour("radiance", {1, 1, 1});
      ep.finish();
    }
    return scenes::append_material(s, name, m);
  }

  // A shape; with `group`, its triangles join that prototype's mesh instead of the scene.
  void read_shape(Scene& s, const pugi::xml_node& n, MeshData* group, std::vector<uint32_t>* group_mats = nullptr) {
    const std::string type = doc_.attr(n, "type");
    Props p(doc_, n);
    if (type == "instance") {
      if (group) doc_.fail(n, "an instance inside a shapegroup is not supported");
      const auto refs = p.children("ref");
      if (refs.size() != 1) doc_.fail(n, "needs one <ref id=\"...\"/> naming a shapegroup");
      add_instance(s, prototype(s, doc_.attr(refs[0], "id"), refs[0]), p.transform("to_world"));
      p.finish({"ref"});
      return;
    }
    MeshData mesh;
    Affine to_world = p.transform("to_world");
    if (type == "obj" || type == "ply") {
      const std::string file = p.string("filename", "");
      if (file.empty()) doc_.fail(n, "needs <string name=\"filename\" value=\"...\"/>");
      const std::string path = (fs::path(doc_.path).parent_path() / file).string();
      if (!read_.exists(path)) doc_.fail(n, fmt::format("'{:.80}': no such file (looked for {:.200})", file, path));
      mesh = read_mesh_file(path, false, read_, *doc_.losses, mesh_bytes_);
      p.boolean("face_normals", false);  // pathbench shades with face normals either way
    } else if (type == "rectangle") {
      mesh = mitsuba::rectangle_mesh();
    } else if (type == "cube") {
      mesh = mitsuba::cube_mesh();
    } else if (type == "sphere") {
      const float radius = float(p.number("radius", 1));
      if (!(radius > 0)) doc_.fail(n, "the radius must be above 0");
      mesh = mitsuba::sphere_mesh(p.point("center", {0, 0, 0}), radius);
      ++spheres_;
    } else {
      doc_.losses->report(doc_.path, fmt::format("shape '{:.30}' (obj, ply, rectangle, cube, sphere and instance only)", type));
      return;
    }
    const bool flip = p.boolean("flip_normals", false);
    if (!(std::fabs(to_world.determinant()) > 0)) doc_.fail(n, "to_world is singular (it flattens the shape)");
    const uint32_t mat = shape_material(s, p, n.attribute("id") ? n.attribute("id").value() : fmt::format("{}{}", type, s.materials.size()));
    p.finish({"bsdf", "ref", "emitter"});
    if (!group) {
      append_mesh(s, mesh, to_world, {mat}, flip);
      return;
    }
    const uint32_t base = uint32_t(group->positions.size());
    for (const Vec3f& v : mesh.positions) group->positions.push_back(to_world.point(v));
    for (const Triangle& t : mesh.triangles) {
      group->triangles.push_back(flip ? Triangle{{base + t.v[0], base + t.v[2], base + t.v[1]}}
                                      : Triangle{{base + t.v[0], base + t.v[1], base + t.v[2]}});
      group_mats->push_back(mat);
    }
  }

  uint32_t prototype(Scene& s, const std::string& id, const pugi::xml_node& at) {
    if (const auto it = prototype_of_group_.find(id); it != prototype_of_group_.end()) return it->second;
    const auto def = doc_.ids.find(id);
    if (def == doc_.ids.end() || std::string(def->second.name()) != "shape" || doc_.attr(def->second, "type") != "shapegroup")
      doc_.fail(at, fmt::format("no <shape type=\"shapegroup\" id=\"{:.60}\">", id));
    MeshData mesh;
    std::vector<uint32_t> mats;
    for (pugi::xml_node c : def->second.children()) {
      if (c.type() != pugi::node_element) continue;
      if (std::string(c.name()) != "shape" || doc_.attr(c, "type") == "shapegroup" || doc_.attr(c, "type") == "instance")
        doc_.fail(c, "a shapegroup holds shapes only (no groups or instances)");
      read_shape(s, c, &mesh, &mats);
    }
    if (mesh.triangles.empty()) doc_.fail(def->second, "the shapegroup has no triangles");
    return prototype_of_group_[id] = add_prototype(s, id, mesh, mats);
  }
};

}  // namespace

Scene parse_scene_mitsuba(const std::string& path, const std::string& text, const FileReader& read, const Losses& losses) {
  pugi::xml_document xml;
  const pugi::xml_parse_result r = xml.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!r) {
    // The line of the byte offset pugixml reports.
    const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + std::min<ptrdiff_t>(r.offset, ptrdiff_t(text.size())), '\n'));
    throw InputError(fmt::format("{}:{}: malformed XML: {}", path, line, r.description()));
  }
  const pugi::xml_node root = xml.document_element();
  if (std::string(root.name()) != "scene")
    throw InputError(fmt::format("{}: not a Mitsuba scene (the root element is <{:.30}>, not <scene>)", path, root.name()));
  Document doc{path, &losses, {}, {}};
  MitsubaReader reader(doc, read);
  return reader.read(root);
}

}  // namespace pb::scene_io
