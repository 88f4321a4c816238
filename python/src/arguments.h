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

namespace pb::python {

namespace py = pybind11;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// Any array-like of real numbers (float or int dtypes) as C-contiguous float32.
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

}  // namespace pb::python
