// The pixel-parallel strategy for scenes with mirrors, glass or rough metal: the same
// code as render_pixel.cpp, compiled for every material kind in a translation unit of
// its own (see there why).
#include "pathbench/common/features.h"
#define PB_CPU_KINDS kCompiledMaterialKinds
#include "render_pixel.cpp"
