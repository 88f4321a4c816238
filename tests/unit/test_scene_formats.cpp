// Scene formats beyond JSON and OBJ: PLY (ASCII, binary both endians), glTF 2.0 and
// Mitsuba 3 XML each load tests/data/scenes/formats/ to the same triangles, materials
// and camera as their JSON or OBJ twin (make_format_scenes.py writes them); JSON
// transforms (rotate, matrix) and instancing; losses are named, or fatal when strict.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include "pathbench/common/errors.h"
#include "test_scene_helpers.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb {
namespace {

const std::string kFormats = std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/scenes/formats/";

void expect_near_vec(Vec3f a, Vec3f b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

// Triangle by triangle: the same corners (within tol, from rotations computed two
// ways), the same material (albedo, emission, kind), and the same camera.
void expect_same_scene(const Scene& a, const Scene& b, float tol) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      expect_near_vec(a.positions[a.triangles[i].v[k]], b.positions[b.triangles[i].v[k]], tol,
                      "triangle " + std::to_string(i) + " corner " + std::to_string(k));
    const Material& ma = a.materials[a.material_ids[i]];
    const Material& mb = b.materials[b.material_ids[i]];
    expect_near_vec(ma.albedo, mb.albedo, 1e-6f, "albedo of triangle " + std::to_string(i));
    expect_near_vec(ma.emission, mb.emission, 1e-6f, "emission of triangle " + std::to_string(i));
    EXPECT_EQ(ma.kind, mb.kind) << "triangle " << i;
  }
  expect_near_vec(a.camera.position, b.camera.position, tol, "camera position");
  expect_near_vec(a.camera.forward, b.camera.forward, tol, "camera forward");
  expect_near_vec(a.camera.up, b.camera.up, tol, "camera up");
  EXPECT_NEAR(a.camera.tan_half_fov_y, b.camera.tan_half_fov_y, 1e-6f);
  EXPECT_EQ(a.emitters, b.emitters);
}

using scene_test::error_of;

class TempDir : public testing::Test {
 protected:
  std::filesystem::path dir_ = std::filesystem::temp_directory_path() /
                               ("pathbench-formats-" + std::to_string(::getpid()));
  void SetUp() override { std::filesystem::create_directories(dir_); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
};

TEST(ScenePly, AsciiAndBinaryAreTheObj) {
  const Scene obj = load_scene(kFormats + "cube.obj");
  for (const char* name : {"cube-ascii.ply", "cube-le.ply", "cube-be.ply"}) {
    SCOPED_TRACE(name);
    expect_same_scene(obj, load_scene(kFormats + name), 0);
  }
}

TEST(SceneGltf, IsTheJsonTwin) {
  testing::internal::CaptureStderr();
  const Scene gltf = load_scene(kFormats + "instanced.gltf");
  const Scene glb = load_scene(kFormats + "instanced.glb");
  testing::internal::GetCapturedStderr();
  const Scene json = load_scene(kFormats + "instanced.json");
  expect_same_scene(json, gltf, 1e-5f);
  expect_same_scene(gltf, glb, 0);
  // The cube mesh is one prototype placed by two nodes.
  ASSERT_EQ(gltf.instances.size(), 4u);  // every mesh node is an instance
  EXPECT_EQ(gltf.instances[0].prototype, gltf.instances[1].prototype);
}

TEST(SceneMitsuba, IsTheJsonTwin) {
  const Scene xml = load_scene(kFormats + "instanced.xml");
  const Scene json = load_scene(kFormats + "instanced.json");
  expect_same_scene(json, xml, 1e-5f);
  EXPECT_EQ(xml.render_defaults.width, 64u);
  EXPECT_EQ(xml.render_defaults.height, 48u);
  EXPECT_EQ(xml.render_defaults.spp, 16u);   // $spp from its <default>
  EXPECT_EQ(xml.render_defaults.max_bounces, 2);  // max_depth 3
  ASSERT_EQ(xml.instances.size(), 2u);
}

TEST(SceneJson, InstancesAreKeptAndExpanded) {
  const Scene s = load_scene(kFormats + "instanced.json");
  ASSERT_EQ(s.prototypes.size(), 1u);
  EXPECT_EQ(s.prototypes[0].triangles.size(), 12u);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.triangles.size(), 2u * 12 + 4);
  // Each instance's triangles are the prototype's moved by its transform.
  for (const SceneInstance& in : s.instances) {
    ASSERT_EQ(in.triangle_count, 12u);
    for (uint32_t t = 0; t < 12; ++t)
      for (int k = 0; k < 3; ++k)
        expect_near_vec(s.positions[s.triangles[in.first_triangle + t].v[k]],
                        in.to_world.point(s.prototypes[0].positions[s.prototypes[0].triangles[t].v[k]]), 0, "instance");
  }
  // The first: rotated 30 degrees about y, then moved: the corner (0.5, -0.5, 0.5) lands at
  // (-1 + 0.5 cos30 + 0.5 sin30, 0, -0.5 sin30 + 0.5 cos30).
  const float c = std::cos(kPi<float> / 6), sn = std::sin(kPi<float> / 6);
  expect_near_vec(s.instances[0].to_world.point({0.5f, -0.5f, 0.5f}), {-1 + 0.5f * c + 0.5f * sn, 0, -0.5f * sn + 0.5f * c},
                  1e-6f, "rotated corner");
}

