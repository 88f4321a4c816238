#pragma once
// The path state parked in shared memory (the pixel megakernels: pixel.cu, pixel_refill.cu):
// each thread's path state and shadow query live in the block's shared memory (25 words a
// thread, an odd stride: no bank conflicts) instead of registers, so that the traversals,
// where the register peak is, run with ~25 registers fewer live.
#include "pathbench/common/path.h"

namespace pb::gpu {

template <class T> struct ParkedPath {
  PathState<T> st;
  ShadowQuery<T> q;
};
static_assert(sizeof(ParkedPath<float>) == 100, "25 words: an odd stride in words");

}  // namespace pb::gpu
