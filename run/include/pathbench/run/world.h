#pragma once
// The ranks of this process's run (issue 13): MPI's world when pathbench was built with
// MPI (PATHBENCH_MPI) and started by mpirun, otherwise one rank. Two implementations of
// the same class: run/src/mpi_world.cpp (MPI) and run/src/single_world.cpp (one rank), so
// nothing above this header knows whether MPI exists. Only the run layer's rank render
// (ranks_render.h), the process's entry and exit (app/main.cpp, bench/bench_main.cpp)
// and the benchmarks' rank followers (bench/bench_ranks.cpp) use it.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pathbench/common/film.h"
#include "pathbench/run/ranks.h"

namespace pb::run {

// A rank's failure as every rank learns it: which rank, its exit status (2: bad input, 1:
// failed) and its message. rank < 0: none.
struct RankFailure {
  int rank = -1;
  int code = 0;
  std::string message;
  bool failed() const { return rank >= 0; }
};

// Thrown on every rank but the one that prints (rank 0) when some rank failed: rank 0
// has printed the message; the others only exit with the same status.
struct PeerFailure : std::exception {
  explicit PeerFailure(int c) : code(c) {}
  int code;
  const char* what() const noexcept override { return "another rank failed (rank 0 printed why)"; }
};

class World {
 public:
  // The process's world; the first call starts MPI when this build has it and mpirun (or
  // another PMI launcher) started the process.
  static World& get();

  bool mpi() const { return mpi_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  int local_rank() const { return local_rank_; }  // among the ranks on this node
  int local_size() const { return local_size_; }
  const std::string& host() const { return host_; }
  bool root() const { return rank_ == 0; }

  // Collective: every rank gives its own failure (or none); all get the lowest failing
  // rank's, the same on every rank.
  RankFailure agree(const RankFailure& mine);
  // Collective: every rank's string, in rank order, on every rank (all) or on rank 0
  // only (gather; empty elsewhere). Within this node only: local_all.
  std::vector<std::string> all(const std::string& mine);
  std::vector<std::string> gather(const std::string& mine);
  std::vector<std::string> local_all(const std::string& mine);
  void barrier();
  // Collective: rank 0's `message` on every rank (the others' argument is ignored).
  // Ranks waiting for rank 0 sleep between polls (1 ms) instead of spinning a core, so
  // that work rank 0 does alone meanwhile (a benchmark of its own) is not slowed.
  std::string announce(const std::string& message);
  // Collective: adds every rank's film into rank 0's, exactly (64-bit integer sums,
  // MPI_Reduce over MPI_INT64_T; the rules of reduce_film: same size, scale and variance,
  // overflow refused with std::overflow_error on rank 0). Other ranks' films are left as
  // they were. The variance sums (doubles) are summed in MPI's order, not bit for bit.
  void reduce_film(Film& film);
  // Collective: the same for dynamic chunks, where each rank traced bands of rows (`mine`,
  // merged): every other rank sends rank 0 its rows alone, which rank 0 adds (checked; an
  // overflow throws std::overflow_error on rank 0 after every rank's rows arrived).
  // Sums and counts are exact, so the film equals reduce_film's.
  void reduce_film_rows(Film& film, const std::vector<RowRange>& mine);
  // Not collective: the same where rank 0 knows which ranks hold rows (dynamic chunks: the
  // dispenser's grants). Each other rank with rows sends them (its film's size, scale and
  // variance with them), a rank without rows does nothing at all, and rank 0 receives from
  // `senders` (its argument alone counts) only: a CPU rank that traced nothing beside a GPU
  // costs the frame no collective (issue 30). The rules and the film are reduce_film_rows's.
  void send_film_rows(Film& film, const std::vector<RowRange>& mine, const std::vector<int>& senders);
  // Whether rank 0 can serve a SampleDispenser from a thread (MPI gave at least
  // MPI_THREAD_SERIALIZED); otherwise ranks split the samples statically.
  bool can_dispense() const;

  // Ends the process's part in the run: MPI_Finalize, or MPI_Abort with `code` where this
  // rank fails alone (a failure the other ranks have not agreed on would leave them
  // waiting). Returns `code`. Called once, by main; nothing where no World was made.
  static int end(int code);

 private:
  World();
  bool mpi_ = false;
  int rank_ = 0, size_ = 1, local_rank_ = 0, local_size_ = 1;
  std::string host_;
  bool agreed_failure_ = false;
  bool threads_ok_ = false;
};

// This process's rank as an MPI launcher (mpirun, srun, MPICH's hydra) set it in the
// environment, or -1 when no launcher started it. Read without starting MPI: World uses
// it to decide whether to, and `pathbench bench` (app/) for the child that joins the run.
int launcher_rank();

// Dynamic balancing: ranks take chunks of the frame's units (UnitRange, ranks.h: row-major
// rows x samples) from one counter held by rank 0, which answers the other ranks from a
// thread of its own while it renders. A chunk's size follows the asking rank's measured
// rate (its units per second), so a GPU and a CPU rank finish together (chunk_size).
// Every rank constructs it and calls finish(); next() and abort() are per rank.
class SampleDispenser {
 public:
  // `units`: the frame's (rows x spp). `rates`: every rank's units per second as measured
  // before the frame (a probe chunk each, RankTracer::calibrate), in rank order, or empty:
  // then the first grants are probes. A rank whose chunk would outlast the frame's
  // projected end (what is left / the ranks' total rate) gets none, unless it is the
  // fastest: a slow rank never holds the frame up.
  // `spp` and `batch`: every chunk starts and ends where a batch of `batch` samples starts
  // (batch_start_at_or_after, ranks.h: kSampleBatch for CPU ranks), or at the frame's end.
  SampleDispenser(World& world, uint64_t units, const std::vector<double>& rates = {}, uint32_t spp = 1,
                  uint32_t batch = 1);
  ~SampleDispenser();
  SampleDispenser(const SampleDispenser&) = delete;
  SampleDispenser& operator=(const SampleDispenser&) = delete;
  // The next chunk for this rank; count 0 when the frame is handed out (or aborted).
  // `rate`: this rank's units per second in its last chunk (0: not measured yet);
  // `probe`: the chunk it wants while its rate is unknown, and its smallest chunk (a GPU
  // needs a larger one than a CPU: a small chunk leaves most of a GPU idle).
  UnitRange next(double rate, uint64_t probe);
  // This rank failed: hand out nothing more, so every rank reaches the next agreement
  // within one chunk.
  void abort();
  // Rank 0's server starts answering here, not when constructed: constructed before the
  // frame's clock (its thread started then), started after the ranks' common start (the
  // thread calls MPI only from here on, so that a world of MPI_THREAD_SERIALIZED never has
  // two threads in MPI). Idempotent; next() starts it too.
  void start();
  // Collective (rank 0 waits for every rank's last request).
  void finish();
  uint64_t chunks_granted() const;  // rank 0: chunks handed out in all
  std::vector<int> ranks_granted() const;  // rank 0: the other ranks granted any units, ascending
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// The grant rule alone (tested in every build): `remaining` units left, a rank of rate
// `rate` among ranks of total rate `total_rate` (rates of ranks not measured yet counted
// as the mean of the measured ones by the caller); `probe` units while its rate is
// unknown, and never less than that (the last crumbs go to whoever asks first).
// A rank of at least kDominantShare of the total rate gets all that is left.
uint64_t chunk_size(uint64_t remaining, uint64_t probe, double rate, double total_rate);
constexpr double kDominantShare = 0.98;

}  // namespace pb::run
