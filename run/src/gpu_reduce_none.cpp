// A build without NCCL (PATHBENCH_NCCL=OFF or not found): GPU ranks' films go through MPI.
#include "gpu_reduce.h"

namespace pb::run {

GpuReduction prepare_gpu_reduction(World&, bool, int) {
  return {false, -1, "mpi", "this build has no NCCL (configure with -DPATHBENCH_NCCL=ON and NCCL installed)", ""};
}
void warm_gpu_reduction(const GpuReduction&, DeviceFilm*, bool) {}
void reduce_gpu_band(const GpuReduction&, DeviceFilm*, Film&, bool, uint32_t, uint32_t) {}
bool finish_gpu_bands(World&, const GpuReduction&, DeviceFilm*, double&, double&) { return false; }
bool reduce_gpu_films(World&, const GpuReduction&, DeviceFilm*, double&, double&) { return false; }
PinnedFilm::PinnedFilm(Film&, bool) {}
PinnedFilm::~PinnedFilm() = default;

}  // namespace pb::run
