#pragma once
// Facts about the CUDA device and its driver, for the report and for the checks before a
// render (the public half, device_available / device_info, is in pathbench/gpu/render.h;
// device_fingerprint in pathbench/gpu/device_facts.h).
#include <string>

namespace pb::gpu {

// The kernel driver's version ("580.159.04"), from /proc on Linux; empty elsewhere.
std::string kernel_driver_version();
// Throws InputError ("--device gpu: ...") when no usable device is present.
void ensure_device();

}  // namespace pb::gpu
