#include "solver/ns/backflow.h"

namespace naris::ns {

void backflow_face(const HybridMesh& mesh, std::span<const NodeId> v,
                   const std::vector<Eigen::Vector3d>& advection, double beta, double smoothing,
                   Eigen::Matrix4d& M, Eigen::Matrix<double, 16, 16>* derivative) {
  M.setZero();
  if (derivative) derivative->setZero();
  const int m = static_cast<int>(v.size());
  const auto node = [&](int i) { return static_cast<std::size_t>(v[static_cast<std::size_t>(i)]); };
  for (int k = 1; k + 1 < m; ++k) {
    const int tri[3] = {0, k, k + 1};
    const Eigen::Vector3d an =
        0.5 * (mesh.nodes[node(tri[1])] - mesh.nodes[node(tri[0])])
                  .cross(mesh.nodes[node(tri[2])] - mesh.nodes[node(tri[0])]);
    const double area = an.norm();
    if (area <= 0.0) continue;
    const Eigen::Vector3d normal = an / area;
    for (int q = 0; q < 3; ++q) {
      double phi[3] = {0.5, 0.5, 0.5};
      phi[q] = 0.0;
      Eigen::Vector3d a = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) a += phi[i] * advection[node(tri[i])];
      const NegativePart inflow = negative_part(a.dot(normal), smoothing);
      if (inflow.value == 0.0 && inflow.slope == 0.0) continue;
      const double weight = -beta * area / 3.0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          M(tri[i], tri[j]) += weight * inflow.value * phi[i] * phi[j];
          if (derivative)
            derivative->block<3, 3>(4 * tri[i], 4 * tri[j]) +=
                weight * inflow.slope * phi[i] * phi[j] * a * normal.transpose();
        }
    }
  }
}

}  // namespace naris::ns
