#include "solver/ns/distributed_field.h"

#include "core/error.h"

namespace naris::ns {

FlowField local_field(const FlowField& whole, const parallel::NodeNumbering& numbering) {
  if (whole.pressure.size() != numbering.global_nodes)
    fail("a field of {} nodes on a mesh of {}", whole.pressure.size(), numbering.global_nodes);
  const std::size_t n = numbering.global.empty() ? numbering.global_nodes : numbering.global.size();
  FlowField f{std::vector<Eigen::Vector3d>(n), std::vector<double>(n)};
  for (std::size_t k = 0; k < n; ++k) {
    const auto g = static_cast<std::size_t>(numbering.to_global(static_cast<NodeId>(k)));
    f.velocity[k] = whole.velocity[g];
    f.pressure[k] = whole.pressure[g];
  }
  return f;
}

DirichletConditions local_conditions(const DirichletConditions& whole,
                                     const parallel::NodeNumbering& numbering) {
  DirichletConditions local;
  for (std::size_t k = 0; k < whole.nodes.size(); ++k)
    if (const NodeId l = numbering.to_local(whole.nodes[k]); l >= 0) {
      local.nodes.push_back(l);
      local.values.push_back(whole.values[k]);
    }
  if (whole.pressure_pin)
    if (const NodeId l = numbering.to_local(whole.pressure_pin->first); l >= 0)
      local.pressure_pin = {l, whole.pressure_pin->second};
  return local;
}

FlowField gather_field(const FlowField& local, const parallel::NodeNumbering& numbering,
                       MPI_Comm comm, int root) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  // Four values per node, owned nodes in global order: the ranks' ranges tile the whole.
  const auto owned = static_cast<std::size_t>(numbering.owned);
  std::vector<double> mine(4 * owned);
  for (std::size_t k = 0; k < owned; ++k) {
    for (int c = 0; c < 3; ++c) mine[4 * k + static_cast<std::size_t>(c)] = local.velocity[k][c];
    mine[4 * k + 3] = local.pressure[k];
  }
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(counts.size());
  for (int r = 0; r < ranks; ++r) {
    const auto range = parallel::owned_nodes(numbering.global_nodes, r, ranks);
    counts[static_cast<std::size_t>(r)] = 4 * (range.end - range.first);
    offsets[static_cast<std::size_t>(r)] = 4 * range.first;
  }
  const bool receives = root < 0 || rank == root;
  std::vector<double> all(receives ? 4 * numbering.global_nodes : 0);
  const int count = static_cast<int>(mine.size());
  if (root < 0)
    MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                   MPI_DOUBLE, comm);
  else
    MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                MPI_DOUBLE, root, comm);
  FlowField whole;
  if (!receives) return whole;
  whole.velocity.resize(numbering.global_nodes);
  whole.pressure.resize(numbering.global_nodes);
  for (std::size_t k = 0; k < numbering.global_nodes; ++k) {
    whole.velocity[k] = {all[4 * k], all[4 * k + 1], all[4 * k + 2]};
    whole.pressure[k] = all[4 * k + 3];
  }
  return whole;
}

}  // namespace naris::ns
