#pragma once
// `pathbench crosscheck SCENE`: renders a scene with pathbench (CPU, and GPU where
// present) and with Mitsuba 3 (the scene exported by pathbench/scene_io/mitsuba_export.h,
// or a Mitsuba XML scene read by Mitsuba itself), and judges each pathbench image against
// Mitsuba's with the per-pixel z-test the test suite uses (tools/crosscheck.py): a verdict and
// difference images. Exit status: 0 same up to noise, 1 different, 2 bad input (then
// nothing this run wrote is left in --out-dir), 3 an internal failure.
#include <CLI/CLI.hpp>

#include <string>

namespace pb::app {

struct CrosscheckOptions {
  std::string scene;
  std::string mitsuba_xml;  // the reference scene; default: SCENE itself if .xml, else exported
  std::string out_dir = "pathbench-out/crosscheck";
  std::string device = "all";
  std::string variant = "scalar_rgb";
  unsigned width = 0, height = 0;  // 0: the scene file's film, else 64 x 48
  unsigned spp = 64;
  unsigned mitsuba_spp_factor = 4;
  int bounces = -2;  // given only when bounces_option->count(); else the scene file's max_depth, else 2
  CLI::Option* bounces_option = nullptr;
  int threads = 0;
  bool strict = false;
};

void add_crosscheck_options(CLI::App& cmd, CrosscheckOptions& o);
int run_crosscheck(CrosscheckOptions& o);

}  // namespace pb::app
