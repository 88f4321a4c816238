#pragma once
// The GPU's part of the machine fingerprint (plain C++ header): name, driver, CUDA
// versions, SM count, clocks, power limit, ECC and MIG state, and `gpu_id`, a hash of
// the identity fields (not current clocks). Clocks, power limit and MIG state come from
// NVML, opened at run time (libnvidia-ml.so.1 ships with the driver); where it is
// missing those fields are null and "nvml" says why.
#include <nlohmann/json.hpp>

namespace pb::gpu {

// Throws InputError when there is no usable device (as device_info()).
nlohmann::json device_fingerprint();

}  // namespace pb::gpu
