#include "arguments.h"

#include <fmt/core.h>

namespace pb::python {

namespace {

std::string type_name(const py::handle& v) { return py::str(py::type::handle_of(v).attr("__name__")); }

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// `a` as a C-contiguous array of T, copied by numpy where it must be. array_t::ensure
// returns a null array when the copy fails (and clears Python's error): the MemoryError
// under a memory limit was then used as an array of nothing. numpy's own call raises.
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> contiguous(const py::handle& a, const char* name) {
  const py::object converted =
      py::module_::import("numpy").attr("asarray")(a, py::arg("dtype") = py::dtype::of<T>(), py::arg("order") = "C");
  auto out = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(converted);
  if (!out) throw py::type_error(fmt::format("{}: cannot be read as a C-contiguous array", name));
  return out;
}

}  // namespace

std::string path_arg(const py::handle& v, const char* name) {
  if (!py::isinstance<py::str>(v) && !py::isinstance<py::bytes>(v) && !py::hasattr(v, "__fspath__"))
    throw py::type_error(fmt::format("{} must be a str, bytes or os.PathLike, got {}", name, type_name(v)));
  return py::module_::import("os").attr("fsencode")(v).cast<std::string>();
}

py::str text(const std::string& s) {
  PyObject* o = PyUnicode_DecodeUTF8(s.data(), py::ssize_t(s.size()), "surrogateescape");
  if (!o) throw py::error_already_set();  // MemoryError: raised, not returned as a null str
  return py::reinterpret_steal<py::str>(o);
}

const SceneHandle& scene_arg(const py::handle& v, const char* name) {
  if (!py::isinstance<SceneHandle>(v))
    throw py::type_error(fmt::format("{} must be a pathbench.Scene, got {}", name, type_name(v)));
  std::shared_ptr<SceneHandle> scene;
  try {
    scene = v.cast<std::shared_ptr<SceneHandle>>();  // throws for an instance whose holder was never made
  } catch (const py::cast_error&) {
  }
  if (!scene)
    throw py::value_error(fmt::format("{} is an empty pathbench.Scene (made without pathbench.load_scene, e.g. by "
                                      "Scene.__new__): load one with pathbench.load_scene",
                                      name));
  return *scene;  // held by `v`'s holder as long as `v` lives
}

FloatArray real_floats(const py::handle& obj, const char* name) {
  // numpy.asarray first, without a dtype, to see what the caller gave: forcecast alone
  // would turn complex into its real part, True into 1.0 and objects into whatever they cast to.
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(obj);
  } catch (py::error_already_set& e) {
    throw py::value_error(fmt::format("{}: not an array of numbers ({})", name, e.what()));
  }
  const char kind = a.dtype().kind();
  if (kind == 'c')
    throw py::type_error(fmt::format("{} is complex ({}): expected real numbers (pass .real if that is meant)",
                                     name, std::string(py::str(a.dtype()))));
  if (kind == 'b') throw py::type_error(fmt::format("{} is an array of bool: expected real numbers", name));
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(fmt::format("{} has dtype {}: expected real numbers (float or int)", name,
                                     std::string(py::str(a.dtype()))));
  return contiguous<float>(a, name);  // float32, C order: copies strided or Fortran-ordered input
}

FloatArray rows3(const py::handle& obj, const char* name) {
  FloatArray a = real_floats(obj, name);
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(fmt::format("{} must have shape (N, 3), got {}", name, shape_of(a)));
  return a;
}

namespace {

// Ray origins as the scene traces them: minus the scene's origin, taken in double so
// that float64 input keeps its digits until that subtraction.
FloatArray traced_origins(const py::handle& obj, Vec3f origin) {
  FloatArray a = rows3(obj, "origins");
  if (origin.x == 0 && origin.y == 0 && origin.z == 0) return a;
  const auto d = contiguous<double>(obj, "origins");
  FloatArray out(std::vector<py::ssize_t>{a.shape(0), 3});
  float* o = out.mutable_data();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (int k = 0; k < 3; ++k) o[3 * i + k] = float(d.at(i, k) - double(origin[k]));
  return out;
}

}  // namespace

Batch make_batch(const py::handle& origins, const py::handle& directions, const py::handle& tnear,
                 const py::handle& tfar, Vec3f origin) {
  Batch b{traced_origins(origins, origin), rows3(directions, "directions"), {}, {}, {}};
  const size_t n = size_t(b.o.shape(0));
  if (size_t(b.d.shape(0)) != n)
    throw py::value_error(fmt::format("origins and directions must have the same number of rows ({} != {})", n,
                                      b.d.shape(0)));
  // tnear / tfar: one number for every ray (stride 0), or one per ray.
  auto per_ray = [n](const py::handle& obj, const char* name, FloatArray& out) -> size_t {
    out = real_floats(obj, name);
    if (out.ndim() == 0) return 0;
    if (out.ndim() != 1 || size_t(out.shape(0)) != n)
      throw py::value_error(fmt::format("{} must be a number or an array of shape ({},), got shape {}", name, n,
                                        shape_of(out)));
    return 1;
  };
  const size_t tn_stride = per_ray(tnear, "tnear", b.tn);
  const size_t tf_stride = per_ray(tfar, "tfar", b.tf);
  b.rays = {b.o.data(), b.d.data(), b.tn.data(), b.tf.data(), tn_stride, tf_stride, n};
  return b;
}

namespace {

// operator.index(v); its exception (an __index__ that raises or returns a non-int)
// raised, not a null int used.
py::int_ index_of(const py::handle& v) {
  PyObject* i = PyNumber_Index(v.ptr());
  if (!i) throw py::error_already_set();
  return py::reinterpret_steal<py::int_>(i);
}

}  // namespace

int64_t int_arg(const py::handle& v, const char* name, int64_t lo, int64_t hi) {
  if (PyBool_Check(v.ptr()) || !PyIndex_Check(v.ptr()))
    throw py::type_error(fmt::format("{} must be an int, got {}", name, type_name(v)));
  const py::int_ i = index_of(v);
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow || x < lo || x > hi)
    throw py::value_error(fmt::format("{} = {} is out of range [{}, {}]", name, std::string(py::repr(i)), lo, hi));
  return x;
}

uint64_t uint64_arg(const py::handle& v, const char* name) {
  if (PyBool_Check(v.ptr()) || !PyIndex_Check(v.ptr()))
    throw py::type_error(fmt::format("{} must be an int, got {}", name, type_name(v)));
  const py::int_ i = index_of(v);
  const unsigned long long x = PyLong_AsUnsignedLongLong(i.ptr());  // refuses negatives and > 2^64 - 1
  if (PyErr_Occurred()) {
    PyErr_Clear();
    throw py::value_error(fmt::format("{} = {} is out of range [0, {}]", name, std::string(py::repr(i)), UINT64_MAX));
  }
  return x;
}

bool bool_arg(const py::handle& v, const char* name) {
  if (PyBool_Check(v.ptr())) return v.ptr() == Py_True;
  if (py::isinstance(v, py::module_::import("numpy").attr("bool_"))) return PyObject_IsTrue(v.ptr()) == 1;
  throw py::type_error(fmt::format("{} must be True or False, got {}", name, type_name(v)));
}

std::string str_arg(const py::handle& v, const char* name) {
  if (!py::isinstance<py::str>(v)) throw py::type_error(fmt::format("{} must be a str, got {}", name, type_name(v)));
  return v.cast<std::string>();
}

}  // namespace pb::python
