#pragma once
// The block sparsity of the nodal operators: for every node in [lo, hi) (local numbers), the
// sorted nodes sharing a cell with it, itself included, as compressed rows.
#include <cstddef>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"

namespace naris::ns {

struct NodeGraph {
  std::vector<std::size_t>
      start;  // row r's neighbours: column[start[r]] … column[start[r + 1] − 1]
  std::vector<NodeId> column;
};

NodeGraph node_graph(const HybridMesh& mesh, NodeId lo, NodeId hi);

// The distributed matrix of four unknowns per node over `comm`: this rank's rows are its owned
// nodes' (`numbering`), in 4×4 blocks, preallocated exactly from the cells of its piece `mesh`;
// type `type` unless the options under `prefix` say otherwise. An entry outside that pattern is
// an error.
petsc::Matrix block_matrix(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                           MPI_Comm comm, MatType type, const std::string& prefix);

}  // namespace naris::ns
