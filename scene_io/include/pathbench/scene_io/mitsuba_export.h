#pragma once
// A loaded Scene as a Mitsuba 3 scene (scene.xml and one binary PLY per material in
// `dir`): each material as the Mitsuba plugin pathbench's BSDF of that kind is defined as,
// emitters as area lights, the camera as a perspective sensor, the settings' size and
// bounces as film and path max_depth. The one Mitsuba exporter (the reverse of
// readers/mitsuba_*.cpp): `pathbench crosscheck`, the Python module's export_mitsuba and
// through it tools/mitsuba_scene.py (accuracy references, mitsuba_speed) use it.
#include <string>

#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb {

// Returns the path of the XML file written.
std::string write_mitsuba_scene(const Scene& scene, const RenderSettings& settings, const std::string& dir);

}  // namespace pb
