// The `pathbench` Python module: load a scene, read its arrays as numpy, cast batches
// of rays through the CPU tracer's Embree scene or the GPU BVH traversal (run on the
// host), and render. Heavy work runs with the GIL released; bad input raises
// ValueError with pathbench's own message (InputError).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/core.h>

#include <array>
#include <limits>
#include <memory>
#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/run/run.h"
#include "ray_cast.h"
#include "scene_handle.h"

namespace py = pybind11;

namespace pb::py_bind {
namespace {

using pb::python::SceneHandle;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

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

FloatArray rows3(const py::object& obj, const char* what) {
  FloatArray a = FloatArray::ensure(obj);
  if (!a) throw InputError(fmt::format("{} must be an array of floats of shape (N, 3)", what));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InputError(fmt::format("{} must have shape (N, 3), got {}", what, std::string(py::str(obj.attr("shape")))));
  return a;
}

// Ray origins in the user's coordinates, as the scene traces them: minus the scene's
// origin (Scene::origin, nonzero only for a scene finalize() moved next to the origin),
// taken in double so that float64 input keeps its digits until that subtraction.
FloatArray traced_origins(const py::object& obj, Vec3f origin) {
  FloatArray a = rows3(obj, "origins");
  if (is_zero(origin)) return a;
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  FloatArray out(std::vector<py::ssize_t>{a.shape(0), 3});
  float* o = out.mutable_data();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (int k = 0; k < 3; ++k) o[3 * i + k] = float(d.at(i, k) - double(origin[k]));
  return out;
}

// tnear / tfar: one number for every ray, or an array of shape (N,).
struct PerRay {
  FloatArray values;
  size_t stride;
};
PerRay per_ray(const py::object& obj, size_t n, const char* what) {
  FloatArray a = FloatArray::ensure(obj);
  if (!a) throw InputError(fmt::format("{} must be a number or an array of shape ({},)", what, n));
  if (a.ndim() == 0) return {a, 0};
  if (a.ndim() != 1 || size_t(a.shape(0)) != n)
    throw InputError(fmt::format("{} must be a number or an array of shape ({},), got shape {}", what, n,
                                 std::string(py::str(a.attr("shape")))));
  return {a, 1};
}

struct Batch {
  FloatArray o, d;
  PerRay tn, tf;
  pb::python::RayBatch rays;
};
Batch make_batch(const SceneHandle& s, const py::object& origins, const py::object& directions,
                 const py::object& tnear, const py::object& tfar) {
  Batch b{traced_origins(origins, s.scene().origin), rows3(directions, "directions"), {}, {}, {}};
  const size_t n = size_t(b.o.shape(0));
  if (size_t(b.d.shape(0)) != n)
    throw InputError(fmt::format("origins and directions must have the same number of rows ({} != {})", n,
                                 b.d.shape(0)));
  b.tn = per_ray(tnear, n, "tnear");
  b.tf = per_ray(tfar, n, "tfar");
  b.rays = {b.o.data(), b.d.data(), b.tn.values.data(), b.tf.values.data(), b.tn.stride, b.tf.stride, n};
  return b;
}

py::dict intersect(const SceneHandle& s, const py::object& origins, const py::object& directions,
                   const py::object& tnear, const py::object& tfar, const std::string& backend, bool watertight) {
  const Batch b = make_batch(s, origins, directions, tnear, tfar);
  const auto be = pb::python::parse_backend(backend);
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

py::array_t<bool> occluded(const SceneHandle& s, const py::object& origins, const py::object& directions,
                           const py::object& tnear, const py::object& tfar, const std::string& backend,
                           bool watertight) {
  const Batch b = make_batch(s, origins, directions, tnear, tfar);
  const auto be = pb::python::parse_backend(backend);
  py::array_t<bool> out(std::vector<py::ssize_t>{py::ssize_t(b.rays.n)});
  bool* o = out.mutable_data();
  {
    py::gil_scoped_release release;
    pb::python::occluded(s, b.rays, be, watertight, o);
  }
  return out;
}

std::shared_ptr<SceneHandle> load(const std::string& name, float scale, std::array<float, 3> offset) {
  py::gil_scoped_release release;
  return std::make_shared<SceneHandle>(
      pb::transformed(load_scene(name), scale, Vec3f{offset[0], offset[1], offset[2]}));
}

py::tuple render(const SceneHandle& s, uint32_t width, uint32_t height, uint32_t spp, int max_bounces,
                 const std::string& sampling, const std::string& strategy, const std::string& device, uint64_t seed,
                 bool russian_roulette, uint64_t paths_in_flight, int threads, bool watertight, bool profile) {
  RenderSettings rs;
  rs.width = width;
  rs.height = height;
  rs.spp = spp;
  rs.max_bounces = max_bounces;
  rs.sampling = parse_sampling(sampling);
  rs.strategy = parse_strategy(strategy);
  rs.device = parse_device(device);
  rs.seed = seed;
  rs.russian_roulette = russian_roulette;
  rs.paths_in_flight = paths_in_flight;
  rs.threads = threads;
  rs.watertight = watertight;
  rs.progress = false;
  Film film(width, height, false);
  RunReport report;
  std::vector<float> mean;
  {
    py::gil_scoped_release release;
    run::render(s.scene(), rs, film, report, {.profile = profile});
    mean = film.mean();
  }
  py::array_t<float> image({py::ssize_t(height), py::ssize_t(width), py::ssize_t(3)});
  std::copy(mean.begin(), mean.end(), image.mutable_data());
  py::object report_dict = py::module_::import("json").attr("loads")(report.to_json().dump());
  return py::make_tuple(image, report_dict);
}

}  // namespace
}  // namespace pb::py_bind

PYBIND11_MODULE(pathbench, m) {
  using namespace pb::py_bind;
  using pb::python::SceneHandle;
  m.doc() = "pathbench: scenes as numpy arrays, batched ray casts (Embree or the GPU BVH on the host), renders";
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
      .def_property_readonly("name", [](const SceneHandle& s) { return s.scene().name; })
      .def_property_readonly("positions",
                             [](py::object self) -> py::array {
                               const auto& s = self.cast<const SceneHandle&>().scene();
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
                               const auto& s = self.cast<const SceneHandle&>().scene();
                               return view(s.triangles.data()->v, {py::ssize_t(s.triangles.size()), 3}, self);
                             },
                             "(M, 3) uint32 vertex indices (read-only view)")
      .def_property_readonly("material_ids",
                             [](py::object self) -> py::array {
                               const auto& s = self.cast<const SceneHandle&>().scene();
                               return view(s.material_ids.data(), {py::ssize_t(s.material_ids.size())}, self);
                             })
      .def_property_readonly("bounds",
                             [](const SceneHandle& h) {
                               const auto& s = h.scene();
                               py::array_t<float> b({2, 3});
                               float* p = b.mutable_data();
                               for (int k = 0; k < 3; ++k) {
                                 p[k] = s.bounds_min[k] + s.origin[k];  // user coordinates
                                 p[3 + k] = s.bounds_max[k] + s.origin[k];
                               }
                               return b;
                             },
                             "(2, 3) float32: [min corner, max corner]")
      .def_property_readonly("extent", [](const SceneHandle& s) { return s.scene().features.extent; })
      .def_property_readonly("num_triangles", [](const SceneHandle& s) { return s.scene().triangles.size(); })
      .def_property_readonly("dropped_triangles", [](const SceneHandle& s) { return s.scene().dropped_triangles; })
      .def("intersect", &intersect, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::kw_only(), py::arg("backend") = "embree",
           py::arg("watertight") = true,
           "Closest hits of rays (origins, directions: (N, 3)) with tnear <= t <= tfar (numbers or (N,) arrays).\n"
           "backend: 'embree' (the CPU tracer's Embree scene) or 'bvh' (the GPU BVH traversal, on the host).\n"
           "Returns {'hit': bool (N,), 'prim': uint32 (N,) (NO_HIT on a miss), 't': float32 (N,) (inf on a miss)}.")
      .def("occluded", &occluded, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0f,
           py::arg("tfar") = std::numeric_limits<float>::infinity(), py::kw_only(), py::arg("backend") = "embree",
           py::arg("watertight") = true, "Any hit in (tnear, tfar): bool (N,).")
      .def("__repr__", [](const SceneHandle& s) {
        return fmt::format("<pathbench.Scene '{}': {} triangles, {} vertices>", s.scene().name,
                           s.scene().triangles.size(), s.scene().positions.size());
      });

  m.def("load_scene", &load, py::arg("name_or_path"), py::arg("scale") = 1.0f,
        py::arg("offset") = std::array<float, 3>{0, 0, 0},
        "A built-in scene ('paper-cornell', 'scaling:100000', ...) or a .json/.obj file, every point moved to\n"
        "p * scale + offset (the camera too). ValueError names what is wrong.");
  m.def("builtin_scenes", [] {
    py::list out;
    for (const auto& b : pb::builtin_scenes()) out.append(py::make_tuple(b.name, b.description));
    return out;
  });
  m.def("render", &render, py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("spp"), py::kw_only(),
        py::arg("max_bounces") = 2, py::arg("sampling") = "nee", py::arg("strategy") = "pixel",
        py::arg("device") = "cpu", py::arg("seed") = 0, py::arg("russian_roulette") = false,
        py::arg("paths_in_flight") = 0, py::arg("threads") = 0, py::arg("watertight") = true,
        py::arg("profile") = false,
        "Renders on 'cpu' or 'gpu' (where built). Returns (image float32 (H, W, 3), row 0 at the top; report dict\n"
        "as in `pathbench render --report`).");
}
