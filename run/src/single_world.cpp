// The one-rank world of a build without MPI (PATHBENCH_MPI=OFF or MPI not found): every
// collective is the identity, the dispenser hands the whole frame to its one rank.
#include <unistd.h>

#include <climits>
#include <cstdio>

#include "pathbench/run/world.h"

namespace pb::run {

World::World() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) == 0) host_ = name;
  // Started by mpirun all the same: say so once, rather than render N whole frames silently.
  if (launcher_rank() >= 0)
    std::fputs("pathbench: warning: started by an MPI launcher, but this build has no MPI (configure with "
               "-DPATHBENCH_MPI=ON and libopenmpi-dev): every process renders the whole frame on its own\n",
               stderr);
}

World& World::get() {
  static World w;
  return w;
}

RankFailure World::agree(const RankFailure& mine) { return mine; }
std::vector<std::string> World::all(const std::string& mine) { return {mine}; }
std::vector<std::string> World::gather(const std::string& mine) { return {mine}; }
std::vector<std::string> World::local_all(const std::string& mine) { return {mine}; }
void World::barrier() {}
std::string World::announce(const std::string& message) { return message; }
void World::reduce_film(Film&) {}
void World::reduce_film_rows(Film&, const std::vector<RowRange>&) {}
void World::send_film_rows(Film&, const std::vector<RowRange>&, const std::vector<int>&) {}
bool World::can_dispense() const { return true; }
int World::end(int code) { return code; }  // no MPI: nothing to end

struct SampleDispenser::Impl {
  uint64_t units, next = 0;
};
SampleDispenser::SampleDispenser(World&, uint64_t units, const std::vector<double>&, uint32_t, uint32_t) : impl_(std::make_unique<Impl>(Impl{units})) {}
SampleDispenser::~SampleDispenser() = default;
UnitRange SampleDispenser::next(double, uint64_t) {
  const UnitRange s{impl_->next, impl_->units - impl_->next};
  impl_->next = impl_->units;
  return s;
}
void SampleDispenser::abort() { impl_->next = impl_->units; }
void SampleDispenser::start() {}
void SampleDispenser::finish() {}
std::vector<int> SampleDispenser::ranks_granted() const { return {}; }
uint64_t SampleDispenser::chunks_granted() const { return impl_->next > 0 ? 1 : 0; }

}  // namespace pb::run
