#include "solver/parallel/partition.h"

#include <algorithm>

namespace naris::parallel {

NodeNumbering whole_numbering(std::size_t nodes) {
  NodeNumbering n;
  n.owned = static_cast<NodeId>(nodes);
  n.range = {0, static_cast<NodeId>(nodes)};
  n.global_nodes = nodes;
  return n;
}

NodeId NodeNumbering::to_local(NodeId global_node) const {
  if (global.empty()) return global_node;
  if (range.contains(global_node)) return global_node - range.first;
  // The halo is sorted by global number: bisection.
  const auto halo = global.begin() + owned;
  const auto it = std::lower_bound(halo, global.end(), global_node);
  return it != global.end() && *it == global_node ? static_cast<NodeId>(it - global.begin()) : -1;
}

MeshPiece mesh_piece(const HybridMesh& whole, int rank, int ranks) {
  const std::size_t n = whole.nodes.size();
  const NodeRange range = owned_nodes(n, rank, ranks);
  // needed: the owned nodes and the nodes of owned cells; kept: every cell touching one.
  std::vector<char> needed(n, 0);
  std::fill(needed.begin() + range.first, needed.begin() + range.end, 1);
  auto mark = [&](const auto& cells) {
    for (const auto& c : cells)
      if (owns_cell(range, c))
        for (NodeId v : c) needed[static_cast<std::size_t>(v)] = 1;
  };
  mark(whole.tets);
  mark(whole.pyramids);
  mark(whole.hexes);
  std::vector<NodeId> local(n, -1);
  MeshPiece piece;
  NodeNumbering& num = piece.numbering;
  num.range = range;
  num.global_nodes = n;
  num.owned = range.end - range.first;
  for (NodeId g = range.first; g < range.end; ++g)
    local[static_cast<std::size_t>(g)] = g - range.first;
  auto touches = [&](const auto& cell) {
    return std::any_of(cell.begin(), cell.end(),
                       [&](NodeId v) { return needed[static_cast<std::size_t>(v)] != 0; });
  };
  // Halo nodes: those of kept cells outside the range, numbered in increasing global order.
  std::vector<char> halo(n, 0);
  auto mark_halo = [&](const auto& cells) {
    for (const auto& c : cells)
      if (touches(c))
        for (NodeId v : c)
          if (!range.contains(v)) halo[static_cast<std::size_t>(v)] = 1;
  };
  mark_halo(whole.tets);
  mark_halo(whole.pyramids);
  mark_halo(whole.hexes);
  num.global.reserve(static_cast<std::size_t>(num.owned));
  for (NodeId g = range.first; g < range.end; ++g) num.global.push_back(g);
  for (std::size_t g = 0; g < n; ++g)
    if (halo[g]) {
      local[g] = static_cast<NodeId>(num.global.size());
      num.global.push_back(static_cast<NodeId>(g));
    }
  HybridMesh& m = piece.mesh;
  m.nodes.resize(num.global.size());
  for (std::size_t l = 0; l < num.global.size(); ++l)
    m.nodes[l] = whole.nodes[static_cast<std::size_t>(num.global[l])];
  auto keep = [&](const auto& cells, auto& out) {
    for (const auto& c : cells)
      if (touches(c)) {
        auto renumbered = c;
        for (NodeId& v : renumbered) v = local[static_cast<std::size_t>(v)];
        out.push_back(renumbered);
      }
  };
  keep(whole.tets, m.tets);
  keep(whole.pyramids, m.pyramids);
  keep(whole.hexes, m.hexes);
  // The boundary faces this rank owns: their cells are owned or touch an owned node, so kept.
  m.patch_names = whole.patch_names;
  auto keep_faces = [&](const auto& faces, const auto& patch, auto& out, auto& out_patch,
                        std::size_t offset) {
    for (std::size_t f = 0; f < faces.size(); ++f)
      if (owns_cell(range, faces[f])) {
        auto renumbered = faces[f];
        for (NodeId& v : renumbered) v = local[static_cast<std::size_t>(v)];
        out.push_back(renumbered);
        out_patch.push_back(patch[f]);
        piece.face_index.push_back(offset + f);
      }
  };
  keep_faces(whole.boundary_tris, whole.boundary_tri_patch, m.boundary_tris, m.boundary_tri_patch,
             0);
  keep_faces(whole.boundary_quads, whole.boundary_quad_patch, m.boundary_quads,
             m.boundary_quad_patch, whole.boundary_tris.size());
  return piece;
}

}  // namespace naris::parallel
