// The GPU ranks' film reduction through NCCL (gpu_reduce.h): built with CUDA, MPI and NCCL.
#include <cuda_runtime.h>
#include <nccl.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>

#include <fmt/core.h>

#include "gpu_reduce.h"
#include "mpi_detail.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/tracer.h"
#include "pathbench/run/world.h"

namespace pb::run {

namespace {
void nccl_check(ncclResult_t r, const char* what) {
  if (r != ncclSuccess && r != ncclInProgress)
    throw std::runtime_error(fmt::format("NCCL: {} failed: {}", what, ncclGetErrorString(r)));
}
void cuda_check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw std::runtime_error(fmt::format("CUDA: {} failed: {}", what, cudaGetErrorString(e)));
}

// One communicator per process and rank layout (the ranks' devices): made once, kept for
// later frames (a benchmark renders many), destroyed at exit.
struct Comm {
  MPI_Comm gpus = MPI_COMM_NULL;  // the GPU ranks
  ncclComm_t nccl = nullptr;
  cudaStream_t stream = nullptr;
};
std::map<std::string, Comm>& comms() {
  static std::map<std::string, Comm> m;
  return m;
}
void destroy_comms() {
  for (auto& [key, c] : comms())
    if (c.nccl) ncclCommDestroy(c.nccl);  // after MPI_Finalize: NCCL needs no MPI for it
  comms().clear();
}
Comm* current = nullptr;

std::string version_string() {
  int v = 0;
  ncclGetVersion(&v);
  return fmt::format("{}.{}.{}", v / 10000, (v / 100) % 100, v % 100);
}
}  // namespace

GpuReduction prepare_gpu_reduction(World& w, bool gpu, int gpu_index) {
  GpuReduction r{false, -1, "mpi", "", version_string()};
  if (!w.mpi() || w.size() == 1) return r;
  // Every rank's (GPU?, node and PCI bus of its GPU): who shares a GPU, and the layout key.
  char bus[64] = "-";
  if (gpu && gpu_index >= 0) cuda_check(cudaDeviceGetPCIBusId(bus, sizeof bus, gpu_index), "cudaDeviceGetPCIBusId");
  const char* env = std::getenv("PATHBENCH_FILM_REDUCE");
  const std::string mine = fmt::format("{} {}/{} {}", gpu ? 1 : 0, w.host(), bus, env ? env : "");
  const std::vector<std::string> all = w.all(mine);
  std::set<std::string> devices;
  int gpus = 0;
  bool shared = false;
  for (size_t i = 0; i < all.size(); ++i) {
    if (all[i][0] != '1') continue;
    if (r.root < 0) r.root = int(i);
    ++gpus;
    shared |= !devices.insert(all[i].substr(2, all[i].rfind(' ') - 2)).second;
  }
  const std::string asked = all[0].substr(all[0].rfind(' ') + 1);  // rank 0's PATHBENCH_FILM_REDUCE
  if (gpus < 2) r.why = "fewer than two GPU ranks";
  else if (asked == "mpi") r.why = "PATHBENCH_FILM_REDUCE=mpi";
  else if (shared) r.why = "two GPU ranks share a GPU (NCCL needs one rank per GPU): MPI";
  if (!r.why.empty()) return r;
  r.nccl = true;
  r.method = "nccl";
  r.why = fmt::format("{} GPU ranks on distinct GPUs: ncclReduce onto rank {}", gpus, r.root);
  std::string key;
  for (const std::string& a : all) key += a + ";";
  auto it = comms().find(key);
  if (it == comms().end()) {
    // Collective over every rank (the split), then over the GPU ranks (id, init).
    Comm c;
    MPI_Comm_split(MPI_COMM_WORLD, gpu ? 0 : MPI_UNDEFINED, w.rank(), &c.gpus);
    if (gpu) {
      int grank = 0, gsize = 0;
      MPI_Comm_rank(c.gpus, &grank);
      MPI_Comm_size(c.gpus, &gsize);
      ncclUniqueId id;
      if (grank == 0) nccl_check(ncclGetUniqueId(&id), "ncclGetUniqueId");
      MPI_Bcast(&id, sizeof id, MPI_BYTE, 0, c.gpus);
      nccl_check(ncclCommInitRank(&c.nccl, gsize, id, grank), "ncclCommInitRank");
      cuda_check(cudaStreamCreateWithFlags(&c.stream, cudaStreamNonBlocking), "cudaStreamCreate");
    }
    if (comms().empty()) std::atexit(destroy_comms);
    it = comms().emplace(key, c).first;
  }
  current = &it->second;
  return r;
}

namespace {
// Adds the GPU ranks' device films onto the GPU communicator's rank 0, in place there.
void nccl_reduce(DeviceFilm& film) {
  const DeviceFilm::Arrays a = film.arrays();
  nccl_check(ncclGroupStart(), "ncclGroupStart");
  nccl_check(ncclReduce(a.sums, a.sums, a.pixels * 3, ncclInt64, ncclSum, 0, current->nccl, current->stream),
             "ncclReduce (sums)");
  nccl_check(ncclReduce(a.counts, a.counts, a.pixels, ncclUint32, ncclSum, 0, current->nccl, current->stream),
             "ncclReduce (counts)");
  if (a.sum_sq)
    nccl_check(ncclReduce(a.sum_sq, a.sum_sq, a.pixels * 3, ncclFloat64, ncclSum, 0, current->nccl, current->stream),
               "ncclReduce (variance sums)");
  nccl_check(ncclGroupEnd(), "ncclGroupEnd");
  cuda_check(cudaStreamSynchronize(current->stream), "cudaStreamSynchronize (NCCL)");
}
}  // namespace

void warm_gpu_reduction(const GpuReduction& r, DeviceFilm* film) {
  if (!r.nccl || !current || !film) return;
  (void)film->max_abs_sum();
  nccl_reduce(*film);  // zeros onto zeros: the root's film stays cleared
}

bool reduce_gpu_films(World& w, const GpuReduction& r, DeviceFilm* film, double& bound_seconds,
                      double& nccl_seconds) {
  using Clock = std::chrono::steady_clock;
  bound_seconds = nccl_seconds = 0;
  if (!r.nccl || !current) return false;
  // The overflow bound: every partial sum stays below the sum of the ranks' largest |sums|.
  const auto t0 = Clock::now();
  uint64_t largest = film ? film->max_abs_sum() : 0;
  std::vector<uint64_t> all(size_t(w.size()), 0);
  MPI_Allgather(&largest, 1, MPI_UINT64_T, all.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  bound_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!sums_cannot_overflow(all)) return false;  // every rank sees the same values
  if (!film) return true;
  const auto t1 = Clock::now();
  // In place on the root (send = receive buffer); the others' receive buffers are unused.
  nccl_reduce(*film);
  nccl_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return true;
}

PinnedFilm::PinnedFilm(Film& film, bool pin) {
  if (!pin) return;
  auto lock = [&](void* p, size_t bytes) {
    if (bytes == 0) return;
    if (cudaHostRegister(p, bytes, cudaHostRegisterDefault) == cudaSuccess) pinned_.push_back(p);
    else (void)cudaGetLastError();  // not fatal: the copy then goes through a bounce buffer
  };
  lock(film.raw_sums().data(), film.raw_sums().size() * sizeof(int64_t));
  lock(film.counts().data(), film.counts().size() * sizeof(uint32_t));
  if (film.has_variance()) lock(film.raw_sum_sq().data(), film.raw_sum_sq().size() * sizeof(double));
}
PinnedFilm::~PinnedFilm() {
  for (void* p : pinned_) cudaHostUnregister(p);
}

}  // namespace pb::run
