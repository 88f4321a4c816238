// A build without NCCL (PATHBENCH_NCCL=OFF or not found): GPU ranks' films go through MPI.
#include "gpu_reduce.h"

namespace pb::run {

GpuReduction prepare_gpu_reduction(World&, bool, int) {
  return {false, -1, "mpi", "this build has no NCCL (configure with -DPATHBENCH_NCCL=ON and NCCL installed)", ""};
}
void warm_gpu_reduction(const GpuReduction&, DeviceFilm*) {}
bool reduce_gpu_films(World&, const GpuReduction&, DeviceFilm*, double&, double&) { return false; }
PinnedFilm::PinnedFilm(Film&, bool) {}
PinnedFilm::~PinnedFilm() = default;

}  // namespace pb::run
