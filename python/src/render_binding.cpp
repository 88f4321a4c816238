#include "render_binding.h"

#include <pybind11/numpy.h>

#include <cctype>
#include <cstdint>
#include <limits>
#include <vector>

#include "arguments.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/run.h"  // the render entry: the one call site in the module (below)
#include "scene_handle.h"

namespace pb::python {

namespace {

// The run report as Python objects (dict, list, int, float, str, bool, None), converted
// directly rather than through the json module.
py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[text(k)] = to_python(v);
      return std::move(d);
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(to_python(v));
      return std::move(l);
    }
    case nlohmann::json::value_t::string: return text(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    default: return py::none();
  }
}

py::array_t<float> image(const std::vector<float>& pixels, uint32_t width, uint32_t height) {
  py::array_t<float> out(std::vector<py::ssize_t>{py::ssize_t(height), py::ssize_t(width), 3});
  std::copy(pixels.begin(), pixels.end(), out.mutable_data());
  return out;
}

constexpr int64_t kU32 = std::numeric_limits<uint32_t>::max();
constexpr int64_t kI32 = std::numeric_limits<int32_t>::max();

py::tuple render(const py::handle& scene, const py::object& width, const py::object& height, const py::object& spp,
                 const py::object& bounces, const py::object& converged, const py::object& rr,
                 const py::object& sampling, const py::object& strategy, const py::object& device,
                 const py::object& precision, const py::object& embree_layout, const py::object& isa,
                 const py::object& instancing, const py::object& seed,
                 const py::object& paths_in_flight, const py::object& threads, const py::object& watertight,
                 const py::object& variance, const py::object& profile) {
  const SceneHandle& s = scene_arg(scene, "scene");
  RenderSettings rs;
  RenderChoices c;
  rs.width = uint32_t(int_arg(width, "width", 0, kU32));
  rs.height = uint32_t(int_arg(height, "height", 0, kU32));
  rs.spp = uint32_t(int_arg(spp, "spp", 0, kU32));
  c.converged = bool_arg(converged, "converged");
  if (!bounces.is_none()) {
    if (c.converged) throw py::value_error("bounces and converged=True exclude each other (converged: unbounded)");
    rs.max_bounces = int32_t(int_arg(bounces, "bounces", -1, kI32));
  }
  rs.russian_roulette = bool_arg(rr, "rr");
  c.sampling = str_arg(sampling, "sampling");
  c.strategy = str_arg(strategy, "strategy");
  c.device = str_arg(device, "device");
  c.precision = str_arg(precision, "precision");
  c.embree_layout = str_arg(embree_layout, "embree_layout");
  c.isa = str_arg(isa, "isa");
  c.instancing = str_arg(instancing, "instancing");
  rs.seed = uint64_arg(seed, "seed");
  rs.paths_in_flight = uint64_arg(paths_in_flight, "paths_in_flight");
  rs.threads = int(int_arg(threads, "threads", std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
  rs.watertight = bool_arg(watertight, "watertight");
  rs.variance = bool_arg(variance, "variance");
  const bool prof = bool_arg(profile, "profile");
  rs.progress = false;

  try {
    apply_choices(c, rs);  // the CLI's parsing (run::render validates)
  } catch (const InputError& e) {
    throw py::value_error(python_terms(e.what()));
  }
  Film film;  // sized and begun by run::render, after it has validated the settings
  RunReport report;
  std::vector<float> mean, var;
  try {
    py::gil_scoped_release release;  // pure C++ from here: no Python object is touched
    run::render(s.scene(), rs, film, report, {.profile = prof});
    mean = film.mean();
    if (rs.variance) var = film.variance_of_mean();
  } catch (const InputError& e) {  // e.g. device='gpu' in a build without CUDA
    throw py::value_error(python_terms(e.what()));
  }
  py::tuple out(rs.variance ? 3 : 2);
  out[0] = image(mean, rs.width, rs.height);
  out[1] = to_python(report.to_json());
  if (rs.variance) out[2] = image(var, rs.width, rs.height);
  return out;
}

}  // namespace

std::string python_terms(const std::string& m) {
  std::string out;
  for (size_t i = 0; i < m.size(); ++i) {
    const bool option = m.compare(i, 2, "--") == 0 && i + 2 < m.size() && std::islower(uint8_t(m[i + 2])) &&
                        (i == 0 || !std::isalnum(uint8_t(m[i - 1])));
    if (!option) {
      out += m[i];
      continue;
    }
    for (i += 2; i < m.size() && (std::islower(uint8_t(m[i])) || m[i] == '-'); ++i) out += m[i] == '-' ? '_' : m[i];
    --i;
  }
  return out;
}

void def_render(py::module_& m) {
  m.def("gpu_available", [] {
    std::string why;
    const bool yes = run::gpu_available(&why);
    return py::make_tuple(yes, why);
  }, "(True, '') when render(device='gpu') can run here, else (False, the reason).");
  m.def("render", &render, py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("spp"), py::kw_only(),
        py::arg("bounces") = py::none(), py::arg("converged") = false, py::arg("rr") = false,
        py::arg("sampling") = "nee", py::arg("strategy") = "pixel", py::arg("device") = "cpu",
        py::arg("precision") = "float", py::arg("embree_layout") = "auto", py::arg("isa") = "auto",
        py::arg("instancing") = "auto", py::arg("seed") = 0,
        py::arg("paths_in_flight") = 0, py::arg("threads") = 0, py::arg("watertight") = true,
        py::arg("variance") = false, py::arg("profile") = false,
        "Renders `scene` as `pathbench render` does, with the same options as keywords (--embree-layout is\n"
        "embree_layout, ...; bounces defaults to 2; converged=True: unbounded paths ended by Russian roulette).\n"
        "Returns (image, report): image float32 (height, width, 3), row 0 at the top; report the dict of\n"
        "`pathbench render --report`. variance=True adds a third item, the variance of each pixel's mean.\n"
        "TypeError for an argument of the wrong type, ValueError for a value the CLI refuses too.");
}

}  // namespace pb::python
