#pragma once
// The unknowns of the steady flow problem at the nodes, and the data that fix them.
#include <Eigen/Dense>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris::ns {

using BodyForce = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

struct FlowField {
  std::vector<Eigen::Vector3d> velocity;  // per node
  std::vector<double> pressure;           // per node
};

// Velocity fixed at some nodes (no-slip walls, inlets, exact data in tests) and optionally the
// pressure at one node (when no boundary sets its level).
struct DirichletConditions {
  std::vector<NodeId> nodes;
  std::vector<Eigen::Vector3d> values;
  std::optional<std::pair<NodeId, double>> pressure_pin;
};

}  // namespace naris::ns
