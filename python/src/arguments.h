#pragma once
// Python arguments to C++ values, strictly: what is not what the argument means is
// refused with TypeError (complex, bool, object or string arrays; a float or a bool where
// an int is meant) or ValueError (a shape or a range), the message naming the argument.
// Nothing is cast silently except real numbers to float32 (numpy's usual rounding), and
// any layout (strided, Fortran order, a view) is copied to a C-contiguous float32 array.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>

#include "pathbench/common/math.h"
#include "ray_cast.h"
#include "scene_handle.h"

namespace pb::python {

namespace py = pybind11;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// Any array-like of real numbers (float or int dtypes) as C-contiguous float32. A
// conversion that fails (no memory for the copy) raises its Python exception
// (MemoryError); it is never used as an empty array.
FloatArray real_floats(const py::handle& obj, const char* name);
// An (N, 3) array of real numbers.
FloatArray rows3(const py::handle& obj, const char* name);

// Rays from Python: (N, 3) origins and directions, tnear / tfar as a number or (N,).
// Holds the converted arrays that `rays` points into.
struct Batch {
  FloatArray o, d, tn, tf;
  RayBatch rays;
};
// `origin`: the scene's Scene::origin (nonzero only for a scene finalize() moved next to
// the origin); ray origins come in the user's coordinates and are traced minus it.
Batch make_batch(const py::handle& origins, const py::handle& directions, const py::handle& tnear,
                 const py::handle& tfar, Vec3f origin);

// An int (or anything with __index__, such as numpy.int64; not bool, not float) in
// [lo, hi]. TypeError / ValueError naming `name`.
int64_t int_arg(const py::handle& v, const char* name, int64_t lo, int64_t hi);
uint64_t uint64_arg(const py::handle& v, const char* name);  // [0, 2^64 - 1]
bool bool_arg(const py::handle& v, const char* name);        // True/False or numpy.bool_
std::string str_arg(const py::handle& v, const char* name);
// A file name: str (bytes that are not UTF-8 as os.fsdecode's surrogate escapes), bytes or
// an os.PathLike, as os.fsencode gives it. TypeError otherwise.
std::string path_arg(const py::handle& v, const char* name);

// A C++ string (a scene name from a file name, a report field) as a Python str: bytes
// that are not UTF-8 kept as surrogate escapes (os.fsdecode's convention), never a
// UnicodeDecodeError.
py::str text(const std::string& s);

// The scene behind a pathbench.Scene argument (`self` too): TypeError when `v` is not a
// Scene; ValueError when it has no scene, as one made by Scene.__new__(Scene) (or a
// pickle or copy of one) without load_scene. Never a null handle. The reference lives as
// long as `v`.
const SceneHandle& scene_arg(const py::handle& v, const char* name);

}  // namespace pb::python
