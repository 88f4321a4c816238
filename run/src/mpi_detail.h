#pragma once
// What mpi_world.cpp and mpi_dispenser.cpp share: the communicator the dispenser talks
// on (a duplicate of MPI_COMM_WORLD, so its messages never meet a collective's).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

namespace pb::run::mpi_detail {
MPI_Comm chunk_comm();
}  // namespace pb::run::mpi_detail
