// Fuzz builds only (PATHBENCH_FUZZ): tinyobjloader's parser compiled from its header
// with the sanitizers and libFuzzer's coverage, instead of Debian's prebuilt library.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