TEST_F(TempDir, JsonMatrixMustBeAffineAndRotateNeedsAnAxis) {
  const std::string head = R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov_y_deg": 40},
    "materials": {"l": {"emission": [1, 1, 1]}}, "meshes": [{"file": ")" + kFormats + R"(cube.obj", "material": "l", )";
  EXPECT_NE(error_of([&] { load_scene(write("p.json", head + R"("transform": {"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]}}]})")); })
                .find("p.json: meshes[0].transform.matrix[3]: the last row of an affine transform must be [0, 0, 0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("z.json", head + R"("transform": {"rotate": {"axis": [0,0,0], "angle": 5}}}]})")); })
                .find("z.json: meshes[0].transform.rotate.axis: is zero"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("s.json", head + R"("transform": {"matrix": [[1,0,0,0],[0,0,0,0],[0,0,1,0]]}}]})")); })
                .find("s.json: meshes[0].transform.matrix: is singular"),
            std::string::npos);
}

TEST_F(TempDir, ObjInJsonKeepsItsMtlMaterials) {
  write("lit.mtl", "newmtl lamp\nKd 0 0 0\nKe 5 5 5\nnewmtl red\nKd 0.6 0.1 0.1\n");
  write("lit.obj", "mtllib lit.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\nusemtl red\nf 1 3 4\n");
  const Scene s = load_scene(write("wrap.json", R"({"camera": {"position": [0.5, 0.5, 3], "look_at": [0.5, 0.5, 0], "fov_y_deg": 40},
    "meshes": [{"file": "lit.obj"}]})"));
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.material_names[s.material_ids[0]], "lit.obj:lamp");
  EXPECT_EQ(s.materials[s.material_ids[0]].emission.x, 5.0f);
  EXPECT_FLOAT_EQ(s.materials[s.material_ids[1]].albedo.x, 0.6f);
  EXPECT_EQ(s.emitters.size(), 1u);  // the scene is lit: not the black render of before
}

TEST_F(TempDir, LossesAreNamedOrFatalWhenStrict) {
  write("n.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "property float nx\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                 "0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n");
  testing::internal::CaptureStderr();
  load_scene((dir_ / "n.ply").string());
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("n.ply: vertex properties nx (not modelled; ignored)"), std::string::npos) << err;
  EXPECT_NE(error_of([&] { load_scene((dir_ / "n.ply").string(), {.strict = true}); })
                .find("n.ply: vertex properties nx: not modelled by pathbench (--strict)"),
            std::string::npos);
  write("t.mtl", "newmtl tex\nKd 0.5 0.5 0.5\nmap_Kd wood.png\n");
  write("t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nusemtl tex\nf 1//1 2//1 3//1\n");
  testing::internal::CaptureStderr();
  load_scene((dir_ / "t.obj").string());
  const std::string obj_err = testing::internal::GetCapturedStderr();
  EXPECT_NE(obj_err.find("material 'tex': texture map_Kd 'wood.png'"), std::string::npos) << obj_err;
  EXPECT_NE(obj_err.find("1 vertex normals (vn)"), std::string::npos) << obj_err;
}

TEST_F(TempDir, MalformedFilesNameTheFileAndFormat) {
  EXPECT_NE(error_of([&] { load_scene(write("bad.ply", "ply\nformat ascii 1.0\nelement vertex 99\nproperty float x\n"
                                                       "property float y\nproperty float z\nelement face 0\n"
                                                       "property list uchar int vertex_indices\nend_header\n0 0 0\n")); })
                .find("bad.ply: malformed PLY: element 'vertex' declares 99 entries"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("idx.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                                       "property float y\nproperty float z\nelement face 1\n"
                                                       "property list uchar int vertex_indices\nend_header\n"
                                                       "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")); })
                .find("idx.ply: malformed PLY: a face refers to vertex 7, but the file has only 3 vertices"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("bad.gltf", R"({"asset": {"version": "2.0"}, "meshes": [)")); })
                .find("bad.gltf: malformed glTF"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("bad.xml", "<scene version=\"3.0.0\"><shape type=\"cube\">\n</scene>")); })
                .find("bad.xml:2: malformed XML"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("tri.stl", "solid x\n")); }).find("tri.stl: STL files are not read by pathbench"),
            std::string::npos);
}

