#pragma once
// The shared path step (common/path.h) as both GPU strategies drive it: the last-vertex
// shortcut they take alike (gpu_final_vertex, in path_trace.h with the megakernel's
// path loop, which the host can run too), so the pixel megakernel and the wavefront
// stages trace the same rays and give the same film.
#include "pathbench/common/path.h"
#include "pathbench/bvh/path_trace.h"
