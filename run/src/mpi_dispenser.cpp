// Dynamic balancing over MPI: rank 0 holds the frame's sample counter and answers the
// other ranks' requests from a thread of its own (polling, so that it takes no core from
// rank 0's render); rank 0 itself takes chunks under the same lock. Messages go over a
// communicator of their own (mpi_detail::chunk_comm).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "mpi_detail.h"
#include "pathbench/run/world.h"

namespace pb::run {

namespace {
constexpr int kAsk = 1, kGrant = 2, kQuit = 3;
}

struct SampleDispenser::Impl {
  Impl(World& w, uint64_t u, uint32_t s, uint32_t b) : world(w), units(u), spp(s), batch(b) {}
  World& world;
  uint64_t units;
  uint32_t spp, batch;  // chunks end where a batch starts (batch_start_at_or_after)
  MPI_Comm comm = mpi_detail::chunk_comm();
  // Rank 0's counter, guarded by `m` (its own render and the server thread take from it).
  std::mutex m;
  uint64_t next = 0;
  bool aborted = false;
  uint64_t chunks = 0;
  std::vector<double> rates;
  // Ranks whose rate is not measured yet: the units of their outstanding chunk and when
  // it was granted. A rank still busy with it after t seconds runs at most units / t:
  // that bound stands for its rate (not the others' mean), so a dominant rank (a GPU
  // beside a slow CPU rank) is known as such from its own first chunk.
  std::vector<bool> finished;  // ranks that have had their last grant (count 0)
  std::vector<uint64_t> pending;
  std::vector<std::chrono::steady_clock::time_point> granted_at;
  std::vector<uint64_t> granted_units;  // per rank: units handed out (ranks_granted)
  std::thread server;
  std::atomic<bool> go{false};  // the server may call MPI (start())
  bool never_started = false;    // destroyed before start(): the server ends without MPI
  bool done = false;  // this rank has had its last grant (or quit)

  UnitRange grant(int rank, double rate, uint64_t probe) {
    std::lock_guard<std::mutex> lock(m);
    if (rate > 0) rates[size_t(rank)] = rate;
    if (aborted) return {next, 0};
    const auto now = std::chrono::steady_clock::now();
    // The total rate: measured ranks' rates, and for the others the bound of their
    // outstanding chunk (pending); ranks that have not asked yet count for nothing.
    double total = 0;
    bool measured = false;
    for (size_t r = 0; r < rates.size(); ++r) {
      if (rates[r] > 0) {
        total += rates[r], measured = true;
      } else if (r != size_t(rank) && pending[r] > 0) {
        const double t = std::chrono::duration<double>(now - granted_at[r]).count();
        total += t > 0 ? double(pending[r]) / t : 0.0;
      }
    }
    if (!measured) total = 0;
    // One rank (no mpirun): the whole frame at once, as the one-rank build does.
    uint64_t count = world.size() == 1 ? units - next : chunk_size(units - next, probe, rates[size_t(rank)], total);
    // A measured rank gets a chunk only if it ends within the frame's projected end, unless
    // it is the fastest of the ranks still taking chunks (who then takes it: the frame is
    // always handed out): a CPU rank beside a GPU never makes the frame longer.
    const double mine = rates[size_t(rank)];
    bool faster_active = false;
    for (size_t r = 0; r < rates.size(); ++r) faster_active |= r != size_t(rank) && !finished[r] && rates[r] > mine;
    if (mine > 0 && total > 0 && count > 0 && faster_active && double(count) / mine > double(units - next) / total)
      count = 0;
    if (count > 0) count = batch_start_at_or_after(next + count, spp, batch, units) - next;
    if (count == 0) finished[size_t(rank)] = true;
    const UnitRange s{next, count};
    next += count;
    granted_units[size_t(rank)] += count;
    if (count) ++chunks;
    if (rates[size_t(rank)] <= 0) pending[size_t(rank)] = count, granted_at[size_t(rank)] = now;
    return s;
  }

