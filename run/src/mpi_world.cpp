// The MPI world (built when PATHBENCH_MPI finds MPI): started on first use when a PMI
// launcher (mpirun) started this process, one rank otherwise. Collectives for the rank
// render: failure agreement, string exchange, and the exact film reduction.
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <stdexcept>

#include <fmt/core.h>

#include "mpi_detail.h"
#include "pathbench/run/world.h"

namespace pb::run {

namespace {
World* g_world = nullptr;
MPI_Comm g_local = MPI_COMM_NULL, g_chunks = MPI_COMM_NULL;


// A sum no film holds (|sum| < 2^62 + 2^62): the checked reduction's "overflowed", sticky.
constexpr int64_t kOverflowed = INT64_MIN;
void checked_sum(void* in, void* inout, int* len, MPI_Datatype*) {
  const int64_t* a = static_cast<const int64_t*>(in);
  int64_t* b = static_cast<int64_t*>(inout);
  for (int i = 0; i < *len; ++i)
    if (a[i] == kOverflowed || b[i] == kOverflowed || __builtin_add_overflow(a[i], b[i], &b[i])) b[i] = kOverflowed;
}

// MPI counts are int: reduce long arrays in pieces.
template <class T> void reduce_to_root(T* data, size_t n, MPI_Datatype type, MPI_Op op, bool root) {
  constexpr size_t kPiece = size_t(1) << 28;
  for (size_t at = 0; at < n; at += kPiece) {
    const int count = int(std::min(kPiece, n - at));
    MPI_Reduce(root ? MPI_IN_PLACE : data + at, root ? data + at : nullptr, count, type, op, 0, MPI_COMM_WORLD);
  }
}

std::vector<std::string> exchange(const std::string& mine, MPI_Comm comm, bool gather_only) {
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  const int len = int(mine.size());
  std::vector<int> lens(size), offsets(size);
  if (gather_only) MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, comm);
  else MPI_Allgather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, comm);
  int total = 0;
  for (int i = 0; i < size; ++i) offsets[i] = total, total += lens[i];
  std::string all(size_t(total), '\0');
  if (gather_only) MPI_Gatherv(mine.data(), len, MPI_CHAR, all.data(), lens.data(), offsets.data(), MPI_CHAR, 0, comm);
  else MPI_Allgatherv(mine.data(), len, MPI_CHAR, all.data(), lens.data(), offsets.data(), MPI_CHAR, comm);
  if (gather_only && rank != 0) return {};
  std::vector<std::string> out;
  for (int i = 0; i < size; ++i) out.push_back(all.substr(size_t(offsets[i]), size_t(lens[i])));
  return out;
}
}  // namespace

MPI_Comm mpi_detail::chunk_comm() { return g_chunks; }

World::World() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) == 0) host_ = name;
  if (launcher_rank() < 0) return;  // not started by mpirun or another PMI launcher
  int provided = MPI_THREAD_SINGLE;
  // Rank 0's dispenser thread makes MPI calls while the main thread renders (and makes
  // none): SERIALIZED is enough, MULTIPLE is asked for.
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_MULTIPLE, &provided);
  mpi_ = true;
  threads_ok_ = provided >= MPI_THREAD_SERIALIZED;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &g_local);
  MPI_Comm_rank(g_local, &local_rank_);
  MPI_Comm_size(g_local, &local_size_);
  MPI_Comm_dup(MPI_COMM_WORLD, &g_chunks);
}

World& World::get() {
  static World w;
  g_world = &w;
  return w;
}

