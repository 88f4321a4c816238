#pragma once
// `pathbench render`: one render to an image and a report.
#include <CLI/CLI.hpp>

#include <string>

#include "pathbench/output/output_file.h"  // write_text_file
#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::app {

struct RenderOptions {
  std::string scene = "paper-cornell";
  RenderSettings settings;
  RenderChoices choices;  // the named options, applied by apply_choices (common/settings.h)
  std::string out, report, variance_out;
  bool profile = false;
  bool quiet = false;
  std::string balance = "auto";  // MPI ranks: auto, static, dynamic (run::Balance)
  bool strict = false;  // what the scene file holds that pathbench does not model is an error
  // The options a scene file's own defaults (Mitsuba's film, sampler, integrator) give
  // way to when they are on the command line.
  struct Given {
    CLI::Option *width = nullptr, *height = nullptr, *spp = nullptr, *bounces = nullptr, *converged = nullptr;
  } given;
};

// The scene file's render defaults for every option not given on the command line,
// with a note naming them.
void apply_scene_defaults(const Scene& scene, RenderOptions& o);

void add_render_options(CLI::App& cmd, RenderOptions& o);
// Turns the parsed strings into settings; throws InputError.
void finish_render_options(RenderOptions& o);
int run_render(RenderOptions& o);

}  // namespace pb::app