  void serve() {
    go.wait(false);  // start(): the thread was made before the frame, MPI is called from here on
    if (never_started) return;
    int finished = 0;  // ranks that have had their last grant or quit
    while (finished < world.size() - 1) {
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm, &flag, &st);
      if (!flag) {
        std::this_thread::sleep_for(std::chrono::microseconds(50));
        continue;
      }
      if (st.MPI_TAG == kAsk) {
        double ask[2] = {0, 0};  // rate, probe
        MPI_Recv(ask, 2, MPI_DOUBLE, st.MPI_SOURCE, kAsk, comm, MPI_STATUS_IGNORE);
        const UnitRange s = grant(st.MPI_SOURCE, ask[0], uint64_t(ask[1]));
        const uint64_t g[2] = {s.first, s.count};
        MPI_Send(g, 2, MPI_UINT64_T, st.MPI_SOURCE, kGrant, comm);
        if (s.count == 0) ++finished;
      } else {
        MPI_Recv(nullptr, 0, MPI_BYTE, st.MPI_SOURCE, kQuit, comm, MPI_STATUS_IGNORE);
        std::lock_guard<std::mutex> lock(m);
        aborted = true;
        ++finished;
      }
    }
  }
};

SampleDispenser::SampleDispenser(World& world, uint64_t units, const std::vector<double>& rates, uint32_t spp,
                                 uint32_t batch)
    : impl_(std::make_unique<Impl>(world, units, std::max(1u, spp), batch)) {
  impl_->rates.assign(size_t(world.size()), 0.0);
  if (rates.size() == impl_->rates.size()) impl_->rates = rates;
  impl_->pending.assign(size_t(world.size()), 0);
  impl_->finished.assign(size_t(world.size()), false);
  impl_->granted_at.resize(size_t(world.size()));
  impl_->granted_units.assign(size_t(world.size()), 0);
  if (world.root() && world.size() > 1) impl_->server = std::thread([this] { impl_->serve(); });
}

SampleDispenser::~SampleDispenser() {
  if (!impl_->go) {  // never started (the frame failed before its start): the thread ends at once
    impl_->never_started = true;
    start();
  }
  if (impl_->server.joinable()) impl_->server.join();
}

void SampleDispenser::start() {
  if (impl_->go.exchange(true)) return;
  impl_->go.notify_all();
}

UnitRange SampleDispenser::next(double rate, uint64_t probe) {
  Impl& d = *impl_;
  start();
  if (d.done) return {0, 0};
  UnitRange s;
  if (d.world.root()) {
    s = d.grant(0, rate, probe);
  } else {
    uint64_t g[2] = {0, 0};
    const double ask[2] = {rate, double(probe)};
    MPI_Send(ask, 2, MPI_DOUBLE, 0, kAsk, d.comm);
    MPI_Recv(g, 2, MPI_UINT64_T, 0, kGrant, d.comm, MPI_STATUS_IGNORE);
    s = {g[0], g[1]};
  }
  if (s.count == 0) d.done = true;
  return s;
}

void SampleDispenser::abort() {
  Impl& d = *impl_;
  if (d.done) return;
  d.done = true;
  if (d.world.root()) {
    std::lock_guard<std::mutex> lock(d.m);
    d.aborted = true;
  } else {
    MPI_Send(nullptr, 0, MPI_BYTE, 0, kQuit, d.comm);
  }
}

void SampleDispenser::finish() {
  start();
  if (impl_->server.joinable()) impl_->server.join();
}

std::vector<int> SampleDispenser::ranks_granted() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  std::vector<int> out;
  for (size_t r = 1; r < impl_->granted_units.size(); ++r)
    if (impl_->granted_units[r] > 0) out.push_back(int(r));
  return out;
}

uint64_t SampleDispenser::chunks_granted() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  return impl_->chunks;
}

}  // namespace pb::run
