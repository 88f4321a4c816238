// The MPI world (built when PATHBENCH_MPI finds MPI): started on first use when a PMI
// launcher (mpirun) started this process, one rank otherwise. Collectives for the rank
// render: failure agreement and string exchange (the film reduction: mpi_film_reduce.cpp).
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
