#pragma once
// The CUDA tracer's kernels live in pb::gpu and name the BVH library's types and
// traversals (pb::bvh: BvhView, traverse, GpuBvhLayout...) unqualified, as they did when
// that library was part of gpu/. This directive is gpu/'s own: code outside gpu/ says bvh::.
namespace pb::bvh {}
namespace pb::gpu {
using namespace pb::bvh;
}  // namespace pb::gpu
