// The `pathbench` Python module: load a scene, read its arrays as numpy, cast batches
// of rays through the CPU tracer's Embree scene or the GPU BVH traversal (run on the
// host), and render (render_binding.cpp). Heavy work runs with the GIL released; bad
// input raises TypeError (a wrong type, arguments.h) or ValueError (a wrong value, with
// pathbench's own message from InputError).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/core.h>

#include <array>
#include <limits>
#include <memory>
#include <string>

#include "arguments.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/report.h"
#include "pathbench/scene_io/mitsuba_export.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/common/scene_warnings.h"
#include "pathbench/run/run.h"
#include "ray_cast.h"
#include "render_binding.h"
#include "scene_handle.h"

namespace py = pybind11;

namespace pb::py_bind {
namespace {

using pb::python::Batch;
using pb::python::make_batch;
using pb::python::SceneHandle;

// A read-only numpy view of `data` that keeps `owner` (the Python Scene) alive.
template <class T>
py::array view(const T* data, std::vector<py::ssize_t> shape, const py::object& owner) {
  std::vector<py::ssize_t> strides(shape.size());
  py::ssize_t s = sizeof(T);
  for (size_t k = shape.size(); k-- > 0;) {
    strides[k] = s;
    s *= shape[k];
  }
  py::array a(py::dtype::of<T>(), shape, strides, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

// Everything the module initialises lazily behind a function-local static or a
// first-call import, done once here at import (under the import lock, before any
// thread can call in): numpy and its C API table, and the dtypes the bindings use.
// pybind11 >= 2.12 makes these first uses safe from several threads by itself; this
// keeps the module free of that first-call race whichever pybind11 builds it.
void initialise_at_import() {
  py::module_::import("numpy");
  (void)py::dtype::of<float>();
  (void)py::dtype::of<uint32_t>();
  (void)py::dtype::of<bool>();
  (void)pb::builtin_scenes();
}

py::dict intersect(const py::handle& self, const py::handle& origins, const py::handle& directions,
                   const py::handle& tnear, const py::handle& tfar, const py::handle& backend_name,
                   const py::handle& watertight_flag) {
  const SceneHandle& s = pb::python::scene_arg(self, "self");
  const Batch b = make_batch(origins, directions, tnear, tfar, s.scene().origin);
  const auto be = pb::python::parse_backend(pb::python::str_arg(backend_name, "backend"));
  const bool watertight = pb::python::bool_arg(watertight_flag, "watertight");
  // Shape as a container: array_t(count) comes out with stride 0 in pybind11 2.10.
  const std::vector<py::ssize_t> shape{py::ssize_t(b.rays.n)};
  py::array_t<bool> hit(shape);
  py::array_t<uint32_t> prim(shape);
  py::array_t<float> t(shape);
  bool* h = hit.mutable_data();
  uint32_t* p = prim.mutable_data();
  float* tt = t.mutable_data();
  {
    py::gil_scoped_release release;
    pb::python::intersect(s, b.rays, be, watertight, h, p, tt);
  }
  py::dict out;
  out["hit"] = hit;
  out["prim"] = prim;
  out["t"] = t;
  return out;
}

py::array_t<bool> occluded(const py::handle& self, const py::handle& origins, const py::handle& directions,
                           const py::handle& tnear, const py::handle& tfar, const py::handle& backend_name,
                           const py::handle& watertight_flag) {
  const SceneHandle& s = pb::python::scene_arg(self, "self");
  const Batch b = make_batch(origins, directions, tnear, tfar, s.scene().origin);
  const auto be = pb::python::parse_backend(pb::python::str_arg(backend_name, "backend"));
  const bool watertight = pb::python::bool_arg(watertight_flag, "watertight");
  py::array_t<bool> out(std::vector<py::ssize_t>{py::ssize_t(b.rays.n)});
  bool* o = out.mutable_data();
  {
    py::gil_scoped_release release;
    pb::python::occluded(s, b.rays, be, watertight, o);
  }
  return out;
}

// The scene of a Python Scene (`self`); ValueError for an empty one (arguments.h scene_arg).
const pb::Scene& scene_of(const py::handle& self) { return pb::python::scene_arg(self, "self").scene(); }

std::shared_ptr<SceneHandle> load(const py::handle& name_or_path, float scale, std::array<float, 3> offset,
                                  const std::string& embree_layout, bool strict) {
  const std::string name = pb::python::path_arg(name_or_path, "name_or_path");
  EmbreeLayout layout;
  try {
    layout = parse_embree_layout(embree_layout);
  } catch (const InputError& e) {
    throw py::value_error(pb::python::python_terms(e.what()));
  }
  std::shared_ptr<SceneHandle> handle;
  std::vector<SceneWarningCollector::Message> said;
  {
    py::gil_scoped_release release;
    SceneWarningCollector collect;  // this thread's scene warnings, raised below as Python warnings
    handle = std::make_shared<SceneHandle>(
        pb::transformed(load_scene(name, {.strict = strict}), scale, Vec3f{offset[0], offset[1], offset[2]}), layout);
    said = collect.messages();
  }
  // UserWarning (warnings.filterwarnings("error") makes them exceptions, as --strict
  // does for what is not modelled).
  for (const auto& m : said) {
    const std::string text = (m.kind == SceneMessage::Note ? "note: " : "") + m.text;
    if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) != 0) throw py::error_already_set();
  }
  return handle;
}

}  // namespace
}  // namespace pb::py_bind

