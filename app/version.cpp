#include "version.h"

#include <fmt/core.h>

#include "pathbench/common/fingerprint.h"
#include "pathbench/output/image_io.h"
#include "pathbench/common/report.h"

#ifndef PATHBENCH_VERSION
#define PATHBENCH_VERSION "unknown"
#endif

namespace pb::app {

const char* version_number() { return PATHBENCH_VERSION; }

std::string version_text() {
  // The build section of the run fingerprint, so --version and every report agree.
  const nlohmann::json& build = machine_fingerprint()["build"];
  std::string isa;
  for (const auto& a : build.value("isa_compiled", nlohmann::json::array())) isa += (isa.empty() ? "" : ",") + a.get<std::string>();
  std::string text = fmt::format("pathbench {}\ngit revision: {}\n", PATHBENCH_VERSION, git_revision());
  if (build.contains("source_commit")) text += fmt::format("source commit: {}\n", build["source_commit"].get<std::string>());
  text += fmt::format("build: {} {}; flags: {}; isa: {}; cuda: {}; openimageio: {}; extra materials: {}\n",
                      build.value("build_type", "?"), build.value("cmake_compiler", "?"), build.value("cxx_flags", "?"),
                      isa.empty() ? "baseline" : isa, PATHBENCH_HAVE_CUDA ? "on" : "off", image_io_has_oiio() ? "on" : "off",
                      PATHBENCH_EXTRA_MATERIALS ? "on" : "off");
  return text;
}

}  // namespace pb::app