RankFailure World::agree(const RankFailure& mine) {
  if (!mpi_) return mine;
  int who = mine.failed() ? rank_ : size_;
  MPI_Allreduce(MPI_IN_PLACE, &who, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (who == size_) return {};
  int head[2] = {mine.code, int(mine.message.size())};
  MPI_Bcast(head, 2, MPI_INT, who, MPI_COMM_WORLD);
  std::string message = mine.message;
  message.resize(size_t(head[1]));
  MPI_Bcast(message.data(), head[1], MPI_CHAR, who, MPI_COMM_WORLD);
  agreed_failure_ = true;
  return {who, head[0], message};
}

std::vector<std::string> World::all(const std::string& mine) {
  return mpi_ ? exchange(mine, MPI_COMM_WORLD, false) : std::vector<std::string>{mine};
}
std::vector<std::string> World::gather(const std::string& mine) {
  return mpi_ ? exchange(mine, MPI_COMM_WORLD, true) : std::vector<std::string>{mine};
}
std::vector<std::string> World::local_all(const std::string& mine) {
  return mpi_ ? exchange(mine, g_local, false) : std::vector<std::string>{mine};
}
void World::barrier() {
  if (mpi_) MPI_Barrier(MPI_COMM_WORLD);
}
std::string World::announce(const std::string& message) {
  if (!mpi_ || size_ == 1) return message;
  uint64_t len = root() ? message.size() : 0;
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Ibcast(&len, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD, &request);
  const timespec step{0, 1'000'000};
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) break;
    if (!root()) ::nanosleep(&step, nullptr);
  }
  // Announcements are short (a benchmark's name); MPI counts are int.
  if (len > uint64_t(INT_MAX)) throw std::length_error("World::announce: message too long");
  std::string out = root() ? message : std::string(size_t(len), '\0');
  MPI_Bcast(out.data(), int(len), MPI_CHAR, 0, MPI_COMM_WORLD);
  return out;
}
bool World::can_dispense() const { return !mpi_ || threads_ok_; }

void World::reduce_film(Film& film) {
  if (!mpi_ || size_ == 1) return;
  // reduce_film's rules, checked on every rank alike (so that all throw or none does).
  const std::string shape = fmt::format("{}x{} scale {:a} variance {}", film.width(), film.height(), film.scale(),
                                        film.has_variance());
  for (const std::string& other : all(shape))
    if (other != shape)
      throw std::invalid_argument(fmt::format("reduce_film: the ranks' films differ ({} vs {})", shape, other));
  // MPI_SUM cannot overflow where the ranks' largest |sums| add up below 2^63 (every
  // partial sum is bounded by that); otherwise a checked sum marks overflowed pixels.
  uint64_t largest = 0;
  for (int64_t v : film.raw_sums()) largest = std::max(largest, v < 0 ? uint64_t(0) - uint64_t(v) : uint64_t(v));
  std::vector<uint64_t> largest_all(size_t(size_), 0);
  MPI_Allgather(&largest, 1, MPI_UINT64_T, largest_all.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  unsigned __int128 bound = 0;
  for (uint64_t v : largest_all) bound += v;
  const bool safe = bound <= (unsigned __int128)INT64_MAX;
  MPI_Op checked = MPI_OP_NULL;
  if (!safe) MPI_Op_create(checked_sum, 1, &checked);
  reduce_to_root(film.raw_sums().data(), film.raw_sums().size(), MPI_INT64_T, safe ? MPI_SUM : checked, root());
  if (!safe) MPI_Op_free(&checked);
  // Counts: every sample index of the frame is traced by one rank, so they add up to spp.
  reduce_to_root(film.counts().data(), film.counts().size(), MPI_UINT32_T, MPI_SUM, root());
  if (film.has_variance()) reduce_to_root(film.raw_sum_sq().data(), film.raw_sum_sq().size(), MPI_DOUBLE, MPI_SUM, root());
  if (!safe && root())
    for (int64_t v : film.raw_sums())
      if (v == kOverflowed) throw std::overflow_error("reduce_film: a pixel sum overflows");
}

int World::end(int code) {
  if (!g_world || !g_world->mpi_) return code;
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) return code;
  // A failure only this rank knows of: the others may be waiting in a collective for it.
  if (code != 0 && !g_world->agreed_failure_) MPI_Abort(MPI_COMM_WORLD, code);
  if (g_chunks != MPI_COMM_NULL) MPI_Comm_free(&g_chunks);
  if (g_local != MPI_COMM_NULL) MPI_Comm_free(&g_local);
  MPI_Finalize();
  return code;
}

}  // namespace pb::run
