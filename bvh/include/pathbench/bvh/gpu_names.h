#pragma once
// Until issue 33 the BVH library lived in gpu/, in namespace pb::gpu; it is pb::bvh now.
// Code written against the old names (the CUDA tracer, whose kernels live in pb::gpu and
// name BvhView, traverse, ... unqualified; python/src, run/src/rank_tracer.cpp and bench/,
// which say gpu::BvhView, gpu::HostGpuTracer, gpu::GpuBvhLayout) finds them there through
// this one using-directive, so that the move changed no line of theirs but an include.
// New code names pb::bvh; this goes once no caller outside gpu/ says gpu:: for a BVH name.
namespace pb::bvh {}
namespace pb::gpu {
using namespace pb::bvh;
}  // namespace pb::gpu
