#include "solver/ns/node_graph.h"

#include <algorithm>

namespace naris::ns {

NodeGraph node_graph(const HybridMesh& mesh, NodeId lo, NodeId hi) {
  const auto rows = static_cast<std::size_t>(hi - lo);
  auto row_of = [&](NodeId a) { return static_cast<std::size_t>(a - lo); };
  auto inside = [&](NodeId a) { return a >= lo && a < hi; };
  // Two passes over the cells: the count of (repeated) neighbours per row, then the lists,
  // sorted and made unique in place — no list per node.
  std::vector<std::size_t> fill(rows + 1, 0);
  auto tally = [&](const auto& cells) {
    for (const auto& c : cells)
      for (NodeId a : c)
        if (inside(a)) fill[row_of(a) + 1] += c.size();
  };
  tally(mesh.tets);
  tally(mesh.pyramids);
  tally(mesh.hexes);
  for (std::size_t r = 0; r < rows; ++r) fill[r + 1] += fill[r];
  std::vector<NodeId> all(fill[rows]);
  std::vector<std::size_t> at(fill.begin(), fill.end() - 1);
  auto place = [&](const auto& cells) {
    for (const auto& c : cells)
      for (NodeId a : c)
        if (inside(a))
          for (NodeId b : c) all[at[row_of(a)]++] = b;
  };
  place(mesh.tets);
  place(mesh.pyramids);
  place(mesh.hexes);
  NodeGraph g;
  g.start.assign(rows + 1, 0);
  g.column.reserve(all.size() / 4);
  for (std::size_t r = 0; r < rows; ++r) {
    const auto first = all.begin() + static_cast<std::ptrdiff_t>(fill[r]),
               last = all.begin() + static_cast<std::ptrdiff_t>(fill[r + 1]);
    std::sort(first, last);
    g.column.insert(g.column.end(), first, std::unique(first, last));
    g.start[r + 1] = g.column.size();
  }
  g.column.shrink_to_fit();
  return g;
}

petsc::Matrix block_matrix(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                           MPI_Comm comm, MatType type, const std::string& prefix) {
  using petsc::check;
  const auto graph = node_graph(mesh, 0, numbering.owned);
  const auto local = static_cast<PetscInt>(numbering.owned);
  const auto n = static_cast<PetscInt>(numbering.global_nodes);
  std::vector<PetscInt> diagonal(static_cast<std::size_t>(local)),
      off_diagonal(static_cast<std::size_t>(local));
  for (std::size_t i = 0; i < diagonal.size(); ++i) {
    const auto first = graph.column.begin() + static_cast<std::ptrdiff_t>(graph.start[i]),
               last = graph.column.begin() + static_cast<std::ptrdiff_t>(graph.start[i + 1]);
    const auto inside = std::count_if(first, last, [&](NodeId j) { return numbering.owns(j); });
    diagonal[i] = static_cast<PetscInt>(inside);
    off_diagonal[i] = static_cast<PetscInt>(last - first) - static_cast<PetscInt>(inside);
  }
  petsc::Matrix matrix;
  check(MatCreate(comm, matrix.out()), "MatCreate");
  check(MatSetSizes(matrix, 4 * local, 4 * local, 4 * n, 4 * n), "MatSetSizes");
  check(MatSetType(matrix, type), "MatSetType");
  check(MatSetBlockSize(matrix, 4), "MatSetBlockSize");
  check(MatSetOptionsPrefix(matrix, prefix.c_str()), "MatSetOptionsPrefix");
  check(MatSetFromOptions(matrix), "MatSetFromOptions");
  check(MatXAIJSetPreallocation(matrix, 4, diagonal.data(), off_diagonal.data(), nullptr, nullptr),
        "MatXAIJSetPreallocation");
  check(MatSetOption(matrix, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  return matrix;
}

}  // namespace naris::ns
