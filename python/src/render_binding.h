#pragma once
// `pathbench.render`: the CLI's render options as keywords, turned into RenderSettings
// by the CLI's own code (pb::apply_choices and RenderSettings::validate, common/), so the
// module accepts and refuses exactly what `pathbench render` does; their messages name
// the CLI option (--embree-layout) and are reworded here to the keyword (embree_layout).
#include <pybind11/pybind11.h>

#include <string>

namespace pb::python {

namespace py = pybind11;

// "--paths-in-flight: must be ..." -> "paths_in_flight: must be ...".
std::string python_terms(const std::string& cli_message);

// Adds `render` to the module (its keywords and docstring live beside the code that reads them).
void def_render(py::module_& m);

}  // namespace pb::python
