#pragma once
// The block sparsity of the nodal operators: for every node in [lo, hi) (local numbers), the
// sorted nodes sharing a cell with it, itself included, as compressed rows.
#include <cstddef>
#include <vector>

#include "hybrid_mesh.h"

namespace naris::ns {

struct NodeGraph {
  std::vector<std::size_t>
      start;  // row r's neighbours: column[start[r]] … column[start[r + 1] − 1]
  std::vector<NodeId> column;
};

NodeGraph node_graph(const HybridMesh& mesh, NodeId lo, NodeId hi);

}  // namespace naris::ns
