#pragma once
// How the mesh is shared among MPI ranks: rank r owns a contiguous range of nodes (the mesher
// numbers nodes slab by slab, so a range is a slab of the geometry), the cells whose smallest
// node it owns, and the boundary faces whose smallest node it owns. Each rank keeps only its
// piece of the mesh: the cells around its nodes and around the nodes of its cells (a halo of
// two layers, which the recovered gradient at those nodes needs), renumbered locally.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "mesh/hybrid_mesh.h"

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

// A rank's local node numbers against the whole mesh's: local nodes [0, owned) are the owned
// range in order, the halo's follow in increasing global number.
struct NodeNumbering {
  std::vector<NodeId> global;  // local → global; empty: the identity (the whole mesh, one rank)
  NodeId owned = 0;
  NodeRange range;  // the owned nodes' global numbers
  std::size_t global_nodes = 0;

  NodeId to_global(NodeId local) const {
    return global.empty() ? local : global[static_cast<std::size_t>(local)];
  }
  // The inverse: the local number of a global node, or −1 where the piece does not hold it.
  NodeId to_local(NodeId global_node) const;
  bool owns(NodeId local) const { return local < owned; }
  // A cell (or face) in local numbers belongs to this rank when its smallest global node is
  // owned (the rule above, so that every cell has exactly one owner).
  template <class Cell>
  bool owns_cell(const Cell& cell) const {
    NodeId lowest = to_global(*cell.begin());
    for (NodeId v : cell) lowest = std::min(lowest, to_global(v));
    return range.contains(lowest);
  }
};

// The numbering of the whole mesh held by one rank.
NodeNumbering whole_numbering(std::size_t nodes);

struct MeshPiece {
  HybridMesh mesh;  // local node numbers; the boundary faces this rank owns
  NodeNumbering numbering;
  std::vector<std::size_t> face_index;  // per local boundary face: its index in the whole
                                        // mesh's (triangles, then quadrilaterals)
};

// Rank `rank`'s piece of `whole` shared by `ranks`.
MeshPiece mesh_piece(const HybridMesh& whole, int rank, int ranks);

}  // namespace naris::parallel
