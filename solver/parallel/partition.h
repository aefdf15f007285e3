#pragma once
// How the mesh is shared among MPI ranks: rank r owns a contiguous range of nodes (the mesher
// numbers nodes slab by slab, so a range is a slab of the geometry) and the cells whose smallest
// node it owns. The solver's rows and assembly and the parallel output pieces follow this rule.
#include <algorithm>
#include <cstdint>

#include "hybrid_mesh.h"

namespace naris::parallel {

struct NodeRange {
  NodeId first = 0, end = 0;  // [first, end)
  bool contains(NodeId node) const { return node >= first && node < end; }
};

inline NodeRange owned_nodes(std::size_t nodes, int rank, int size) {
  const auto n = static_cast<std::int64_t>(nodes);
  return {static_cast<NodeId>(n * rank / size), static_cast<NodeId>(n * (rank + 1) / size)};
}

template <class Cell>
bool owns_cell(const NodeRange& range, const Cell& cell) {
  return range.contains(*std::min_element(cell.begin(), cell.end()));
}

}  // namespace naris::parallel
