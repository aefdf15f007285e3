#pragma once
// Fields and conditions between the whole mesh and the ranks' pieces (parallel/partition.h).
#include <mpi.h>

#include "solver/ns/flow_field.h"
#include "solver/parallel/partition.h"

namespace naris::ns {

// A whole field's values on a piece, and conditions on the whole mesh as the piece's.
FlowField local_field(const FlowField& whole, const parallel::NodeNumbering& numbering);
DirichletConditions local_conditions(const DirichletConditions& whole,
                                     const parallel::NodeNumbering& numbering);
// The whole field from the owned nodes of every rank's piece: on every rank (`root` < 0) or on
// rank `root` only (the others get an empty field). Collective over `comm`.
FlowField gather_field(const FlowField& local, const parallel::NodeNumbering& numbering,
                       MPI_Comm comm, int root = -1);

}  // namespace naris::ns