// The scene as Mitsuba 3 XML + PLY (pb::write_mitsuba_scene, the one exporter); returns
// the path of scene.xml.
py::str export_mitsuba(const py::handle& scene, const py::handle& folder, const py::handle& width,
                       const py::handle& height, const py::handle& bounces, const py::handle& converged) {
  const pb::Scene& s = pb::python::scene_arg(scene, "scene").scene();
  const std::string dir = pb::python::path_arg(folder, "folder");
  pb::RenderSettings rs;
  constexpr int64_t kMaxSide = std::numeric_limits<uint32_t>::max();
  rs.width = uint32_t(pb::python::int_arg(width, "width", 1, kMaxSide));
  rs.height = uint32_t(pb::python::int_arg(height, "height", 1, kMaxSide));
  if (pb::python::bool_arg(converged, "converged")) {
    if (!bounces.is_none()) throw py::value_error("bounces and converged=True exclude each other (converged: unbounded)");
    rs.max_bounces = -1;  // as `--converged`: unbounded, ended by Russian roulette
    rs.russian_roulette = true;
  } else if (!bounces.is_none()) {
    rs.max_bounces = int32_t(pb::python::int_arg(bounces, "bounces", 0, std::numeric_limits<int32_t>::max() - 1));
  }
  try {
    return pb::python::text(pb::write_mitsuba_scene(s, rs, dir));
  } catch (const pb::InputError& e) {  // a folder that cannot be written
    throw py::value_error(e.what());
  }
}

