#pragma once
// Node → incident items (cells, faces) as a compressed table, for the mesh improvement stages.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris {

class NodeIncidence {
 public:
  // nodes_of(i): the nodes of item i (a range of NodeId), for i < items.
  template <class NodesOf>
  void build(std::size_t nodes, std::size_t items, const NodesOf& nodes_of) {
    start_.assign(nodes + 1, 0);
    for (std::size_t i = 0; i < items; ++i)
      for (NodeId n : nodes_of(i)) ++start_[static_cast<std::size_t>(n) + 1];
    for (std::size_t n = 0; n < nodes; ++n) start_[n + 1] += start_[n];
    item_.resize(start_[nodes]);
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < items; ++i)
      for (NodeId n : nodes_of(i)) item_[fill[n]++] = static_cast<std::int32_t>(i);
  }
  // The items of node n, in increasing order.
  std::span<const std::int32_t> of(NodeId n) const {
    const auto k = static_cast<std::size_t>(n);
    return {item_.data() + start_[k], start_[k + 1] - start_[k]};
  }

 private:
  std::vector<std::size_t> start_;
  std::vector<std::int32_t> item_;
};

}  // namespace naris
