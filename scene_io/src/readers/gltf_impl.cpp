// tinygltf's implementation, compiled here (with gltf_config.h's settings) so that it
// is the same in every build, fuzz builds instrument it, and no shared library is needed.
// <fstream>: its writer uses std::ofstream even without a file system (TINYGLTF_NO_FS).
#include <fstream>
#define TINYGLTF_IMPLEMENTATION
#include "readers/gltf_config.h"
