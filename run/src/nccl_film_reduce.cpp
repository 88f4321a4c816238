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
#include "pathbench/common/errors.h"
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
  // The banded reduction's receive buffer on the root (sums, counts, variance sums).
  char* recv = nullptr;
  size_t recv_bytes = 0;
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
  const char* bands_env = std::getenv("PATHBENCH_REDUCE_BANDS");
  const std::string mine =
      fmt::format("{} {}/{} {}|{}", gpu ? 1 : 0, w.host(), bus, env ? env : "", bands_env ? bands_env : "");
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
  const std::string last = all[0].substr(all[0].rfind(' ') + 1);  // rank 0's "PATHBENCH_FILM_REDUCE|..._BANDS"
  const std::string asked = last.substr(0, last.find('|'));
  const std::string bands = last.substr(last.find('|') + 1);
  if (!bands.empty() && bands != "auto") {
    char* end = nullptr;
    const long n = std::strtol(bands.c_str(), &end, 10);
    if (*end != '\0' || n < 1 || n > 64)
      throw InputError(fmt::format("PATHBENCH_REDUCE_BANDS='{}': expected auto or a band count 1..64", bands));
    r.bands_asked = int(n);
  }
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

namespace {
// The overflow bound (collective over every rank): every partial sum of the GPU ranks' films
// stays below the sum of the ranks' largest |sums|; true where that is below 2^63 (every rank
// sees the same values, so all agree).
bool films_cannot_overflow(World& w, DeviceFilm* film) {
  const uint64_t largest = film ? film->max_abs_sum() : 0;
  std::vector<uint64_t> all(size_t(w.size()), 0);
  MPI_Allgather(&largest, 1, MPI_UINT64_T, all.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  return sums_cannot_overflow(all);
}

// Where the banded reduction's receive buffer holds a film of `pixels` (variance or not).
struct RecvLayout {
  size_t sums, counts, sum_sq, bytes;
  RecvLayout(uint64_t pixels, bool variance) {
    sums = 0;
    counts = pixels * 3 * sizeof(int64_t);
    sum_sq = (counts + pixels * sizeof(uint32_t) + 15) / 16 * 16;
    bytes = sum_sq + (variance ? pixels * 3 * sizeof(double) : 0);
  }
};
}  // namespace

void warm_gpu_reduction(const GpuReduction& r, DeviceFilm* film, bool band_root) {
  if (!r.nccl || !current || !film) return;
  (void)film->max_abs_sum();
  nccl_reduce(*film);  // zeros onto zeros: the root's film stays cleared
  if (!band_root) return;
  const DeviceFilm::Arrays a = film->arrays();
  const RecvLayout at(a.pixels, a.sum_sq != nullptr);
  if (current->recv_bytes >= at.bytes) return;
  if (current->recv) cuda_check(cudaFree(current->recv), "cudaFree (the banded reduction's receive buffer)");
  current->recv = nullptr;
  current->recv_bytes = 0;
  void* p = nullptr;
  cuda_check(cudaMalloc(&p, at.bytes), "cudaMalloc (the banded reduction's receive buffer: a second film)");
  current->recv = static_cast<char*>(p);
  current->recv_bytes = at.bytes;
}

void reduce_gpu_band(const GpuReduction& r, DeviceFilm* film, Film& host, bool root, uint32_t first_row,
                     uint32_t rows) {
  if (!r.nccl || !current || !film || rows == 0) return;
  const DeviceFilm::Arrays a = film->arrays();
  const RecvLayout at(a.pixels, a.sum_sq != nullptr);
  if (uint64_t(first_row) + rows > host.height() || a.pixels != host.pixels())
    throw std::logic_error("reduce_gpu_band: the band lies outside the film");
  if (root && current->recv_bytes < at.bytes)
    throw std::logic_error("reduce_gpu_band: no receive buffer (warm_gpu_reduction with band_root)");
  const size_t px0 = size_t(first_row) * host.width(), px = size_t(rows) * host.width();
  auto* sums = static_cast<int64_t*>(a.sums) + px0 * 3;
  auto* counts = static_cast<uint32_t*>(a.counts) + px0;
  auto* sq = a.sum_sq ? static_cast<double*>(a.sum_sq) + px0 * 3 : nullptr;
  // The root receives into its second film (out of place); the others' receive buffers are unused.
  auto* rsums = root ? reinterpret_cast<int64_t*>(current->recv + at.sums) + px0 * 3 : sums;
  auto* rcounts = root ? reinterpret_cast<uint32_t*>(current->recv + at.counts) + px0 : counts;
  auto* rsq = root && sq ? reinterpret_cast<double*>(current->recv + at.sum_sq) + px0 * 3 : sq;
  cudaStream_t st = current->stream;
  nccl_check(ncclGroupStart(), "ncclGroupStart");
  nccl_check(ncclReduce(sums, rsums, px * 3, ncclInt64, ncclSum, 0, current->nccl, st), "ncclReduce (a band's sums)");
  nccl_check(ncclReduce(counts, rcounts, px, ncclUint32, ncclSum, 0, current->nccl, st), "ncclReduce (a band's counts)");
  if (sq) nccl_check(ncclReduce(sq, rsq, px * 3, ncclFloat64, ncclSum, 0, current->nccl, st), "ncclReduce (a band's variance sums)");
  nccl_check(ncclGroupEnd(), "ncclGroupEnd");
  if (!root) return;
  cuda_check(cudaMemcpyAsync(host.raw_sums().data() + px0 * 3, rsums, px * 3 * sizeof(int64_t), cudaMemcpyDeviceToHost, st),
             "cudaMemcpyAsync (a band's sums)");
  cuda_check(cudaMemcpyAsync(host.counts().data() + px0, rcounts, px * sizeof(uint32_t), cudaMemcpyDeviceToHost, st),
             "cudaMemcpyAsync (a band's counts)");
  if (sq && host.has_variance())
    cuda_check(cudaMemcpyAsync(host.raw_sum_sq().data() + px0 * 3, rsq, px * 3 * sizeof(double), cudaMemcpyDeviceToHost, st),
               "cudaMemcpyAsync (a band's variance sums)");
}

bool finish_gpu_bands(World& w, const GpuReduction& r, DeviceFilm* film, double& bound_seconds,
                      double& wait_seconds) {
  using Clock = std::chrono::steady_clock;
  bound_seconds = wait_seconds = 0;
  if (!r.nccl || !current) return false;
  // The bound first (its kernel runs beside the last band's reduction, on another stream):
  // the banded sums were added unchecked, so they count only where no partial sum can overflow.
  const auto t0 = Clock::now();
  const bool safe = films_cannot_overflow(w, film);
  const auto t1 = Clock::now();
  bound_seconds = std::chrono::duration<double>(t1 - t0).count();
  if (film) cuda_check(cudaStreamSynchronize(current->stream), "cudaStreamSynchronize (the bands' reductions)");
  wait_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return safe;
}

bool reduce_gpu_films(World& w, const GpuReduction& r, DeviceFilm* film, double& bound_seconds,
                      double& nccl_seconds) {
  using Clock = std::chrono::steady_clock;
  bound_seconds = nccl_seconds = 0;
  if (!r.nccl || !current) return false;
  const auto t0 = Clock::now();
  const bool safe = films_cannot_overflow(w, film);
  bound_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!safe) return false;
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