// A Mitsuba scene around one shape with the given BSDF, for the mapping tests.
std::string mitsuba_with(const std::string& bsdf, const std::string& sensor_extra = "") {
  return R"(<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="60"/>)" + sensor_extra +
         R"(<transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/><rfilter type="box"/></film>
    </sensor><shape type="cube">)" + bsdf + R"(</shape>
    <shape type="rectangle"><transform name="to_world"><translate z="3"/></transform>
    <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape></scene>)";
}

TEST_F(TempDir, MitsubaBsdfsMapToPathbenchMaterials) {
  auto cube_material = [&](const std::string& bsdf) {
    testing::internal::CaptureStderr();
    const Scene s = load_scene(write("m.xml", mitsuba_with(bsdf)));
    testing::internal::GetCapturedStderr();
    return s.materials[s.material_ids[0]];
  };
  Material m = cube_material(R"(<bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.3, 0.4"/></bsdf></bsdf>)");
  EXPECT_EQ(m.kind, MaterialKind::Diffuse);
  EXPECT_FLOAT_EQ(m.albedo.z, 0.4f);
  m = cube_material(R"(<bsdf type="conductor"><string name="material" value="none"/><rgb name="specular_reflectance" value="0.9"/></bsdf>)");
  EXPECT_EQ(m.kind, MaterialKind::Mirror);
  EXPECT_FLOAT_EQ(m.albedo.x, 0.9f);
  m = cube_material(R"(<bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha" value="0.3"/></bsdf>)");
  EXPECT_EQ(m.kind, MaterialKind::RoughConductor);
  EXPECT_FLOAT_EQ(m.alpha, 0.3f);
  m = cube_material(R"(<bsdf type="dielectric"><string name="int_ior" value="water"/><float name="ext_ior" value="1"/></bsdf>)");
  EXPECT_EQ(m.kind, MaterialKind::Dielectric);
  EXPECT_FLOAT_EQ(m.ior, 1.333f);
  m = cube_material(R"(<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.25"/></bsdf>)");
  EXPECT_EQ(m.kind, MaterialKind::Diffuse);  // a stand-in, named as lost
  EXPECT_FLOAT_EQ(m.albedo.y, 0.25f);
  // Named as lost, or an error with strict.
  EXPECT_NE(error_of([&] { load_scene(write("p.xml", mitsuba_with(R"(<bsdf type="plastic"/>)")), {.strict = true}); })
                .find("p.xml: bsdf 'plastic' (a diffuse stand-in is used): not modelled by pathbench (--strict)"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("b.xml", mitsuba_with(R"(<bsdf type="roughconductor"/>)")), {.strict = true}); })
                .find("microfacet distribution 'beckmann' (rendered as GGX)"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_scene(write("i.xml", mitsuba_with(R"(<bsdf type="dielectric"><string name="int_ior" value="unobtainium"/></bsdf>)"))); })
                .find("i.xml: Mitsuba XML: <bsdf type=\"dielectric\">: int_ior: unknown index of refraction 'unobtainium'"),
            std::string::npos);
}

TEST_F(TempDir, MitsubaFieldOfViewFollowsItsAxis) {
  // fov 60 along x on a 200x100 film: tan(fov_y / 2) = tan(30 deg) / 2.
  const Scene x = load_scene(write("x.xml", mitsuba_with("")));
  EXPECT_NEAR(x.camera.tan_half_fov_y, std::tan(kPi<double> / 6) / 2, 1e-6);
  const Scene y = load_scene(write("y.xml", mitsuba_with("", R"(<string name="fov_axis" value="y"/>)")));
  EXPECT_NEAR(y.camera.tan_half_fov_y, std::tan(kPi<double> / 6), 1e-6);
  EXPECT_NEAR(y.camera.forward.z, -1, 1e-6);  // looking from z = 5 to the origin
}

TEST_F(TempDir, GltfMetalsAreRoughConductors) {
  // instanced.gltf with its blue material made metallic (roughness 0.5: alpha 0.25).
  std::ifstream in(kFormats + "instanced.gltf");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = R"("baseColorFactor": [
     0.1,
     0.2,
     0.6,
     1
    ],
    "metallicFactor": 0)";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), R"("baseColorFactor": [0.1, 0.2, 0.6, 1], "metallicFactor": 1, "roughnessFactor": 0.5)");
  testing::internal::CaptureStderr();
  const Scene s = load_scene(write("metal.gltf", text));
  testing::internal::GetCapturedStderr();
  const Material& m = s.materials[s.material_ids[0]];
  EXPECT_EQ(m.kind, MaterialKind::RoughConductor);
  EXPECT_FLOAT_EQ(m.alpha, 0.25f);
  EXPECT_FLOAT_EQ(m.albedo.z, 0.6f);
}

}  // namespace
}  // namespace pb