PYBIND11_MODULE(_core, m) {
  using namespace pb::py_bind;
  using pb::python::SceneHandle;
  m.doc() = "pathbench: scenes as numpy arrays, batched ray casts (Embree or the GPU BVH on the host), renders";
  initialise_at_import();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pb::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.attr("__version__") = PROJECT_VERSION_STRING;
  m.attr("git_revision") = pb::git_revision();
  m.attr("NO_HIT") = uint32_t(0xFFFFFFFFu);

  py::class_<SceneHandle, std::shared_ptr<SceneHandle>>(m, "Scene",
                                                        "A finalized scene (zero-area triangles dropped); "
                                                        "primitive ids index `triangles`.")
      .def_property_readonly("name", [](const py::handle& self) { return pb::python::text(scene_of(self).name); })
      .def_property_readonly("positions",
                             [](py::object self) -> py::array {
                               const auto& s = scene_of(self);
                               const std::vector<py::ssize_t> shape{py::ssize_t(s.positions.size()), 3};
                               if (is_zero(s.origin)) return view(&s.positions.data()->x, shape, self);
                               // Moved next to the origin to be traced: give back the user's
                               // coordinates (exactly the floats it was given).
                               py::array_t<float> a(shape);
                               float* p = a.mutable_data();
                               for (size_t i = 0; i < s.positions.size(); ++i)
                                 for (int k = 0; k < 3; ++k) p[3 * i + k] = s.positions[i][k] + s.origin[k];
                               a.attr("setflags")(py::arg("write") = false);
                               return std::move(a);
                             },
                             "(N, 3) float32 vertex positions (read-only)")
      .def_property_readonly("triangles",
                             [](py::object self) -> py::array {
                               const auto& s = scene_of(self);
                               return view(s.triangles.data()->v, {py::ssize_t(s.triangles.size()), 3}, self);
                             },
                             "(M, 3) uint32 vertex indices (read-only view)")
      .def_property_readonly("material_ids",
                             [](py::object self) -> py::array {
                               const auto& s = scene_of(self);
                               return view(s.material_ids.data(), {py::ssize_t(s.material_ids.size())}, self);
                             })
      .def_property_readonly("bounds",
                             [](const py::handle& self) {
                               const auto& s = scene_of(self);
                               py::array_t<float> b({2, 3});
                               float* p = b.mutable_data();
                               for (int k = 0; k < 3; ++k) {
                                 p[k] = s.bounds_min[k] + s.origin[k];  // user coordinates
                                 p[3 + k] = s.bounds_max[k] + s.origin[k];
                               }
                               return b;
                             },
                             "(2, 3) float32: [min corner, max corner]")
      .def_property_readonly("extent", [](const py::handle& self) { return scene_of(self).features.extent; })
      .def_property_readonly("num_triangles", [](const py::handle& self) { return scene_of(self).triangles.size(); })
      .def_property_readonly("dropped_triangles",
                             [](const py::handle& self) { return scene_of(self).dropped_triangles; })
      .def("intersect", &intersect, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::kw_only(), py::arg("backend") = "embree",
           py::arg("watertight") = true,
           "Closest hits of rays (origins, directions: (N, 3)) with tnear <= t <= tfar (numbers or (N,) arrays).\n"
           "backend: 'embree' (the CPU tracer's Embree scene) or 'bvh' (the GPU BVH traversal, on the host).\n"
           "Returns {'hit': bool (N,), 'prim': uint32 (N,) (NO_HIT on a miss), 't': float32 (N,) (inf on a miss)}.")
      .def("occluded", &occluded, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::kw_only(), py::arg("backend") = "embree",
           py::arg("watertight") = true, "Any hit in (tnear, tfar): bool (N,).")
      .def("__repr__", [](const py::handle& self) -> std::string {
        const SceneHandle* h = nullptr;
        try {
          h = &pb::python::scene_arg(self, "self");
        } catch (const py::value_error&) {
          return "<pathbench.Scene (empty: not made by load_scene)>";
        }
        return fmt::format("<pathbench.Scene {}: {} triangles, {} vertices>", py::repr(pb::python::text(h->scene().name)).cast<std::string>(),
                           h->scene().triangles.size(), h->scene().positions.size());
      })
      // A scene is read-only: a copy is the same scene (copy.copy would otherwise make an
      // empty one through Scene.__new__).
      .def("__copy__", [](const py::object& self) { return self; })
      .def("__deepcopy__", [](const py::object& self, const py::handle&) { return self; }, py::arg("memo"))
      .def("__reduce__", [](const py::handle&) -> py::object {
        throw py::type_error("a pathbench.Scene cannot be pickled; load it again with pathbench.load_scene");
      });

  m.def("load_scene", &load, py::arg("name_or_path"), py::arg("scale") = 1.0f,
        py::arg("offset") = std::array<float, 3>{0, 0, 0}, py::arg("embree_layout") = "auto",
        py::arg("strict") = false,
        "A built-in scene ('paper-cornell', 'scaling:100000', ...) or a scene file (.json, .obj, .ply, .gltf,\n"
        ".glb, Mitsuba 3 .xml), every point moved to p * scale + offset (the camera too); embree_layout as\n"
        "`--embree-layout` (auto, triangles, quads) for the CPU ray casts. What the file holds that pathbench\n"
        "does not model is a UserWarning, or with strict=True (`render --strict`) a ValueError. ValueError\n"
        "names what is wrong.");
  m.def("export_mitsuba", &export_mitsuba, py::arg("scene"), py::arg("folder"), py::arg("width"), py::arg("height"),
        py::kw_only(), py::arg("bounces") = py::none(), py::arg("converged") = false,
        "The scene as a Mitsuba 3 scene: folder/scene.xml and one binary PLY per material, each material as\n"
        "the Mitsuba plugin its pathbench BSDF is defined as, the camera as a perspective sensor, a path\n"
        "integrator for `bounces` (default 2; converged=True: unbounded with Russian roulette), as\n"
        "`pathbench crosscheck` writes it. Returns the path of scene.xml.");
  m.def("builtin_scenes", [] {
    py::list out;
    for (const auto& b : pb::builtin_scenes()) out.append(py::make_tuple(b.name, b.description));  // ASCII
    return out;
  });
  pb::python::def_render(m);
}
