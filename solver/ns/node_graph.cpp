#include "ns/node_graph.h"

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

}  // namespace naris::ns
