#include "pathbench/scene_io/mitsuba_export.h"

#include <fmt/core.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "pathbench/output/output_file.h"

namespace pb {

namespace {

std::string rgb(Vec3f c) { return fmt::format("{:.9g}, {:.9g}, {:.9g}", c.x, c.y, c.z); }

// The Mitsuba plugin pathbench's BSDF of each kind is defined as: the one definition of this
// mapping (the XML reader, readers/mitsuba_bsdf.cpp, maps these plugins back).
std::string bsdf(const Material& m) {
  const std::string c = rgb(m.albedo);
  switch (m.kind) {
    case MaterialKind::Mirror:
      return fmt::format(R"(<bsdf type="twosided"><bsdf type="conductor"><string name="material" value="none"/>)"
                         R"(<rgb name="specular_reflectance" value="{}"/></bsdf></bsdf>)", c);
    case MaterialKind::Dielectric:
      return fmt::format(R"(<bsdf type="dielectric"><float name="int_ior" value="{:.9g}"/><float name="ext_ior" value="1"/>)"
                         R"(<rgb name="specular_reflectance" value="{}"/><rgb name="specular_transmittance" value="{}"/></bsdf>)",
                         m.ior, c, c);
    case MaterialKind::RoughConductor:
      return fmt::format(R"(<bsdf type="twosided"><bsdf type="roughconductor"><string name="material" value="none"/>)"
                         R"(<string name="distribution" value="ggx"/><float name="alpha" value="{:.9g}"/>)"
                         R"(<rgb name="specular_reflectance" value="{}"/></bsdf></bsdf>)", m.alpha, c);
    default:
      return fmt::format(R"(<bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="{}"/></bsdf></bsdf>)", c);
  }
}

// Binary little-endian PLY of the triangles of one material, with their own vertices.
std::string ply(const Scene& s, uint32_t material, size_t& faces) {
  std::vector<float> xyz;
  std::string body;
  faces = 0;
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    if (s.material_ids[i] != material) continue;
    const uint32_t base = uint32_t(xyz.size() / 3);
    for (uint32_t v : s.triangles[i].v) xyz.insert(xyz.end(), {s.positions[v].x, s.positions[v].y, s.positions[v].z});
    body.push_back(char(3));
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t idx = base + k;  // little-endian hosts only (x86-64, aarch64)
      body.append(reinterpret_cast<const char*>(&idx), 4);
    }
    ++faces;
  }
  std::string out = fmt::format("ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n"
                                "property float y\nproperty float z\nelement face {}\n"
                                "property list uchar uint vertex_indices\nend_header\n",
                                xyz.size() / 3, faces);
  out.append(reinterpret_cast<const char*>(xyz.data()), xyz.size() * sizeof(float));
  return out + body;
}

}  // namespace

std::string write_mitsuba_scene(const Scene& s, const RenderSettings& settings, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  const Camera& c = s.camera;
  const Vec3f target = c.position + c.forward;
  const double fov = 2 * std::atan(double(c.tan_half_fov_y)) * 180 / 3.14159265358979323846;
  // Russian roulette only for unbounded paths, as pathbench's --converged.
  const int depth = settings.max_bounces < 0 ? -1 : settings.max_bounces + 1;
  std::string xml = fmt::format(
      "<!-- {} as pathbench loaded it (pathbench crosscheck) -->\n<scene version=\"3.0.0\">\n"
      "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"{}\"/>"
      "<integer name=\"rr_depth\" value=\"{}\"/></integrator>\n"
      "  <sensor type=\"perspective\"><float name=\"fov\" value=\"{:.9g}\"/><string name=\"fov_axis\" value=\"y\"/>\n"
      "    <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>\n"
      "    <sampler type=\"independent\"><integer name=\"sample_count\" value=\"4\"/></sampler>\n"
      "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/><integer name=\"height\" value=\"{}\"/>"
      "<rfilter type=\"box\"/><string name=\"pixel_format\" value=\"rgb\"/></film>\n  </sensor>\n",
      s.name, depth, settings.russian_roulette ? 5 : std::max(depth, 1) + 100, fov, rgb(c.position), rgb(target), rgb(c.up),
      settings.width, settings.height);
  for (uint32_t m = 0; m < s.materials.size(); ++m) {
    size_t faces = 0;
    const std::string mesh = ply(s, m, faces);
    if (faces == 0) continue;
    const std::string file = fmt::format("material{}.ply", m);
    write_text_file((fs::path(dir) / file).string(), mesh);
    const Material& mat = s.materials[m];
    std::string emitter;
    if (max_component(mat.emission) > 0)
      emitter = fmt::format(R"(<emitter type="area"><rgb name="radiance" value="{}"/></emitter>)", rgb(mat.emission));
    xml += fmt::format("  <shape type=\"ply\"><string name=\"filename\" value=\"{}\"/><boolean name=\"face_normals\" "
                       "value=\"true\"/>{}{}</shape>\n", file, bsdf(mat), emitter);
  }
  xml += "</scene>\n";
  const std::string path = (fs::path(dir) / "scene.xml").string();
  write_text_file(path, xml);
  return path;
}

}  // namespace pb
